/* graupel-bench --devices K: one core's set-up split into K strips along y,
 * each strip a piece of the split domain (the core's piece contract: its
 * ring toward each neighbour, the halo calls, the allreduce) on its own
 * OpenCL device, all in one process: one host thread and one context per
 * piece, the halo exchange and the allreduce done on the host between the
 * threads. Multi-GPU without MPI, for the GPU machines that have no
 * ParaView; the same halo calls an MPI run makes.
 *
 * Exchange: after every step the core calls the piece's exchange, which
 * waits for the piece's device (the step's kernels: "device wait"), copies
 * the owned rows next to each neighbour into the piece's mailbox (halo_get),
 * meets the other threads at a barrier, and copies the neighbours' rows
 * into its ring (halo_set). The mailboxes alternate between two sets from
 * one exchange to the next, so one barrier per step is enough: a piece
 * cannot write a set again before every piece has passed the next barrier,
 * which it reaches only after reading that set. The mailboxes are pinned
 * host memory on GPUs (a mapped CL_MEM_ALLOC_HOST_PTR buffer of the writing
 * piece's context), which they copy to and from at their DMA rate; plain
 * malloc'ed ones on other devices, with GRAUPEL_BENCH_PINNED=0, or where the
 * mapping fails.
 *
 * Allreduce: every piece writes its values into its slot, a barrier, then
 * every piece combines the slots in piece order (the same operations on the
 * same doubles: every piece gets the same bits, whatever the thread timing),
 * a barrier. The fields are what the core computes on a whole grid bit for
 * bit wherever its header promises that; sums over pieces (ledgers) are
 * equal to rounding.
 *
 * A failure on one piece breaks the barrier: the others' next collective
 * call returns GR_ERR_ABORTED instead of waiting for ever. */
#include "bench.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------- a breakable barrier */

typedef struct split_barrier {
  pthread_mutex_t lock;
  pthread_cond_t turn;
  int count, waiting;
  unsigned long generation;
  int broken;
} split_barrier;

/* 0 when every thread arrived; -1 when the barrier is (or gets) broken. */
static int barrier_wait(split_barrier *b) {
  pthread_mutex_lock(&b->lock);
  if (b->broken) {
    pthread_mutex_unlock(&b->lock);
    return -1;
  }
  unsigned long gen = b->generation;
  if (++b->waiting == b->count) {
    b->waiting = 0;
    b->generation++;
    pthread_cond_broadcast(&b->turn);
    pthread_mutex_unlock(&b->lock);
    return 0;
  }
  while (gen == b->generation && !b->broken)
    pthread_cond_wait(&b->turn, &b->lock);
  int r = gen == b->generation ? -1 : 0;
  pthread_mutex_unlock(&b->lock);
  return r;
}

static void barrier_break(split_barrier *b) {
  pthread_mutex_lock(&b->lock);
  b->broken = 1;
  pthread_cond_broadcast(&b->turn);
  pthread_mutex_unlock(&b->lock);
}

/* ------------------------------------------------------------- the team */

/* Doubles per piece in one allreduce: the longest call any core makes
 * (Snow Accumulation reduces its exposure view in calls of
 * GR_SNOW_ACCUMULATION_REDUCE_CHUNK values). */
#define SPLIT_SLOTS 65536

typedef struct split_team split_team;

typedef struct split_member {
  split_team *team;
  int rank, j0, ny, device; /* device: index among the distinct devices */
  gr_context *ctx;
  void *state;
  gr_bench_link link;
  size_t halo_bytes[2]; /* toward the south (0) and north (1) neighbour; 0: none */
  unsigned long exchanges;
  /* seconds since the timed steps began */
  double wait_s, halo_s, barrier_s, allreduce_s;
  int allreduce_calls;
  double allreduce_values; /* values reduced (8 bytes each) */
  double step_allreduce_s; /* of allreduce_s: in the timed steps */
  int step_allreduce_calls;
  double step_allreduce_values;
  unsigned long step_exchanges;
  double t0, t1; /* the timed steps' start and end */
  gr_status st;
  char error[600];
  char stages[400]; /* the piece's stage line (gr_bench_split's stages), or "" */
} split_member;

struct split_team {
  const gr_bench_split *split;
  const gr_bench_core *core;
  int k, n, steps;
  split_barrier barrier;
  double *slots;       /* k * SPLIT_SLOTS */
  void **mail[2];      /* [parity][2 * rank + (0 south, 1 north)] */
  cl_mem *mail_mem[2]; /* the pinned buffer behind each mailbox, or NULL (malloc'ed) */
  float **gathered;    /* --verify: every output of the whole grid, or NULL */
  char summary[400];   /* the first piece's summary line */
};

static void member_fail(split_member *m, gr_status st, const char *what) {
  if (m->st == GR_OK) {
    m->st = st;
    const char *detail = m->state ? m->team->split->last_error(m->state) : "";
    snprintf(m->error, sizeof(m->error), "piece %d (%s): %s", m->rank, what,
             detail && detail[0] ? detail : gr_last_error(m->ctx));
  }
  barrier_break(&m->team->barrier);
}

static gr_status split_allreduce(void *user, double *values, int n, gr_reduce_op op) {
  split_member *m = user;
  split_team *t = m->team;
  if (n < 0 || n > SPLIT_SLOTS)
    return gr_set_error(m->ctx, GR_ERR_INVALID_ARGUMENT,
                        "graupel-bench's allreduce takes at most %d values (got %d).", SPLIT_SLOTS,
                        n);
  double t0 = gr_bench_now_s();
  memcpy(t->slots + (size_t)m->rank * SPLIT_SLOTS, values, (size_t)n * sizeof(double));
  if (barrier_wait(&t->barrier) != 0)
    return gr_set_error(m->ctx, GR_ERR_ABORTED, "Another piece failed during the allreduce.");
  for (int q = 0; q < n; ++q) {
    double v = t->slots[q];
    for (int r = 1; r < t->k; ++r) {
      double w = t->slots[(size_t)r * SPLIT_SLOTS + q];
      v = op == GR_REDUCE_SUM ? v + w : op == GR_REDUCE_MAX ? fmax(v, w) : fmin(v, w);
    }
    values[q] = v;
  }
  /* Nobody may write its slot again before everybody has read them all. */
  if (barrier_wait(&t->barrier) != 0)
    return gr_set_error(m->ctx, GR_ERR_ABORTED, "Another piece failed during the allreduce.");
  m->allreduce_s += gr_bench_now_s() - t0;
  m->allreduce_calls++;
  m->allreduce_values += n;
  return GR_OK;
}

static gr_status split_exchange(void *user) {
  split_member *m = user;
  split_team *t = m->team;
  const gr_bench_split *sp = t->split;
  int parity = (int)(m->exchanges & 1);
  void **mail = t->mail[parity];
  double t0 = gr_bench_now_s();
  gr_status st = gr_finish(m->ctx);
  double t1 = gr_bench_now_s();
  if (st == GR_OK && m->halo_bytes[0])
    st = sp->halo_get(m->state, GR_BENCH_SOUTH, mail[2 * m->rank], m->halo_bytes[0]);
  if (st == GR_OK && m->halo_bytes[1])
    st = sp->halo_get(m->state, GR_BENCH_NORTH, mail[2 * m->rank + 1], m->halo_bytes[1]);
  double t2 = gr_bench_now_s();
  if (st != GR_OK) {
    barrier_break(&t->barrier);
    return st;
  }
  if (barrier_wait(&t->barrier) != 0)
    return gr_set_error(m->ctx, GR_ERR_ABORTED, "Another piece failed during the halo exchange.");
  double t3 = gr_bench_now_s();
  /* The southern neighbour's northern rows fill the southern ring, and so on. */
  if (m->halo_bytes[0])
    st = sp->halo_set(m->state, GR_BENCH_SOUTH, mail[2 * (m->rank - 1) + 1], m->halo_bytes[0]);
  if (st == GR_OK && m->halo_bytes[1])
    st = sp->halo_set(m->state, GR_BENCH_NORTH, mail[2 * (m->rank + 1)], m->halo_bytes[1]);
  double t4 = gr_bench_now_s();
  if (st != GR_OK)
    barrier_break(&t->barrier);
  m->wait_s += t1 - t0;
  m->halo_s += (t2 - t1) + (t4 - t3);
  m->barrier_s += t3 - t2;
  m->exchanges++;
  return st;
}

/* Gathers output i's owned cells into the whole grid's array. */
static gr_status member_gather(split_member *m) {
  split_team *t = m->team;
  const gr_bench_split *sp = t->split;
  for (int i = 0; i < sp->outputs; ++i) {
    const char *name = NULL;
    int comps = 1;
    gr_status st = sp->output(m->state, i, &name, &comps, NULL);
    size_t at = (size_t)m->j0 * (size_t)t->n * (size_t)comps;
    if (st == GR_OK)
      st = sp->output(m->state, i, &name, &comps, t->gathered[i] + at);
    if (st != GR_OK)
      return st;
  }
  return GR_OK;
}

/* Mailbox i of set p, written by piece m: on a GPU pinned (mapped from a
 * CL_MEM_ALLOC_HOST_PTR buffer of m's context) unless GRAUPEL_BENCH_PINNED=0
 * or the mapping fails, otherwise malloc'ed. 0: out of memory. */
static int mailbox_alloc(split_member *m, int p, int i, size_t bytes) {
  split_team *t = m->team;
  const char *pinned = getenv("GRAUPEL_BENCH_PINNED");
  cl_device_type type = 0;
  clGetDeviceInfo(gr_context_device(m->ctx), CL_DEVICE_TYPE, sizeof(type), &type, NULL);
  if ((type & CL_DEVICE_TYPE_GPU) && !(pinned && *pinned && atoi(pinned) == 0)) {
    cl_int err = CL_SUCCESS;
    cl_mem buf = clCreateBuffer(gr_context_cl(m->ctx), CL_MEM_ALLOC_HOST_PTR | CL_MEM_READ_WRITE,
                                bytes, NULL, &err);
    void *at = err == CL_SUCCESS
                   ? clEnqueueMapBuffer(gr_context_queue(m->ctx), buf, CL_TRUE,
                                        CL_MAP_READ | CL_MAP_WRITE, 0, bytes, 0, NULL, NULL, &err)
                   : NULL;
    if (at && err == CL_SUCCESS) {
      t->mail[p][i] = at;
      t->mail_mem[p][i] = buf;
      return 1;
    }
    if (buf)
      clReleaseMemObject(buf);
  }
  return (t->mail[p][i] = malloc(bytes)) != NULL;
}

/* Mailbox i of set p freed (unmapped on its writer's queue, before the
 * writer's context goes). */
static void mailbox_free(split_team *t, split_member *m, int p, int i) {
  if (t->mail_mem[p] && t->mail_mem[p][i]) {
    cl_command_queue q = gr_context_queue(m[i / 2].ctx);
    clEnqueueUnmapMemObject(q, t->mail_mem[p][i], t->mail[p][i], 0, NULL, NULL);
    clFinish(q);
    clReleaseMemObject(t->mail_mem[p][i]);
  } else if (t->mail[p]) {
    free(t->mail[p][i]);
  }
}

static void *member_run(void *arg) {
  split_member *m = arg;
  split_team *t = m->team;
  const gr_bench_split *sp = t->split;
  gr_status st = sp->setup(m->ctx, t->n, m->j0, m->ny, &m->link, &m->state);
  if (st != GR_OK) {
    member_fail(m, st, "set-up");
    return NULL;
  }
  if (m->j0 > 0)
    st = sp->halo_size(m->state, GR_BENCH_SOUTH, &m->halo_bytes[0]);
  if (st == GR_OK && m->j0 + m->ny < t->n)
    st = sp->halo_size(m->state, GR_BENCH_NORTH, &m->halo_bytes[1]);
  for (int p = 0; st == GR_OK && p < 2; ++p)
    for (int s = 0; s < 2; ++s)
      if (m->halo_bytes[s] && !mailbox_alloc(m, p, 2 * m->rank + s, m->halo_bytes[s]))
        st = gr_set_error(m->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory for the halo.");
  if (st != GR_OK) {
    member_fail(m, st, "halo buffers");
    return NULL;
  }
  /* Warm-up, as the one-device run: first launches pay for compilation. */
  for (int i = 0; st == GR_OK && i < 2; ++i)
    st = t->core->step(m->state);
  if (st == GR_OK)
    st = gr_finish(m->ctx);
  if (st == GR_OK && barrier_wait(&t->barrier) != 0)
    st = GR_ERR_ABORTED;
  if (st != GR_OK) {
    member_fail(m, st, "warm-up");
    return NULL;
  }
  /* The set-up's allreduce waited for the slowest program build: count from here. */
  m->wait_s = m->halo_s = m->barrier_s = m->allreduce_s = 0.0;
  m->allreduce_calls = 0;
  m->allreduce_values = 0.0;
  unsigned long exchanges0 = m->exchanges;
  m->t0 = gr_bench_now_s();
  for (int i = 0; st == GR_OK && i < t->steps; ++i)
    st = t->core->step(m->state);
  if (st == GR_OK)
    st = gr_finish(m->ctx);
  m->t1 = gr_bench_now_s();
  m->step_allreduce_s = m->allreduce_s;
  m->step_allreduce_calls = m->allreduce_calls;
  m->step_allreduce_values = m->allreduce_values;
  m->step_exchanges = m->exchanges - exchanges0;
  if (st != GR_OK) {
    member_fail(m, st, "steps");
    return NULL;
  }
  if (sp->summary) {
    char line[sizeof(t->summary)] = "";
    st = sp->summary(m->state, line, sizeof(line));
    if (st != GR_OK) {
      member_fail(m, st, "summary");
      return NULL;
    }
    if (m->rank == 0)
      memcpy(t->summary, line, sizeof(line));
  }
  if (t->gathered && (st = member_gather(m)) != GR_OK) {
    member_fail(m, st, "read-back");
    return NULL;
  }
  /* After the read-back: --verify's whole grid runs as many steps as the
   * pieces before it. */
  if (sp->stages && (st = sp->stages(m->state, m->stages, sizeof(m->stages))) != GR_OK)
    member_fail(m, st, "stages");
  return NULL;
}

/* ------------------------------------------------------------- --verify */

/* One whole grid on ctx, the same steps (warm-up included) as the pieces;
 * every output compared with the pieces' stitched one. Returns the number
 * of values that differ in any bit, or -1 on an error. */
static long verify_whole(split_team *t, gr_context *ctx, const char *name) {
  const gr_bench_split *sp = t->split;
  void *state = NULL;
  gr_status st = sp->setup(ctx, t->n, 0, t->n, NULL, &state);
  for (int i = 0; st == GR_OK && i < 2 + t->steps; ++i)
    st = t->core->step(state);
  if (st == GR_OK)
    st = gr_finish(ctx);
  long total = 0;
  size_t values = 0;
  double worst = 0.0;
  size_t cells = (size_t)t->n * (size_t)t->n;
  for (int i = 0; st == GR_OK && i < sp->outputs; ++i) {
    const char *out = NULL;
    int comps = 1;
    st = sp->output(state, i, &out, &comps, NULL);
    float *whole = st == GR_OK ? malloc(cells * (size_t)comps * sizeof(float)) : NULL;
    if (st == GR_OK && !whole)
      st = gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory for --verify.");
    if (st == GR_OK)
      st = sp->output(state, i, &out, &comps, whole);
    long differ = 0;
    double max_diff = 0.0;
    for (size_t c = 0; st == GR_OK && c < cells * (size_t)comps; ++c) {
      float a = whole[c], b = t->gathered[i][c];
      if (memcmp(&a, &b, sizeof(float)) == 0)
        continue;
      ++differ;
      double d = isnan(a) || isnan(b) ? INFINITY : fabs((double)a - (double)b);
      if (d > max_diff)
        max_diff = d;
    }
    if (st == GR_OK && differ)
      printf("verify: %s: %ld of %zu values differ from the whole grid's (max |diff| %.6g)\n", out,
             differ, cells * (size_t)comps, max_diff);
    if (max_diff > worst)
      worst = max_diff;
    total += differ;
    values += cells * (size_t)comps;
    free(whole);
  }
  if (st != GR_OK) {
    fprintf(stderr, "graupel-bench: --verify's whole grid: %s\n",
            state && sp->last_error(state)[0] ? sp->last_error(state) : gr_last_error(ctx));
    if (state)
      t->core->teardown(state);
    return -1;
  }
  printf("verify: %s, %d pieces against one whole grid after %d steps: %ld of %zu values in %d "
         "outputs differ in any bit (max |diff| %.6g)\n",
         name, t->k, 2 + t->steps, total, values, sp->outputs, worst);
  if (sp->summary) {
    char line[sizeof(t->summary)] = "";
    if (sp->summary(state, line, sizeof(line)) != GR_OK) {
      fprintf(stderr, "graupel-bench: --verify's whole grid: %s\n", sp->last_error(state));
      t->core->teardown(state);
      return -1;
    }
    /* Equal to rounding in general (sums over pieces); the same bits where
     * a core's header promises its ledger so. */
    printf("verify: the whole grid's summary (%s the pieces'):\n%s\n",
           strcmp(line, t->summary) == 0 ? "the same bits as" : "differs from", line);
  }
  t->core->teardown(state);
  return total;
}

/* ------------------------------------------------------------ the driver */

/* The request every piece's device comes from: the option, else
 * GRAUPEL_DEVICE, else "auto" (every GPU where there are GPUs, else every
 * CPU device). */
static const char *base_request(const char *device) {
  if (device && device[0] && strcmp(device, "auto") != 0)
    return device;
  const char *env = getenv("GRAUPEL_DEVICE");
  return env && env[0] ? env : "auto";
}

/* The request's limits: 0 when the core, the size and the pieces suit
 * --devices (and --verify), else 2 with the message printed. */
static int check_split(const char *name, const gr_bench_split *sp, int n, int k, int verify) {
  if (!sp) {
    fprintf(stderr,
            "graupel-bench: --devices needs a core that runs as pieces of a split "
            "domain; '%s' does not: leave --devices out, or see --help for the cores marked *.\n",
            name);
    return 2;
  }
  int ring = sp->ring();
  if (k > 1 && n / k < ring) {
    fprintf(stderr,
            "graupel-bench: --devices %d cuts %d rows into strips of %d, fewer than the %d rows "
            "of ring '%s' needs toward a neighbour: use --size %d or more, or fewer devices.\n",
            k, n, n / k, ring, name, ring * k);
    return 2;
  }
  if (verify && n > 4096) {
    fprintf(stderr, "graupel-bench: --verify keeps every output of the whole grid twice on the "
                    "host: use --size 4096 or less with it.\n");
    return 2;
  }
  return 0;
}

/* One context per piece, piece r on the (r mod d)-th of the d devices base
 * matches (a ":N" request is one device), and each piece's strip of rows;
 * *distinct the d. Prints which device has which pieces. Returns 0, else
 * the exit status (1, or 77 when --verify finds no OpenCL device). */
static int open_pieces(split_team *t, split_member *m, const char *base, int verify,
                       int *distinct) {
  int k = t->k, n = t->n;
  int has_index = strchr(base, ':') != NULL;
  char request[300];
  *distinct = 0;
  for (int r = 0; r < k; ++r) {
    gr_context_options opt;
    gr_context_options_init(&opt);
    if (has_index)
      snprintf(request, sizeof(request), "%s", base);
    else
      snprintf(request, sizeof(request), "%s:%d", base, *distinct ? r % *distinct : r);
    opt.device = request;
    gr_status st = gr_context_create(&opt, &m[r].ctx);
    if (st != GR_OK && r > 0 && !has_index && !*distinct) {
      *distinct = r; /* no r-th device: share the first r */
      snprintf(request, sizeof(request), "%s:%d", base, r % *distinct);
      st = gr_context_create(&opt, &m[r].ctx);
    }
    if (st != GR_OK) {
      fprintf(stderr, "graupel-bench: %s\n", gr_last_error(NULL));
      int rc = st == GR_ERR_NO_PLATFORM || st == GR_ERR_NO_DEVICE ? (verify ? 77 : 1) : 1;
      if (rc == 77)
        printf("graupel-bench: no OpenCL device: --verify skipped.\n");
      return rc;
    }
    m[r].team = t;
    m[r].rank = r;
    m[r].j0 = (int)((long long)n * r / k);
    m[r].ny = (int)((long long)n * (r + 1) / k) - m[r].j0;
  }
  if (has_index)
    *distinct = 1;
  else if (!*distinct)
    *distinct = k;
  for (int r = 0; r < k; ++r)
    m[r].device = r % *distinct;
  for (int d = 0; d < *distinct; ++d) {
    printf("device %d: %s (%s): pieces", d, gr_context_device_name(m[d].ctx),
           gr_context_platform_name(m[d].ctx));
    for (int r = d; r < k; r += *distinct)
      printf(" %d", r);
    printf("\n");
  }
  if (*distinct < k)
    printf("note: %d pieces on %d device%s ('%s' matches no more): the pieces share them, so the "
           "figures measure the split's cost, not a speed-up\n",
           k, *distinct, *distinct == 1 ? "" : "s", base);
  return 0;
}

/* The copy rates of the distinct devices added up into *copy_bps; 0, or -1
 * with the message printed. */
static int probe_copy(const split_team *t, split_member *m, int distinct, double *copy_bps) {
  size_t cells = (size_t)t->n * (size_t)t->n;
  *copy_bps = 0.0;
  for (int d = 0; d < distinct; ++d) {
    double bps = 0.0;
    /* Each device probed alone; one device's pieces share its copy rate. */
    if (gr_bench_copy_bandwidth(m[d].ctx, cells / (size_t)t->k * 4, &bps) != GR_OK) {
      fprintf(stderr, "graupel-bench: %s\n", gr_last_error(m[d].ctx));
      return -1;
    }
    *copy_bps += bps;
  }
  return 0;
}

/* The allreduce slots, the mailboxes' tables and, with --verify, the whole
 * grid's outputs; each piece's link. 0, or -1 with the message printed. */
static int team_alloc(split_team *t, split_member *m, int verify) {
  const gr_bench_split *sp = t->split;
  int k = t->k;
  size_t cells = (size_t)t->n * (size_t)t->n;
  t->slots = calloc((size_t)k * SPLIT_SLOTS, sizeof(double));
  t->mail[0] = calloc((size_t)2 * k, sizeof(void *));
  t->mail[1] = calloc((size_t)2 * k, sizeof(void *));
  t->mail_mem[0] = calloc((size_t)2 * k, sizeof(cl_mem));
  t->mail_mem[1] = calloc((size_t)2 * k, sizeof(cl_mem));
  int ok = t->slots && t->mail[0] && t->mail[1] && t->mail_mem[0] && t->mail_mem[1];
  if (ok && verify) {
    t->gathered = calloc((size_t)sp->outputs, sizeof(float *));
    ok = t->gathered != NULL;
    for (int i = 0; ok && i < sp->outputs; ++i) {
      const char *out = NULL;
      int comps = 1;
      ok = sp->output(NULL, i, &out, &comps, NULL) == GR_OK &&
           (t->gathered[i] = malloc(cells * (size_t)comps * sizeof(float))) != NULL;
    }
  }
  if (!ok) {
    fprintf(stderr, "graupel-bench: out of host memory%s.\n", verify ? " for --verify" : "");
    return -1;
  }
  for (int r = 0; r < k; ++r)
    m[r].link = (gr_bench_link){split_allreduce, &m[r], split_exchange, &m[r]};
  return 0;
}

/* One thread per piece, all joined; the pieces' failures printed (the
 * first cause before the aborts it caused). Returns 1 when any failed. */
static int run_pieces(split_team *t, split_member *m) {
  int k = t->k;
  pthread_t *threads = calloc((size_t)k, sizeof(pthread_t));
  int started = 0;
  for (; threads && started < k; ++started)
    if (pthread_create(&threads[started], NULL, member_run, &m[started]) != 0) {
      barrier_break(&t->barrier);
      break;
    }
  for (int r = 0; r < started; ++r)
    pthread_join(threads[r], NULL);
  free(threads);
  int failed = started < k;
  for (int r = 0; r < k; ++r)
    if (m[r].st != GR_OK && m[r].st != GR_ERR_ABORTED) {
      fprintf(stderr, "graupel-bench: %s\n", m[r].error);
      failed = 1;
    }
  for (int r = 0; !failed && r < k; ++r)
    if (m[r].st != GR_OK) {
      fprintf(stderr, "graupel-bench: %s\n", m[r].error);
      failed = 1;
    }
  return failed;
}

/* The pieces' figures combined: the slowest piece's times, the whole run's
 * span. */
typedef struct split_figures {
  double elapsed, halo, wait, barrier, allreduce, step_allreduce;
  int calls, step_calls;
  double step_values;
  unsigned long exchanges;
  size_t halo_bytes;
  double ms, mcells, bw, frac;
} split_figures;

static void combine_figures(const split_team *t, const split_member *m, double copy_bps,
                            split_figures *f) {
  int k = t->k, steps = t->steps;
  size_t cells = (size_t)t->n * (size_t)t->n;
  double t0 = m[0].t0, t1 = m[0].t1;
  memset(f, 0, sizeof(*f));
  for (int r = 0; r < k; ++r) {
    t0 = fmin(t0, m[r].t0);
    t1 = fmax(t1, m[r].t1);
    f->halo = fmax(f->halo, m[r].halo_s);
    f->wait = fmax(f->wait, m[r].wait_s);
    f->barrier = fmax(f->barrier, m[r].barrier_s);
    f->step_allreduce = fmax(f->step_allreduce, m[r].step_allreduce_s);
    f->allreduce = fmax(f->allreduce, m[r].allreduce_s - m[r].step_allreduce_s);
    f->step_calls = m[r].step_allreduce_calls;
    f->step_values = fmax(f->step_values, m[r].step_allreduce_values);
    f->calls = m[r].allreduce_calls - m[r].step_allreduce_calls;
    f->exchanges = m[r].step_exchanges;
    f->halo_bytes += m[r].halo_bytes[0] + m[r].halo_bytes[1];
  }
  f->elapsed = t1 - t0;
  f->ms = 1e3 * f->elapsed / steps;
  f->mcells = (double)cells / (f->elapsed / steps) / 1e6;
  f->bw = t->core->bytes_per_cell * (double)cells / (f->elapsed / steps);
  f->frac = copy_bps > 0.0 ? f->bw / copy_bps : 0.0;
}

/* The figures' lines, the machine-readable one aside. */
static void print_figures(const split_team *t, const split_member *m, const char *name,
                          double copy_bps, int distinct, const split_figures *f) {
  int k = t->k, n = t->n, steps = t->steps;
  printf("copy probe: %.1f GB/s over %d device%s\n", copy_bps / 1e9, distinct,
         distinct == 1 ? "" : "s");
  printf("%s: %d x %d in %d strips along y (ring %d rows), %d steps: %.4f ms/step, %.1f "
         "Mcells/s, %.2f GB/s (%.3f of copy)\n",
         name, n, n, k, k > 1 ? t->split->ring() : 0, steps, f->ms, f->mcells, f->bw / 1e9,
         f->frac);
  for (int r = 0; r < k; ++r)
    printf("  piece %d: rows %d-%d on device %d: device wait %.4f, halo copies %.4f, barrier "
           "%.4f ms/step\n",
           r, m[r].j0, m[r].j0 + m[r].ny - 1, m[r].device, 1e3 * m[r].wait_s / steps,
           1e3 * m[r].halo_s / steps, 1e3 * m[r].barrier_s / steps);
  printf("%s: halo exchange %.4f ms/step (copies, the slowest piece's; %.4g exchanges a step, "
         "%zu bytes each over all pieces), barrier wait %.4f ms/step; allreduce %.4f ms/step "
         "(%.4g calls a step), %.4f ms in %d calls after the steps (the summary)\n",
         name, 1e3 * f->halo / steps, (double)f->exchanges / steps, f->halo_bytes,
         1e3 * f->barrier / steps, 1e3 * f->step_allreduce / steps, (double)f->step_calls / steps,
         1e3 * f->allreduce, f->calls);
  /* What an MPI run would send through MPI_Allreduce: 8 bytes a value. */
  printf("%s: allreduce %.0f bytes a step per piece (%.4g values of 8 bytes)\n", name,
         8.0 * f->step_values / steps, f->step_values / steps);
  if (t->summary[0])
    printf("%s\n", t->summary);
  for (int r = 0; r < k; ++r)
    if (m[r].stages[0])
      printf("  piece %d stages (%s)\n", r, m[r].stages);
}

/* Every piece's state and context, the mailboxes, the slots, the gathered
 * outputs and the barrier released. */
static void team_free(split_team *t, split_member *m) {
  int k = t->k;
  for (int p = 0; p < 2; ++p) {
    for (int i = 0; t->mail[p] && i < 2 * k; ++i)
      mailbox_free(t, m, p, i);
    free(t->mail[p]);
    free(t->mail_mem[p]);
  }
  for (int r = 0; r < k; ++r) {
    if (m[r].state)
      t->core->teardown(m[r].state);
    gr_context_release(m[r].ctx);
  }
  for (int i = 0; t->gathered && i < t->split->outputs; ++i)
    free(t->gathered[i]);
  free(t->gathered);
  free(t->slots);
  pthread_mutex_destroy(&t->barrier.lock);
  pthread_cond_destroy(&t->barrier.turn);
  free(m);
}

/* The pieces opened, run and measured; --verify's comparison. Returns the
 * exit status. */
static int split_measure(split_team *t, split_member *m, const char *name, const char *base,
                         int verify) {
  int distinct = 0;
  double copy_bps = 0.0;
  int rc = open_pieces(t, m, base, verify, &distinct);
  if (rc != 0)
    return rc;
  if (probe_copy(t, m, distinct, &copy_bps) != 0 || team_alloc(t, m, verify) != 0 ||
      run_pieces(t, m) != 0)
    return 1;
  split_figures f;
  combine_figures(t, m, copy_bps, &f);
  print_figures(t, m, name, copy_bps, distinct, &f);
  rc = 0;
  if (verify) {
    long differ = verify_whole(t, m[0].ctx, name);
    rc = differ == 0 ? 0 : 1;
  }
  printf("core=%s size=%d steps=%d devices=%d ms_per_step=%.6g mcells_per_s=%.6g "
         "bw_fraction=%.4g halo_ms_per_step=%.6g exchanges_per_step=%.4g ring=%d "
         "allreduce_bytes_per_step=%.0f device=\"%s\"\n",
         name, t->n, t->steps, t->k, f.ms, f.mcells, f.frac, 1e3 * f.halo / t->steps,
         (double)f.exchanges / t->steps, t->k > 1 ? t->split->ring() : 0,
         8.0 * f.step_values / t->steps, gr_context_device_name(m[0].ctx));
  return rc;
}

int gr_bench_split_run(const char *name, const gr_bench_core *core, int n, int steps,
                       const char *device, int k, int verify) {
  const gr_bench_split *sp = core->split;
  int rc = check_split(name, sp, n, k, verify);
  if (rc != 0)
    return rc;
  const char *base = base_request(device);
  split_member *m = calloc((size_t)k, sizeof(*m));
  split_team t;
  memset(&t, 0, sizeof(t));
  t.split = sp;
  t.core = core;
  t.k = k;
  t.n = n;
  t.steps = steps;
  if (!m) {
    fprintf(stderr, "graupel-bench: out of host memory.\n");
    return 1;
  }
  pthread_mutex_init(&t.barrier.lock, NULL);
  pthread_cond_init(&t.barrier.turn, NULL);
  t.barrier.count = k;
  rc = split_measure(&t, m, name, base, verify);
  team_free(&t, m);
  return rc;
}
