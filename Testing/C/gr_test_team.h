/* A team of host threads, one a piece of a split domain, for the C core
 * tests: the allreduce and the halo exchange that a core's pieces call
 * (gr_allreduce_fn, gr_halo_exchange_fn), done through a barrier, a slot of
 * values per rank and a mailbox per rank and side, as MPI would do across
 * processes. A test wraps them in its own callbacks, which count the calls
 * and fail on purpose where the test needs it. */
#ifndef GR_TEST_TEAM_H
#define GR_TEST_TEAM_H

#include "graupel/graupel.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

enum { GR_TEST_TEAM_MAX = 8 };

/* A core's halo_get (set 0) or halo_set (set 1) on its object sim: the one
 * core-specific piece the exchange needs. */
typedef gr_status (*gr_test_halo_fn)(void *sim, int side, void *host, size_t bytes, int set);

typedef struct gr_test_team {
  pthread_barrier_t barrier;
  int n;                             /* pieces, ranked 0 .. n - 1 along the split */
  int max_values;                    /* the most values one allreduce takes */
  double *slot[GR_TEST_TEAM_MAX];    /* each rank's values in an allreduce */
  void *mail[GR_TEST_TEAM_MAX][4];   /* each rank's strips out, by side (W E S N) */
  size_t bytes[GR_TEST_TEAM_MAX][4]; /* 0: no neighbour on that side */
} gr_test_team;

static inline void gr_test_team_init(gr_test_team *t, int n, int max_values) {
  memset(t, 0, sizeof(*t));
  t->n = n;
  t->max_values = max_values;
  pthread_barrier_init(&t->barrier, NULL, (unsigned)n);
  for (int k = 0; k < n; ++k)
    t->slot[k] = (double *)malloc((size_t)max_values * sizeof(double));
}

/* The mailbox of rank on side for a strip of that many bytes (0: none). */
static inline void gr_test_team_mail(gr_test_team *t, int rank, int side, size_t bytes) {
  free(t->mail[rank][side]);
  t->bytes[rank][side] = bytes;
  t->mail[rank][side] = bytes ? malloc(bytes) : NULL;
}

static inline void gr_test_team_destroy(gr_test_team *t) {
  for (int k = 0; k < t->n; ++k) {
    free(t->slot[k]);
    for (int side = 0; side < 4; ++side)
      free(t->mail[k][side]);
  }
  pthread_barrier_destroy(&t->barrier);
}

/* values[0..n-1] reduced over every rank, combined in rank order so that
 * every rank gets the same bits, and a rerun too. More than max_values:
 * GR_ERR_INVALID_ARGUMENT before the barrier (every rank asks alike). */
static inline gr_status gr_test_team_allreduce(gr_test_team *t, int rank, double *values, int n,
                                               gr_reduce_op op) {
  if (n > t->max_values)
    return GR_ERR_INVALID_ARGUMENT;
  memcpy(t->slot[rank], values, (size_t)n * sizeof(double));
  pthread_barrier_wait(&t->barrier);
  for (int q = 0; q < n; ++q) {
    double v = t->slot[0][q];
    for (int k = 1; k < t->n; ++k) {
      double w = t->slot[k][q];
      v = op == GR_REDUCE_SUM ? v + w : op == GR_REDUCE_MAX ? fmax(v, w) : fmin(v, w);
    }
    values[q] = v;
  }
  pthread_barrier_wait(&t->barrier);
  return GR_OK;
}

/* Every rank's strips out through its mailboxes, then its neighbours' in:
 * the pieces are ranked along the split, so a rank's even sides (west,
 * south) face rank - 1 and its odd sides rank + 1, whose strip for this one
 * is in its mailbox of the opposite side. Every rank passes both barriers
 * whatever fails, so none waits for ever; the first failure is returned. */
static inline gr_status gr_test_team_exchange(gr_test_team *t, int rank, void *sim,
                                              gr_test_halo_fn halo) {
  gr_status st = GR_OK;
  for (int side = 0; side < 4; ++side)
    if (st == GR_OK && t->bytes[rank][side])
      st = halo(sim, side, t->mail[rank][side], t->bytes[rank][side], 0);
  pthread_barrier_wait(&t->barrier);
  for (int side = 0; side < 4; ++side) {
    int other = side & 1 ? rank + 1 : rank - 1;
    if (st == GR_OK && t->bytes[rank][side])
      st = halo(sim, side, t->mail[other][side ^ 1], t->bytes[rank][side], 1);
  }
  pthread_barrier_wait(&t->barrier);
  return st;
}

/* The exchange's two barriers alone: a rank with nothing to send (its step
 * failed) while the others exchange. */
static inline void gr_test_team_pass(gr_test_team *t) {
  pthread_barrier_wait(&t->barrier);
  pthread_barrier_wait(&t->barrier);
}

/* fn on n threads, one for each of items[0..n-1] (size bytes each);
 * returns when every one has. */
static inline void gr_test_team_run(int n, void *(*fn)(void *), void *items, size_t size) {
  pthread_t th[GR_TEST_TEAM_MAX];
  for (int k = 0; k < n; ++k)
    pthread_create(&th[k], NULL, fn, (char *)items + (size_t)k * size);
  for (int k = 0; k < n; ++k)
    pthread_join(th[k], NULL);
}

#endif
