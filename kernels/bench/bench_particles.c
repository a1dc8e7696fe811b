/* graupel-bench --core particles: --size N computes N x N rain drops (4096:
 * 2^24, the seed's largest count) at 10 mm/h with a 5 m/s wind in a
 * 1 km x 1 km x 200 m box, one time 1/60 s later per step. */
#include "bench.h"

#include <stdlib.h>

typedef struct particles_bench {
  gr_particles *p;
  double time;
} particles_bench;

static gr_status particles_setup(gr_context *ctx, int n, void **state) {
  gr_particles_params p;
  gr_particles_params_init(&p);
  p.count = n * n;
  p.wind[0] = 5.0;
  const double region[6] = {0.0, 1000.0, 0.0, 1000.0, 0.0, 200.0};
  for (int c = 0; c < 6; ++c)
    p.region[c] = region[c];
  particles_bench *b = calloc(1, sizeof(*b));
  if (!b)
    return GR_ERR_OUT_OF_MEMORY;
  gr_status st = gr_particles_create(ctx, &p, &b->p);
  if (st != GR_OK) {
    free(b);
    return st;
  }
  *state = b;
  return GR_OK;
}

static gr_status particles_step(void *state) {
  particles_bench *b = state;
  b->time += 1.0 / 60.0;
  return gr_particles_compute(b->p, b->time);
}

static void particles_teardown(void *state) {
  particles_bench *b = state;
  gr_particles_destroy(b->p);
  free(b);
}

/* Position, velocity and streak (3 floats each) and the diameter written
 * per particle; nothing read. */
static const gr_bench_core bench = {
    "rain particles: N x N drops at a time t (Marshall-Palmer, Atlas, wind; seed 004)",
    particles_setup,
    particles_step,
    particles_teardown,
    40.0,
    NULL,
    NULL};

const gr_bench_core *gr_bench_particles(void) {
  return &bench;
}
