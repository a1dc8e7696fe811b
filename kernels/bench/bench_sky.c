/* graupel-bench --core sky: per step, the cloud cover image (Resolution n,
 * 6 octaves) at a time 60 s later than the step before, the wind drifting
 * it. The lightning is a few hundred points on the host and not timed. */
#include "bench.h"

#include <stdlib.h>

typedef struct sky_bench {
  gr_cloud_cover *clouds;
  double t;
} sky_bench;

static gr_status sky_setup(gr_context *ctx, int n, void **state) {
  gr_cloud_cover_params p;
  gr_cloud_cover_params_init(&p);
  p.resolution = n;
  sky_bench *b = calloc(1, sizeof(*b));
  if (!b)
    return GR_ERR_OUT_OF_MEMORY;
  gr_status st = gr_cloud_cover_create(ctx, &p, &b->clouds);
  if (st != GR_OK) {
    free(b);
    return st;
  }
  *state = b;
  return GR_OK;
}

static gr_status sky_step(void *state) {
  sky_bench *b = state;
  b->t += 60.0;
  return gr_cloud_cover_compute(b->clouds, b->t);
}

static void sky_teardown(void *state) {
  sky_bench *b = state;
  gr_cloud_cover_destroy(b->clouds);
  free(b);
}

/* The noise written and read back by the shading (8 bytes), cloud (4) and
 * sky_rgb (3) written. */
static const gr_bench_core bench = {"sky: cloud cover image, 6 octaves of drifting fBm (seed 001)",
                                    sky_setup,
                                    sky_step,
                                    sky_teardown,
                                    15.0,
                                    NULL,
                                    NULL};

const gr_bench_core *gr_bench_sky(void) {
  return &bench;
}
