/* Rain runoff core, host side: the stable step of both flow models and
 * advance, with its progress callback's watch over the queue
 * (rain_runoff_internal.h). */
#include "rain_runoff_internal.h"

/* The shallow-water step takes this times CourantNumber of its positivity
 * bound (gr_rain_runoff_sw_stable_dt), at most all of it: CourantNumber is
 * shared with the local inertial model, whose limit (1 / sqrt(2)) sets its
 * default 0.7; this makes that 0.9 of the bound for shallow water (it was
 * 0.7: 1.29 times the steps). */
#define GR_RAIN_RUNOFF_SW_COURANT (9.0 / 7.0)

static double gr_rain_runoff_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* A piece's watch: its own progress callback (if any) only raises a flag,
 * and the flags of every piece are reduced after every step, so all pieces
 * stop after the same step whichever asked; every piece makes this call at
 * every step, callback or not, so the allreduce calls match. One 8-byte
 * reduction per step costs little next to the step's halo exchange. */
static gr_status gr_rain_runoff_watch_global(gr_rain_runoff *s, gr_rain_runoff_watch *w,
                                             double time, int *stop) {
  double flag = 0.0;
  gr_status st = GR_OK;
  if (s->progress) {
    /* The exchange has usually waited already; this makes the time the
     * device's for a piece without a ring too. */
    st = gr_finish(s->ctx);
    double now = gr_rain_runoff_now();
    if (st == GR_OK && now - w->last_call >= GR_RAIN_RUNOFF_PROGRESS_EVERY) {
      w->last_call = now;
      if (s->progress(s->progress_user, time) != 0)
        flag = 1.0;
    }
  }
  /* Reached even when the wait failed: a piece that skipped the collective
   * would leave the others waiting in it. */
  gr_status sr = gr_rain_runoff_allreduce(s, &flag, 1, GR_REDUCE_MAX);
  if (st == GR_OK)
    st = sr;
  if (st == GR_OK && flag != 0.0)
    *stop = 1;
  return st;
}

/* Called after each enqueued step; `time` is the simulated time it reaches.
 * *stop becomes 1 when the callback asks to stop. */
gr_status gr_rain_runoff_watch_step(gr_rain_runoff *s, gr_rain_runoff_watch *w, double time,
                                    int *stop) {
  if (w->global)
    return gr_rain_runoff_watch_global(s, w, time, stop);
  if (++w->since < w->batch)
    return GR_OK;
  gr_status st = gr_finish(s->ctx);
  if (st != GR_OK)
    return st;
  double now = gr_rain_runoff_now(), span = now - w->last_wait;
  if (span < 0.5 * GR_RAIN_RUNOFF_BATCH_S && w->batch < (1 << 20))
    w->batch *= 2;
  else if (span > GR_RAIN_RUNOFF_BATCH_S && w->batch > 1)
    w->batch /= 2;
  w->since = 0;
  w->last_wait = now;
  if (now - w->last_call >= GR_RAIN_RUNOFF_PROGRESS_EVERY) {
    w->last_call = now;
    if (s->progress(s->progress_user, time) != 0)
      *stop = 1;
  }
  return GR_OK;
}

/* ------------------------------------------------------------ stable step */

/* The longest step dt whose gravity wave, in the water that rain and
 * inflows arriving at `rate` (m/s of depth) make on dry (or still) ground
 * within the step, r dt deep, crosses no more than `reach` metres:
 *   sqrt(g r dt) dt <= reach,   dt = (reach / sqrt(g r))^(2/3).
 * Both models' stable steps take it, each with its own reach: a step
 * computed from the water there is before the step's rain lands is
 * unbounded on dry ground (MaxTimeStep long), and the rain of that step,
 * which the step's own faces already see, makes water whose waves it
 * outruns. HUGE_VAL with no water arriving. */
static double gr_rain_runoff_rain_dt(double rate, double reach) {
  return rate > 0.0 ? pow(reach / sqrt(GR_GRAVITY * rate), 2.0 / 3.0) : HUGE_VAL;
}

/* Shallow water: the Courant condition of the explicit finite volumes on the
 * fastest waves of any cell, |u| + sqrt(g h) along x and |v| + sqrt(g h)
 * along y:  dt max(ax / dx + ay / dy) <= c / 2,
 * the half keeping the hydrostatic reconstruction's depths positive with the
 * second-order reconstruction (Audusse et al. 2004), and c the fraction of
 * that bound taken: GR_RAIN_RUNOFF_SW_COURANT cfl, at most 1. */
static gr_status gr_rain_runoff_sw_stable_dt(gr_rain_runoff *s, double *dt) {
  cl_int n = (cl_int)gr_rain_runoff_cells(s);
  cl_int row = s->nxl, own_x0 = s->ring[0], own_x1 = s->nxl - s->ring[1];
  cl_int own_y0 = s->ring[2], own_y1 = s->nyl - s->ring[3];
  cl_int masked = gr_rain_runoff_has_ring(s);
  cl_float g = (cl_float)GR_GRAVITY;
  cl_float inv_dx = (cl_float)(1.0 / s->grid.dx), inv_dy = (cl_float)(1.0 / s->grid.dy);
  const gr_rain_runoff_arg args[] = {
      {"inv_dx", sizeof(inv_dx), &inv_dx},
      {"inv_dy", sizeof(inv_dy), &inv_dy},
      {"h", sizeof(cl_mem), &s->h},
      {"qu", sizeof(cl_mem), &s->qu},
      {"qv", sizeof(cl_mem), &s->qv},
      {"n", sizeof(n), &n},
      {"row", sizeof(row), &row},
      {"own_x0", sizeof(own_x0), &own_x0},
      {"own_x1", sizeof(own_x1), &own_x1},
      {"own_y0", sizeof(own_y0), &own_y0},
      {"own_y1", sizeof(own_y1), &own_y1},
      {"masked", sizeof(masked), &masked},
      {"g", sizeof(g), &g},
  };
  /* The deepest cell, the fastest rate, the heaviest rain (m/s), the
   * steepest bed (slope_rate). */
  double maxes[4] = {0.0, 0.0,
                     (s->has_rain ? s->rain_field_max : gr_rain_runoff_rain_max(s)) +
                         gr_rain_runoff_source_max(s),
                     s->slope_rate};
  gr_status st = GR_RAIN_RUNOFF_ARGS(s, s->sw_speed, args);
  if (st == GR_OK)
    st = gr_reduction_run(s->ctx, &s->speed, s->sw_speed, NULL, maxes);
  /* A level edge's water enters at up to twice its wave speed (a dry
   * front's, HLL's). */
  double edge = gr_rain_runoff_edge_depth(s);
  if (edge > 0.0) {
    double c2 = 2.0 * sqrt(GR_GRAVITY * edge) * (1.0 / s->grid.dx + 1.0 / s->grid.dy);
    maxes[0] = edge > maxes[0] ? edge : maxes[0];
    maxes[1] = c2 > maxes[1] ? c2 : maxes[1];
  }
  if (st == GR_OK && s->allreduce)
    st = gr_rain_runoff_allreduce(s, maxes, 4, GR_REDUCE_MAX);
  if (st != GR_OK)
    return st;
  double rate = maxes[1];
  double c = fmin(1.0, GR_RAIN_RUNOFF_SW_COURANT * s->params.cfl);
  double stable = rate > 0.0 ? 0.5 * c / rate : s->params.max_dt;
  /* Rain on dry (or still) ground: the step must not outrun the waves of
   * the water it adds, r dt deep: dt sqrt(g r dt) (1/dx + 1/dy) <= cfl / 2.
   * Without it a dry grid's first step is MaxTimeStep long. */
  double r = maxes[2];
  if (r > 0.0) {
    double wet =
        gr_rain_runoff_rain_dt(r, 0.5 * s->params.cfl / (1.0 / s->grid.dx + 1.0 / s->grid.dy));
    stable = wet < stable ? wet : stable;
  }
  /* Frictionless water on a slope gains g S dt of speed within the step,
   * before the second stage moves it: a film on a steep bed that starts
   * still (which the speeds above cannot see) would cross cells in that
   * stage. So, with ManningN 0, also
   *   dt^2 g max(|db/dx| / dx + |db/dy| / dy) <= cfl / 8,
   * (both together: c / 2 + cfl / 8 at worst, 0.54 at the default cfl
   * 0.7, a little over the 1/2 that keeps depths positive, as 1.25 cfl / 2
   * was above cfl 0.8), each bound a function of
   * one maximum, so that pieces taking the smallest of their steps take
   * the whole grid's. With friction, taken in each stage, a film gains no
   * more than its Manning speed, and no bound is needed. (sw_thin_films
   * shows both: frictionless rain on slopes up to 3, with MaxTimeStep 1 s,
   * emptied cells beyond their water without it.) */
  double accel = maxes[3];
  if (accel > 0.0 && gr_rain_runoff_min_n(s) == 0.0 && (maxes[0] > 0.0 || r > 0.0)) {
    double steep = sqrt(0.125 * s->params.cfl / accel);
    stable = steep < stable ? steep : stable;
  }
  *dt = stable < s->params.max_dt ? stable : s->params.max_dt;
  return GR_OK;
}

/* The local inertial model's kinematic rate (1/s): rain_runoff_li_speed
 * reduced over the owned cells. */
static gr_status gr_rain_runoff_film_rate(gr_rain_runoff *s, double *rate) {
  cl_int n = (cl_int)gr_rain_runoff_cells(s);
  cl_int row = s->nxl, rows = s->nyl, own_x0 = s->ring[0], own_x1 = s->nxl - s->ring[1];
  cl_int own_y0 = s->ring[2], own_y1 = s->nyl - s->ring[3];
  cl_int use_nodata = s->has_nodata, use_n2 = s->has_n2;
  cl_float n2 = (cl_float)(s->params.manning_n * s->params.manning_n);
  cl_float inv_dx = (cl_float)(1.0 / s->grid.dx), inv_dy = (cl_float)(1.0 / s->grid.dy);
  cl_float g = (cl_float)GR_GRAVITY, cfl = (cl_float)s->params.cfl;
  const gr_rain_runoff_arg args[] = {
      {"h", sizeof(cl_mem), &s->h},
      {"b", sizeof(cl_mem), &s->b},
      {"nodata", sizeof(cl_mem), s->has_nodata ? &s->nodata : &s->dummy},
      {"use_nodata", sizeof(use_nodata), &use_nodata},
      {"n2map", sizeof(cl_mem), s->has_n2 ? &s->n2map : &s->dummy},
      {"use_n2", sizeof(use_n2), &use_n2},
      {"n2", sizeof(n2), &n2},
      {"n", sizeof(n), &n},
      {"row", sizeof(row), &row},
      {"rows", sizeof(rows), &rows},
      {"own_x0", sizeof(own_x0), &own_x0},
      {"own_x1", sizeof(own_x1), &own_x1},
      {"own_y0", sizeof(own_y0), &own_y0},
      {"own_y1", sizeof(own_y1), &own_y1},
      {"inv_dx", sizeof(inv_dx), &inv_dx},
      {"inv_dy", sizeof(inv_dy), &inv_dy},
      {"g", sizeof(g), &g},
      {"cfl", sizeof(cfl), &cfl},
  };
  gr_status st = GR_RAIN_RUNOFF_ARGS(s, s->li_speed, args);
  if (st == GR_OK)
    st = gr_reduction_run(s->ctx, &s->film, s->li_speed, NULL, rate);
  return st;
}

static gr_status gr_rain_runoff_stable_dt_impl(gr_rain_runoff *s, double *dt) {
  if (s->params.flow_model == GR_FLOW_SHALLOW_WATER)
    return gr_rain_runoff_sw_stable_dt(s, dt);
  /* li_speed reads the no-data cells and the Manning map. */
  gr_status st = gr_rain_runoff_specialise(s);
  if (st != GR_OK)
    return st;
  /* The deepest cell and the fastest that water arrives (m/s): the
   * heaviest rain and the strongest inflow. */
  double maxes[3] = {0.0, 0.0, 0.0};
  st = gr_rain_runoff_deepest(s, &maxes[0]);
  if (st == GR_OK)
    st = gr_rain_runoff_film_rate(s, &maxes[2]);
  maxes[1] =
      (s->has_rain ? s->rain_field_max : gr_rain_runoff_rain_max(s)) + gr_rain_runoff_source_max(s);
  /* A level edge's water counts as the grid's. */
  double edge = gr_rain_runoff_edge_depth(s);
  maxes[0] = edge > maxes[0] ? edge : maxes[0];
  /* The whole domain's: every piece takes the same step. */
  if (st == GR_OK && s->allreduce)
    st = gr_rain_runoff_allreduce(s, maxes, 3, GR_REDUCE_MAX);
  if (st != GR_OK)
    return st;
  /* The scheme's stability limit in 2-D for gravity waves, c = sqrt(g h)
   * at the deepest cell: a checkerboard mode of the staggered grid, damped
   * by the smoothing to 2 theta - 1 per step, grows unless
   *   c dt sqrt(1/dx^2 + 1/dy^2) <= sqrt(theta).
   * (Bates et al. 2010's cfl dx / sqrt(g h) is the 1-D limit; in 2-D it
   * allows steps sqrt(2 / theta) times too long.) cfl is the fraction of the
   * limit taken. The flow speed |u| is left out on purpose: the local
   * inertial equations have no advection term, and q / h of a cell that a
   * step has just drained would shrink the step for nothing.
   *   The rain and inflow of the step add to that: the step's faces see
   * each cell's depth after them, h + r dt. On dry ground, where h_max
   * alone allowed any step up to MaxTimeStep, the step also keeps the
   * waves of r dt within the limit (gr_rain_runoff_rain_dt). Each bound is
   * a function of one maximum, as shallow water's are, so that pieces taking
   * the smallest of their steps take the whole grid's; where both bind, h +
   * r dt is at most twice the depth either allows, a wave sqrt(2) faster:
   * within the limit while cfl <= 1 / sqrt(2) (the default is 0.7).
   *   Friction adds a bound of its own on thin films on steep slopes.
   * It is implicit (Bates et al. 2010):
   *   q' (1 + kf |q'|) = q~ - g h dt S,   kf = g dt n^2 / h^(7/3),
   * so a long step tends to the Manning discharge h^(5/3) sqrt|S| / n and
   * never beyond it, and q's response to the surface slope, dq'/dS =
   * -g h dt / (1 + 2 kf |q'|), is at most the frictionless g h dt: as a
   * diffusion of the surface its explicit limit lies within the gravity-wave
   * limit above. Its response to the depth is not bounded so. With
   * kf q'^2 = g h dt |S| - q' (for q~ = 0),
   *   dq'/dh = g dt |S| (10/3 - (7/3) q' / (g h dt |S|)) / (1 + 2 kf |q'|),
   * the celerity of the film's kinematic wave: 5/3 of the Manning speed
   * u = h^(2/3) sqrt|S| / n on a long step, at most (10/3) g |S| dt on a
   * short one. That wave moves upwind and explicitly, monotone only while it
   * crosses at most a cell a step, dt dq'/dh / dx <= 1, and u / sqrt(g h)
   * (the Froude number, h^(1/6) sqrt|S| / (n sqrt g): 2.7 for 1 cm on a
   * slope of 0.3 with n 0.03, 8 with n 0.01) is not bounded: a
   * supercritical film takes gravity-limited steps in which it would leave
   * its cell several times over. The limiter then lets each cell empty once
   * a step, the water moves a cell a step, slower than the film, and piles
   * up: with no cap, tilted_plane_uncapped's plane of slope 0.3 with n 0.01
   * stood two to three times too deep. So also dt <= cfl / rate, the rate
   * the fastest face's of rain_runoff_li_speed: min(5/3 u / d, sqrt(cfl
   * (10/3) g |S| / d)) per face, each direction's Courant condition on its
   * own faces (as the faces of the two directions are computed apart). It
   * takes each face's Manning speed from its depth and surface slope, not
   * q / h, which a cell just drained makes large for nothing; a lake at
   * rest has none. */
  double inv = sqrt(1.0 / (s->grid.dx * s->grid.dx) + 1.0 / (s->grid.dy * s->grid.dy));
  double c = sqrt(GR_GRAVITY * maxes[0]);
  double stable =
      c > 0.0 ? s->params.cfl * sqrt(GR_RAIN_RUNOFF_THETA) / (c * inv) : s->params.max_dt;
  double wet = gr_rain_runoff_rain_dt(maxes[1], s->params.cfl * sqrt(GR_RAIN_RUNOFF_THETA) / inv);
  stable = wet < stable ? wet : stable;
  double film = maxes[2] > 0.0 ? s->params.cfl / maxes[2] : HUGE_VAL;
  stable = film < stable ? film : stable;
  *dt = stable < s->params.max_dt ? stable : s->params.max_dt;
  return GR_OK;
}

gr_status gr_rain_runoff_stable_dt(gr_rain_runoff *s, double *dt) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_stable_dt needs a simulation and a place for dt.");
  if (!dt)
    return GR_RAIN_RUNOFF_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_stable_dt needs a simulation and a place for dt."));
  return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_rain_runoff_stable_dt_impl(s, dt));
}

static gr_status gr_rain_runoff_advance_impl(gr_rain_runoff *s, double duration,
                                             long long *taken_out) {
  if (!(duration >= 0.0 && duration < HUGE_VAL))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The duration to advance must be a finite number of seconds, 0 or more "
                        "(got %g).",
                        duration);
  if (gr_rain_runoff_has_ring(s) && (!s->allreduce || !s->halo_exchange))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "A rain runoff piece with neighbours advances only with a global "
                        "reduction and a halo exchange (it has %s and %s): set them with "
                        "gr_rain_runoff_set_allreduce and gr_rain_runoff_set_halo_exchange, or "
                        "step it with gr_rain_runoff_step, exchanging its halo between steps.",
                        s->allreduce ? "one" : "none", s->halo_exchange ? "one" : "none");
  /* The stable step is read back again after a few steps, not once: rain
   * filling a dry bowl deepens it, and a step that was stable at the start
   * of a long advance is not by its end. The stretch between reads starts
   * at one step (GR_RAIN_RUNOFF_CHUNK_MIN) and doubles (to
   * GR_RAIN_RUNOFF_CHUNK_MAX) while the stable step holds, back to one
   * when it shrinks by more than 5 %; the last stretch is split into equal
   * steps that end exactly at the duration. One step, not four, at the
   * start: on dry ground the first stable step sees still water only rain
   * deep, and the water's own speed and depth shrink it by half and more
   * within a few steps (advance_dry_start: four steps of the first took the
   * shallow-water model past its Courant limit, where cut negative depths
   * made water). All of it depends on the state only, so the same state and
   * duration give the same steps; the progress watch only adds waits. */
  double left = duration, last_dt = 0.0;
  int chunk = GR_RAIN_RUNOFF_CHUNK_MIN, stop = 0;
  gr_rain_runoff_watch watch = {0.0, 0.0, 1, 0, s->allreduce != NULL};
  watch.last_call = watch.last_wait = gr_rain_runoff_now();
  /* The callback's cadence runs on across advances: a caller advancing in
   * parts shorter than GR_RAIN_RUNOFF_PROGRESS_EVERY (a GPU's 1000 s may
   * take 80 ms) still hears from it. */
  if (s->progress_last > 0.0)
    watch.last_call = s->progress_last;
  gr_rain_runoff_watch *w = s->progress || watch.global ? &watch : NULL;
  gr_status st = GR_OK;
  while (st == GR_OK && left > 0.0 && !stop) {
    double dt = 0.0;
    st = gr_rain_runoff_stable_dt_impl(s, &dt);
    if (st != GR_OK)
      break;
    if (last_dt > 0.0)
      chunk = dt >= 0.95 * last_dt
                  ? (chunk * 2 < GR_RAIN_RUNOFF_CHUNK_MAX ? chunk * 2 : GR_RAIN_RUNOFF_CHUNK_MAX)
                  : GR_RAIN_RUNOFF_CHUNK_MIN;
    last_dt = dt;
    double n = ceil(left / dt);
    if (n < 1.0)
      n = 1.0;
    if ((double)*taken_out + n > (double)INT_MAX) {
      st = gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "Advancing by %g s takes more than %d steps (the stable step is %g s "
                        "with %g s left): advance in parts.",
                        duration, INT_MAX, dt, left);
      break;
    }
    int done = 0;
    if (n <= chunk) {
      st = gr_rain_runoff_enqueue(s, left / n, (int)n, w, &done, &stop);
      *taken_out += done;
      break;
    }
    st = gr_rain_runoff_enqueue(s, dt, chunk, w, &done, &stop);
    *taken_out += done;
    if (st == GR_OK)
      left -= chunk * dt;
  }
  if (s->progress)
    s->progress_last = watch.last_call;
  if (st == GR_OK && stop)
    st = gr_set_error(s->ctx, GR_ERR_ABORTED,
                      "The rain runoff advance was stopped by %s at %g s of simulated time; the "
                      "state is valid there and may be advanced further.",
                      watch.global ? "the progress callback of this or another piece of the domain"
                                   : "its progress callback",
                      s->time);
  return st;
}

gr_status gr_rain_runoff_advance(gr_rain_runoff *s, double duration, int *steps_taken) {
  if (steps_taken)
    *steps_taken = 0;
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_advance needs a simulation.");
  long long taken = 0;
  gr_status st = gr_rain_runoff_advance_impl(s, duration, &taken);
  if (steps_taken)
    *steps_taken = (int)taken;
  return GR_RAIN_RUNOFF_KEEP_ERROR(s, st);
}

void gr_rain_runoff_set_progress(gr_rain_runoff *s, gr_progress_fn fn, void *user) {
  if (!s)
    return;
  s->progress = fn;
  s->progress_user = fn ? user : NULL;
  s->progress_last = 0.0;
}
