/* libFuzzer harness: the cores' checkpoint readers, gr_<core>_state_load,
 * for the five cores that keep checkpoints (the bytes a RestartFile's
 * piece carries in its graupel_state array).
 *
 * Set-up, once (LLVMFuzzerInitialize): a context on the OpenCL CPU device
 * (PoCL) and the small simulations of Testing/C/gr_test_states.h, one per
 * core, with something in their state (rain and a slope, snow on ridges
 * under a box, snow under a box that moves, melting snow, a lake with
 * waves); each state saved (the valid state), then stepped once more and
 * saved again (the valid state one step on). Without an OpenCL device the harness says
 * "skipped: no OpenCL device" (the ctest skips on it) and stops.
 *
 * Input layout (missing bytes read as 0): byte 0 picks the core (of 5),
 * byte 1 what the rest makes:
 *   mode 0  the rest, as it is, is the state;
 *   mode 1  the valid state with patches: (offset u32, length u8 % 16 + 1,
 *           that many bytes) until the input ends;
 *   mode 2  the valid state cut or grown to a length (u32 % (2 size + 64);
 *           grown with the rest of the input, then zeros);
 *   mode 3  the valid state with values poisoned: (place u32, kind u8)
 *           until the input ends; kind picks a float32 at a 4-byte place
 *           or a float64 at an 8-byte place, and NaN, +-Inf, -1, -0,
 *           3e38, 1e308 or the largest int64 as its value.
 *
 * Checks, per input, the simulation starting from the valid state: the
 * load gives GR_OK or a refusal (any status but GR_OK) with a sentence
 * (the simulation's last error, ending in '.'); a refused load leaves the
 * state as it was (state_save gives the valid bytes back) and the
 * simulation steps on from it to the valid state one step on, bit for
 * bit; after an accepted load a step may fail (with a sentence) but not
 * crash, nor may the ledger that follows it, and loading the valid state
 * again and stepping gives the same bits. No crash, no sanitizer report, no leak. */
#include "fuzz_common.h"
#include "gr_test_states.h" /* Testing/C: the five simulations, as the state tests make them */

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static gr_state_core cores[GR_STATE_CORES];
static gr_context *ctx;
static unsigned char *scratch;

static void fail_setup(const char *what, gr_status st, const char *why) {
  fprintf(stderr, "fuzz_state_load: %s: %s: %s\n", what, gr_status_string(st), why);
  exit(1);
}

int LLVMFuzzerInitialize(int *argc, char ***argv) {
  (void)argc, (void)argv;
  gr_context_options opt;
  gr_context_options_init(&opt);
  opt.device = "cpu";
  gr_status st = gr_context_create(&opt, &ctx);
  if (st == GR_ERR_NO_PLATFORM || st == GR_ERR_NO_DEVICE) {
    printf("fuzz_state_load: skipped: no OpenCL device (%s)\n", gr_last_error(NULL));
    fflush(stdout);
    exit(0);
  }
  if (st != GR_OK)
    fail_setup("context", st, gr_last_error(NULL));
  const char *failed = "";
  st = gr_state_cores_make(ctx, cores, &failed);
  if (st != GR_OK)
    fail_setup(failed, st, gr_last_error(NULL));
  size_t most = 0;
  for (int k = 0; k < GR_STATE_CORES; ++k) {
    /* The step changed something, or a load could not be told from none. */
    REQUIRE(memcmp(cores[k].valid, cores[k].stepped, cores[k].bytes) != 0);
    most = cores[k].bytes > most ? cores[k].bytes : most;
  }
  scratch = malloc(2 * most + 64 + 65536);
  REQUIRE(scratch != NULL);
  return 0;
}

/* Released at exit, so that LeakSanitizer sees only what an input leaked. */
__attribute__((destructor)) static void release_all(void) {
  gr_state_cores_free(cores);
  free(scratch);
  gr_context_release(ctx);
}

/* ------------------------------------------------------------ the inputs */

static uint32_t take_u32(reader *r) {
  uint8_t b[4];
  take(r, b, sizeof b);
  return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

/* Poisons one value of buf (n bytes) as kind says, at place. */
static void poison(unsigned char *buf, size_t n, uint32_t place, uint8_t kind) {
  static const float f[] = {NAN, INFINITY, -INFINITY, -1.0f, -0.0f, 3e38f};
  static const double d[] = {NAN, INFINITY, -INFINITY, -1.0, 1e308};
  int wide = kind % 2;
  size_t width = wide ? 8 : 4;
  if (n < width)
    return;
  size_t at = (size_t)place % (n / width) * width;
  if (!wide) {
    memcpy(buf + at, &f[(kind / 2) % 6], 4);
  } else if ((kind / 2) % 6 == 5) {
    const int64_t big = INT64_MAX;
    memcpy(buf + at, &big, 8);
  } else {
    memcpy(buf + at, &d[(kind / 2) % 6], 8);
  }
}

/* The bytes the input makes for core c in scratch; their count. */
static size_t make_state(const gr_state_core *c, int mode, reader *r) {
  size_t n = c->bytes;
  switch (mode) {
  case 0:
    memcpy(scratch, r->p, r->n);
    return r->n;
  case 1:
    memcpy(scratch, c->valid, n);
    while (r->n > 0) {
      size_t at = take_u32(r) % n, len = take_byte(r) % 16 + 1;
      if (at + len > n)
        len = n - at;
      take(r, scratch + at, len);
    }
    return n;
  case 2: {
    size_t len = take_u32(r) % (2 * n + 64);
    memcpy(scratch, c->valid, len < n ? len : n);
    if (len > n)
      take(r, scratch + n, len - n);
    return len;
  }
  default:
    memcpy(scratch, c->valid, n);
    while (r->n > 0) {
      uint32_t place = take_u32(r);
      poison(scratch, n, place, take_byte(r));
    }
    return n;
  }
}

/* A refusal's sentence: the simulation's last error, ending in '.'. */
static void check_sentence(const gr_state_core *c) {
  const char *m = c->last_error(c->sim);
  size_t len = m ? strlen(m) : 0;
  REQUIRE(len > 1 && m[len - 1] == '.');
}

/* The simulation steps from the valid state to the valid state one step on. */
static void check_steps_on(const gr_state_core *c) {
  REQUIRE(c->step(c->sim) == GR_OK);
  REQUIRE(c->save(c->sim, scratch, c->bytes) == GR_OK);
  REQUIRE(memcmp(scratch, c->stepped, c->bytes) == 0);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  reader r = {data, size};
  const gr_state_core *c = &cores[take_byte(&r) % GR_STATE_CORES];
  int mode = take_byte(&r) % 4;
  if (size > 65536)
    return 0;
  REQUIRE(c->load(c->sim, c->valid, c->bytes) == GR_OK);
  size_t n = make_state(c, mode, &r);
  gr_status st = c->load(c->sim, scratch, n);
  if (st != GR_OK) {
    check_sentence(c);
    REQUIRE(c->save(c->sim, scratch, c->bytes) == GR_OK);
    REQUIRE(memcmp(scratch, c->valid, c->bytes) == 0);
    check_steps_on(c);
    return 0;
  }
  if (c->step(c->sim) != GR_OK)
    check_sentence(c);
  if (c->ledger(c->sim) != GR_OK)
    check_sentence(c);
  REQUIRE(c->load(c->sim, c->valid, c->bytes) == GR_OK);
  check_steps_on(c);
  return 0;
}
