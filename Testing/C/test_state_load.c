/* The cores' checkpoint readers (gr_<core>_state_load) against damaged
 * bytes, one subtest per core that keeps checkpoints, on the simulations of
 * gr_test_states.h:
 *   - a state of another size (none, a byte, half, one byte or word short
 *     or long, twice as long) is refused;
 *   - NaN written as a float32 at every 4-byte place and as a float64 (its
 *     sign set, so that as an int64 it is negative) at every 8-byte place:
 *     past the first 2048 bytes (all of most headers, whose integers may
 *     hold anything; snow deformation's is longer, and all doubles past
 *     them) each place is refused by one of the two, so every float is
 *     checked to be finite and every int64 not to be negative before
 *     anything is loaded;
 *   - the largest int64 at every 8-byte place of those 2048 bytes: a state
 *     that loads steps and keeps a ledger (a step count of 2^63 - 1 was
 *     loaded, and the next step overflowed it: fuzz_state_load);
 *   - every float past those bytes 3e38: a state that loads steps and
 *     keeps a ledger (a huge depth made rain runoff's int64 ledger sums
 *     overflow on the host, fuzz_state_load found; core.runtime.sums_wrap
 *     pins the sums themselves);
 *   - every refusal is a sentence and leaves
 *     the state as it was: state_save gives the valid bytes back, and the
 *     simulation steps on from them to the valid state one step on, bit for
 *     bit.
 * Before these checks every reader loaded NaN into the device at most of
 * those places (rain runoff 5626 of 5626, snow accumulation 1856 of 1868,
 * snow deformation 1182 of 1822, snow melt 5904 of 5904, water surface 142
 * of 142): rain runoff, snow melt and the water surface checked no array,
 * snow accumulation and deformation only the snow's depth (and density). */
#include "gr_test.h"
#include "gr_test_states.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define HEADER_ROOM 2048

static gr_context *ctx;
static gr_state_core cores[GR_STATE_CORES];
static int made;

static int setup(void) {
  if (gr_context_acquire(NULL, &ctx) != GR_OK)
    return 0;
  const char *failed = "";
  gr_status st = gr_state_cores_make(ctx, cores, &failed);
  CHECK_MSG(st == GR_OK, "set-up of the %s simulation: %s", failed, gr_last_error(NULL));
  made = st == GR_OK;
  return 1;
}

static void teardown(void) {
  gr_state_cores_free(cores);
  gr_context_release(ctx);
}

/* A refusal: a sentence (a capital first, a full stop last). */
static int refused_with_sentence(const gr_state_core *c, gr_status st) {
  const char *m = c->last_error(c->sim);
  size_t n = strlen(m);
  return st != GR_OK && n > 10 && m[0] >= 'A' && m[0] <= 'Z' && m[n - 1] == '.';
}

/* The state is the valid one, and steps on to the valid state one step on. */
static int intact(const gr_state_core *c, unsigned char *back, int step) {
  if (c->save(c->sim, back, c->bytes) != GR_OK || memcmp(back, c->valid, c->bytes) != 0)
    return 0;
  if (!step)
    return 1;
  int ok = c->step(c->sim) == GR_OK && c->save(c->sim, back, c->bytes) == GR_OK &&
           memcmp(back, c->stepped, c->bytes) == 0;
  return c->load(c->sim, c->valid, c->bytes) == GR_OK && ok;
}

/* NaN at every place of width bytes (4: a float32, 8: a float64 with its
 * sign set); marks each refused place in refused[place / 4]. Returns the
 * refusals that were not sentences or did not leave the state intact. */
static int sweep(const gr_state_core *c, int width, unsigned char *buf, unsigned char *back,
                 unsigned char *refused) {
  const float f = NAN;
  const double d = -NAN;
  int bad = 0, k = 0;
  for (size_t at = 0; at + (size_t)width <= c->bytes; at += (size_t)width) {
    memcpy(buf, c->valid, c->bytes);
    if (width == 4)
      memcpy(buf + at, &f, 4);
    else
      memcpy(buf + at, &d, 8);
    gr_status st = c->load(c->sim, buf, c->bytes);
    if (st == GR_OK) {
      if (c->load(c->sim, c->valid, c->bytes) != GR_OK)
        ++bad;
      continue;
    }
    for (int q = 0; q < width / 4; ++q)
      refused[at / 4 + (size_t)q] |= (unsigned char)(width == 4 ? 1 : 2);
    /* The state checked now and then: a device read each time. */
    bad += !refused_with_sentence(c, st) || (++k % 97 == 0 && !intact(c, back, 0));
  }
  return bad;
}

/* The largest int64 at every 8-byte place of the first HEADER_ROOM bytes
 * (a header's counts and sums): a state that loads must step, and keep a
 * ledger, without overflowing (the sanitizer build traps on it). Returns
 * the places where it loaded and then did not step. */
static int huge_counts(const gr_state_core *c, unsigned char *buf) {
  const int64_t big = INT64_MAX;
  int bad = 0;
  for (size_t at = 0; at + 8 <= HEADER_ROOM && at + 8 <= c->bytes; at += 8) {
    memcpy(buf, c->valid, c->bytes);
    memcpy(buf + at, &big, 8);
    gr_status st = c->load(c->sim, buf, c->bytes);
    if (st != GR_OK) {
      bad += !refused_with_sentence(c, st);
      continue;
    }
    gr_status stepped = c->step(c->sim);
    bad += (stepped != GR_OK && !refused_with_sentence(c, stepped)) ||
           (c->ledger(c->sim) != GR_OK && !refused_with_sentence(c, GR_ERR_FORMAT));
    bad += c->load(c->sim, c->valid, c->bytes) != GR_OK;
  }
  return bad;
}

/* Every float past the first HEADER_ROOM bytes 3e38 (finite, near the
 * largest): refused, or loaded and then stepped with a ledger that does
 * not overflow (the sanitizer build traps on it). 0 when so. */
static int huge_floats(const gr_state_core *c, unsigned char *buf) {
  const float big = 3e38f;
  memcpy(buf, c->valid, c->bytes);
  for (size_t at = HEADER_ROOM; at + 4 <= c->bytes; at += 4)
    memcpy(buf + at, &big, 4);
  gr_status st = c->load(c->sim, buf, c->bytes);
  if (st != GR_OK)
    return !refused_with_sentence(c, st);
  gr_status stepped = c->step(c->sim), kept = c->ledger(c->sim);
  int bad = (stepped != GR_OK && !refused_with_sentence(c, stepped)) ||
            (kept != GR_OK && !refused_with_sentence(c, kept));
  return bad + (c->load(c->sim, c->valid, c->bytes) != GR_OK);
}

static void check_core(int k) {
  gr_state_core *c = &cores[k];
  if (!made || !c->sim) {
    CHECK_MSG(0, "no %s simulation", c->name);
    return;
  }
  unsigned char *buf = calloc(2 * c->bytes + 64, 1), *back = malloc(c->bytes);
  unsigned char *refused = calloc(c->bytes / 4 + 1, 1);
  if (!buf || !back || !refused) {
    CHECK(0);
    free(buf), free(back), free(refused);
    return;
  }
  CHECK_MSG(c->bytes > HEADER_ROOM + 256, "%s: a state of %zu bytes", c->name, c->bytes);
  CHECK(c->load(c->sim, c->valid, c->bytes) == GR_OK && intact(c, back, 1));

  const size_t sizes[] = {0,
                          1,
                          8,
                          c->bytes / 2,
                          c->bytes - 8,
                          c->bytes - 4,
                          c->bytes - 1,
                          c->bytes + 1,
                          c->bytes + 4,
                          2 * c->bytes};
  memcpy(buf, c->valid, c->bytes);
  for (size_t q = 0; q < sizeof(sizes) / sizeof(sizes[0]); ++q) {
    gr_status st = c->load(c->sim, buf, sizes[q]);
    CHECK_MSG(refused_with_sentence(c, st), "%s: a state of %zu bytes (of %zu): %s", c->name,
              sizes[q], c->bytes, st == GR_OK ? "loaded" : c->last_error(c->sim));
  }
  CHECK(intact(c, back, 1));

  int bad = sweep(c, 4, buf, back, refused) + sweep(c, 8, buf, back, refused) +
            huge_counts(c, buf) + huge_floats(c, buf);
  CHECK_MSG(bad == 0, "%s: %d refusals without a sentence or with the state changed", c->name, bad);
  size_t open = 0, first_open = 0, floats = 0, wides = 0;
  for (size_t p = HEADER_ROOM / 4; p < c->bytes / 4; ++p) {
    floats += (refused[p] & 1) != 0;
    wides += (refused[p] & 2) != 0;
    if (!refused[p] && open++ == 0)
      first_open = 4 * p;
  }
  CHECK_MSG(open == 0, "%s: NaN is loaded at %zu places past the header, the first at byte %zu",
            c->name, open, first_open);
  printf("%s: %zu bytes; past the header, NaN refused as a float32 at %zu and as a float64 or "
         "negative int64 at %zu of %zu places\n",
         c->name, c->bytes, floats, wides, c->bytes / 4 - HEADER_ROOM / 4);
  CHECK(intact(c, back, 1));
  free(buf), free(back), free(refused);
}

static void test_rain_runoff(void) {
  check_core(0);
}
static void test_snow_accumulation(void) {
  check_core(1);
}
static void test_snow_deformation(void) {
  check_core(2);
}
static void test_snow_melt(void) {
  check_core(3);
}
static void test_water_surface(void) {
  check_core(4);
}

int main(int argc, char **argv) {
  static const gr_subtest tests[] = {
      {"rain_runoff", test_rain_runoff, 0},
      {"snow_accumulation", test_snow_accumulation, 0},
      {"snow_deformation", test_snow_deformation, 0},
      {"snow_melt", test_snow_melt, 0},
      {"water_surface", test_water_surface, 0},
  };
  return gr_test_main(argc, argv, tests, (int)(sizeof(tests) / sizeof(tests[0])), setup, teardown);
}
