/* Water surface core, host side (water_surface_internal.h): stepping (the
 * stable step, steps and advance with its progress), the outputs, the
 * ledger and reset. */
#include "water_surface_internal.h"

/* With a progress callback, advance waits after a batch of steps that takes
 * about this long (s) and calls the callback at most this often (s). */
#define GR_WS_BATCH_S 0.08
#define GR_WS_PROGRESS_EVERY 0.1

/* --------------------------------------------------------------- stepping */

/* The CFL limit of the step: c dt sqrt(1/dx^2 + 1/dy^2) <= 1. */
static double gr_ws_limit(const gr_water_surface *s) {
  const gr_grid *g = &s->grid;
  return 1.0 / (s->params.wave_speed * sqrt(1.0 / (g->dx * g->dx) + 1.0 / (g->dy * g->dy)));
}

gr_status gr_water_surface_stable_dt(gr_water_surface *s, double *dt) {
  if (!s || !dt)
    return s ? GR_WS_KEEP(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                          "gr_water_surface_stable_dt needs a place for dt."))
             : gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                            "gr_water_surface_stable_dt needs a simulation.");
  *dt = s->params.cfl * gr_ws_limit(s);
  return GR_OK;
}

/* Enqueues one step of dt: the wave update with this step's drops (one
 * kernel, which decides the drops and sums their Gaussians in local memory
 * tile by tile). */
static gr_status gr_ws_enqueue_one(gr_water_surface *s, double dt) {
  const gr_water_surface_params *p = &s->params;
  const gr_grid *gd = &s->grid;
  const size_t m = sizeof(cl_mem);
  cl_int nx = gd->nx, ny = gd->ny;
  double chance = p->drop_rate * gd->dx * gd->dy * dt;
  cl_uint threshold = chance >= 1.0 ? (cl_uint)16777216u : (cl_uint)floor(chance * 16777216.0);
  cl_int drops = p->drop_amplitude > 0.0 && threshold > 0;
  double sigma = p->drop_radius;
  cl_int rx = gr_ws_reach(sigma, gd->dx), ry = gr_ws_reach(sigma, gd->dy), gj0 = s->row0;
  cl_float dx = (cl_float)gd->dx, dy = (cl_float)gd->dy;
  cl_float inv_2sig2 = (cl_float)(1.0 / (2.0 * sigma * sigma));
  cl_uint seed = (cl_uint)p->seed;
  uint64_t k = (uint64_t)s->steps;
  cl_uint step_lo = (cl_uint)(k & 0xffffffffu), step_hi = (cl_uint)(k >> 32);
  cl_float inv_dx2 = (cl_float)(1.0 / (gd->dx * gd->dx));
  cl_float inv_dy2 = (cl_float)(1.0 / (gd->dy * gd->dy));
  cl_float c2dt = (cl_float)(p->wave_speed * p->wave_speed * dt), dtf = (cl_float)dt;
  cl_float damp = (cl_float)exp(-p->damping * dt);
  cl_float drop_coef = (cl_float)(0.5 * p->drop_amplitude * p->drop_radius * p->drop_radius);
  /* The tile's local memory: the drops of the tile and 1 + reach around it
   * (their offsets, and a bit mask per row of words of 32 points with one
   * spare word), g on the tile and one around it; minimal without drops. */
  const size_t *tile = s->tile;
  size_t gw = tile[0] + 2, gh = tile[1] + 2;
  size_t dw = gw + 2 * (size_t)rx, dh = gh + 2 * (size_t)ry, mw = (dw + 31) / 32 + 1;
  size_t drop_bytes = drops ? dw * dh * sizeof(cl_float2) : sizeof(cl_float2);
  size_t mask_bytes = drops ? dh * mw * sizeof(cl_uint) : sizeof(cl_uint);
  size_t g_bytes = drops ? gw * gh * sizeof(cl_float) : sizeof(cl_float);
  int now = 1 - s->cur;
  cl_int j_lo = s->ring_s, j_hi = s->ring_s + s->own_ny;
  const gr_ws_arg args[] = {
      {"h_in", m, &s->h[s->cur]},
      {"h_out", m, &s->h[now]},
      {"v", m, &s->v},
      {"wet", m, &s->wet},
      {"nx", sizeof(nx), &nx},
      {"ny", sizeof(ny), &ny},
      {"inv_dx2", sizeof(inv_dx2), &inv_dx2},
      {"inv_dy2", sizeof(inv_dy2), &inv_dy2},
      {"c2dt", sizeof(c2dt), &c2dt},
      {"dt", sizeof(dtf), &dtf},
      {"damp", sizeof(damp), &damp},
      {"drops", sizeof(drops), &drops},
      {"drop_coef", sizeof(drop_coef), &drop_coef},
      {"j_lo", sizeof(j_lo), &j_lo},
      {"j_hi", sizeof(j_hi), &j_hi},
      {"dx", sizeof(dx), &dx},
      {"dy", sizeof(dy), &dy},
      {"inv_2sig2", sizeof(inv_2sig2), &inv_2sig2},
      {"reach_x", sizeof(rx), &rx},
      {"reach_y", sizeof(ry), &ry},
      {"threshold", sizeof(threshold), &threshold},
      {"seed", sizeof(seed), &seed},
      {"step_lo", sizeof(step_lo), &step_lo},
      {"step_hi", sizeof(step_hi), &step_hi},
      {"gj0", sizeof(gj0), &gj0},
      {"drop_at", drop_bytes, NULL},
      {"drop_mask", mask_bytes, NULL},
      {"g_tile", g_bytes, NULL},
  };
  gr_status st = GR_WS_ARGS(s, s->step, args);
  if (st == GR_OK)
    st = gr_enqueue_2d(s->ctx, s->step, 0, (size_t)j_lo, (size_t)nx, (size_t)(j_hi - j_lo), tile);
  if (st != GR_OK)
    return st;
  s->cur = now;
  s->steps += 1;
  s->time += dt;
  s->last_dt = dt;
  /* A piece's ring row of h: the neighbour's new row, for the next step
   * (and the ledger's and the normals' differences across the cut). */
  if (gr_ws_pieced(s)) {
    st = s->halo_exchange(s->halo_user);
    if (st != GR_OK)
      return gr_set_error(s->ctx, st,
                          "The water surface piece's halo exchange (the callback given to "
                          "gr_water_surface_set_halo_exchange) failed in step %lld with %s; the "
                          "piece's ring is not fresh, so restore a checkpoint before stepping on.",
                          s->steps, gr_status_string(st));
  }
  return GR_OK;
}

/* What every stepping call checks first: water, and the wave's time-0 sum. */
static gr_status gr_ws_ready(gr_water_surface *s) {
  if (gr_ws_pieced(s) && (!s->allreduce || !s->halo_exchange))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "A water surface piece with neighbours steps only with an allreduce and "
                        "a halo exchange set (gr_water_surface_set_allreduce, "
                        "gr_water_surface_set_halo_exchange).");
  gr_status st = gr_ws_prepare(s);
  return st == GR_OK ? gr_ws_know_initial(s) : st;
}

static gr_status gr_ws_step_impl(gr_water_surface *s, double dt, int nsteps) {
  double limit = gr_ws_limit(s);
  if (!(dt > 0.0 && dt <= limit * (1.0 + 1e-12)))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The water surface's time step must be above 0 and at most the CFL "
                        "limit %g s for WaveSpeed %g m/s on this grid (got %g s): take shorter "
                        "steps.",
                        limit, s->params.wave_speed, dt);
  if (nsteps < 0)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The number of steps must be 0 or more (got %d).", nsteps);
  gr_status st = gr_ws_ready(s);
  for (int k = 0; st == GR_OK && k < nsteps; ++k)
    st = gr_ws_enqueue_one(s, dt);
  return st;
}

gr_status gr_water_surface_step(gr_water_surface *s, double dt, int nsteps) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT, "gr_water_surface_step needs a simulation.");
  return GR_WS_KEEP(s, gr_ws_step_impl(s, dt, nsteps));
}

static double gr_ws_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static gr_status gr_ws_advance_impl(gr_water_surface *s, double duration, int *taken) {
  if (!(duration >= 0.0 && duration < HUGE_VAL))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The duration to advance must be a finite number of seconds, 0 or more "
                        "(got %g).",
                        duration);
  gr_status st = gr_ws_ready(s);
  if (st != GR_OK || duration == 0.0)
    return st;
  double stable = s->params.cfl * gr_ws_limit(s), n = ceil(duration / stable);
  if (n < 1.0)
    n = 1.0;
  if (n > (double)INT_MAX)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "Advancing the water surface by %g s takes more than %d steps of %g s: "
                        "advance in parts.",
                        duration, INT_MAX, stable);
  /* Equal steps ending exactly at the duration; the progress watch only adds
   * waits, so what is computed never depends on it. */
  double dt = duration / n, last_call = gr_ws_now(), last_wait = last_call;
  int total = (int)n, batch = 1, since = 0, stop = 0;
  for (int k = 0; st == GR_OK && k < total; ++k) {
    st = gr_ws_enqueue_one(s, dt);
    if (st != GR_OK)
      break;
    ++*taken;
    if (s->progress && ++since >= batch && k + 1 < total) {
      st = gr_finish(s->ctx);
      double now = gr_ws_now(), span = now - last_wait;
      if (span < 0.5 * GR_WS_BATCH_S && batch < (1 << 20))
        batch *= 2;
      else if (span > GR_WS_BATCH_S && batch > 1)
        batch /= 2;
      since = 0;
      last_wait = now;
      if (st == GR_OK && now - last_call >= GR_WS_PROGRESS_EVERY) {
        last_call = now;
        stop = s->progress(s->progress_user, s->time) != 0;
      }
    }
    /* The pieces' callbacks run at their own wall times: a stop asked on
     * any piece stops every piece after this same step. */
    if (st == GR_OK && gr_ws_pieced(s) && k + 1 < total) {
      double flag = stop;
      st = gr_ws_allreduce(s, &flag, 1, GR_REDUCE_MAX);
      stop = flag > 0.0;
    }
    if (st == GR_OK && stop)
      return gr_set_error(s->ctx, GR_ERR_ABORTED,
                          "The water surface advance was stopped by its progress callback at %g s "
                          "of simulated time; the state is valid there.",
                          s->time);
  }
  return st;
}

gr_status gr_water_surface_advance(gr_water_surface *s, double duration, int *steps_taken) {
  if (steps_taken)
    *steps_taken = 0;
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_water_surface_advance needs a simulation.");
  int taken = 0;
  gr_status st = gr_ws_advance_impl(s, duration, &taken);
  if (steps_taken)
    *steps_taken = taken;
  return GR_WS_KEEP(s, st);
}

void gr_water_surface_set_progress(gr_water_surface *s, gr_progress_fn fn, void *user) {
  if (!s)
    return;
  s->progress = fn;
  s->progress_user = fn ? user : NULL;
}

/* ---------------------------------------------------------------- reading */

static gr_status gr_ws_derive(gr_water_surface *s, cl_int what, size_t comps, float *host) {
  size_t n = gr_ws_points(s);
  gr_status st = GR_OK;
  if (!s->scratch)
    st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, 3 * n * sizeof(cl_float), NULL, &s->scratch);
  cl_int nx = s->grid.nx, ny = s->grid.ny;
  cl_float inv_dx = (cl_float)(1.0 / s->grid.dx), inv_dy = (cl_float)(1.0 / s->grid.dy);
  const size_t m = sizeof(cl_mem);
  const gr_ws_arg args[] = {
      {"h", m, &s->h[s->cur]},
      {"base", m, &s->base},
      {"wet", m, &s->wet},
      {"out", m, &s->scratch},
      {"nx", sizeof(nx), &nx},
      {"ny", sizeof(ny), &ny},
      {"inv_dx", sizeof(inv_dx), &inv_dx},
      {"inv_dy", sizeof(inv_dy), &inv_dy},
      {"what", sizeof(what), &what},
  };
  if (st == GR_OK)
    st = GR_WS_ARGS(s, s->derive, args);
  if (st == GR_OK)
    st =
        gr_enqueue_2d(s->ctx, s->derive, 0, (size_t)s->ring_s, (size_t)nx, (size_t)s->own_ny, NULL);
  /* The own rows (a piece's local arrays hold its rings around them). */
  if (st == GR_OK)
    st = gr_buffer_read(s->ctx, s->scratch, comps * gr_ws_own_first(s) * sizeof(cl_float),
                        comps * gr_ws_own_points(s) * sizeof(cl_float), host);
  return st;
}

static gr_status gr_ws_get_impl(gr_water_surface *s, gr_water_surface_output o, float *host) {
  if ((int)o < 0 || o >= GR_WATER_OUTPUT_COUNT)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The water surface has no output %d; its outputs are wave_height, "
                        "normal, water_surface, wet, elevation and water_depth.",
                        (int)o);
  size_t n = gr_ws_own_points(s), first = gr_ws_own_first(s);
  if (o == GR_WATER_ELEVATION) {
    memcpy(host, s->elevation + first, n * sizeof(float));
    return GR_OK;
  }
  gr_status st = gr_ws_prepare(s);
  if (st != GR_OK)
    return st;
  switch (o) {
  case GR_WATER_WAVE_HEIGHT:
    return gr_ws_derive(s, GR_WATER_SURFACE_DERIVE_WAVE, 1, host);
  case GR_WATER_NORMAL:
    return gr_ws_derive(s, GR_WATER_SURFACE_DERIVE_NORMAL, 3, host);
  case GR_WATER_SURFACE:
    return gr_ws_derive(s, GR_WATER_SURFACE_DERIVE_SURFACE, 1, host);
  case GR_WATER_WET:
    return gr_ws_derive(s, GR_WATER_SURFACE_DERIVE_WET, 1, host);
  default: {
    /* water_depth: the input, or the lake's depth over its wet points. */
    float level = (float)s->params.lake_level;
    for (size_t c = 0; c < n; ++c) {
      float b = s->elevation[first + c];
      if (!gr_ws_lake(s))
        host[c] = s->depth[first + c];
      else
        host[c] = b < level ? level - b : 0.0f;
    }
    return GR_OK;
  }
  }
}

gr_status gr_water_surface_get(gr_water_surface *s, gr_water_surface_output o, float *host) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_water_surface_get needs a simulation and room for the output.");
  if (!host)
    return GR_WS_KEEP(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "gr_water_surface_get needs a simulation and room for the "
                                      "output."));
  return GR_WS_KEEP(s, gr_ws_get_impl(s, o, host));
}

static gr_status gr_ws_ledger_impl(gr_water_surface *s, gr_water_surface_ledger *out) {
  double sums[3], hmax = 0.0;
  gr_status st = gr_ws_ready(s);
  if (st == GR_OK)
    st = gr_ws_reduce(s, sums, &hmax);
  if (st != GR_OK)
    return st;
  double area = s->grid.dx * s->grid.dy;
  memset(out, 0, sizeof(*out));
  out->time = s->time;
  out->steps = s->steps;
  out->wet_points = (long long)sums[2];
  out->wave_volume = sums[0] * area;
  out->initial_volume = s->initial_sum * area;
  out->energy = sums[1] * area;
  out->max_wave = hmax;
  return GR_OK;
}

gr_status gr_water_surface_ledger_get(gr_water_surface *s, gr_water_surface_ledger *out) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_water_surface_ledger_get needs a simulation and a ledger to fill.");
  if (!out)
    return GR_WS_KEEP(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "gr_water_surface_ledger_get needs a simulation and a "
                                      "ledger to fill."));
  return GR_WS_KEEP(s, gr_ws_ledger_impl(s, out));
}

static gr_status gr_ws_reset_impl(gr_water_surface *s) {
  size_t bytes = gr_ws_points(s) * sizeof(cl_float);
  gr_status st;
  if (s->h0)
    st = gr_cl_check(s->ctx,
                     clEnqueueCopyBuffer(gr_context_queue(s->ctx), s->h0, s->h[s->cur], 0, 0, bytes,
                                         0, NULL, NULL),
                     "Copying the initial wave");
  else
    st = gr_ws_fill(s, s->h[s->cur], 0.0f, bytes);
  if (st == GR_OK)
    st = gr_ws_fill(s, s->v, 0.0f, bytes);
  if (st == GR_OK) {
    s->time = 0.0;
    s->steps = 0;
    s->last_dt = 0.0;
    s->initial_known = 0;
  }
  return st;
}

gr_status gr_water_surface_reset(gr_water_surface *s) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_water_surface_reset needs a simulation.");
  return GR_WS_KEEP(s, gr_ws_reset_impl(s));
}
