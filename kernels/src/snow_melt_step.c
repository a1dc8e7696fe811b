/* Snow melt core, host side (snow_melt_internal.h): the sun's positions,
 * advance with its progress, mark, the outputs, the ledger, reset and
 * checkpoints. */
#include "snow_melt_internal.h"

#define GR_SM_PI 3.14159265358979323846
/* The solar constant (W/m^2) of Hock (1999). */
#define GR_SM_SOLAR_CONSTANT 1368.0
/* Steps per batch of advance: the host waits for the device (to write the
 * next batch's sun records) and calls the progress callback between
 * batches. The batches never change what is computed. */
#define GR_SM_BATCH_STEPS 16
#define GR_SM_PROGRESS_EVERY 0.1
/* Checkpoints: "GRM1" and the layout's version. */
#define GR_SM_STATE_MAGIC 0x314d5247u
#define GR_SM_STATE_VERSION 1u

/* ------------------------------------------------------------------ sun */

/* The sun's record (snow_melt_shared.h) at t s of simulated time. */
static void gr_sm_sun(const gr_snow_melt_params *p, double t, float *rec) {
  double hours = p->start_hour + t / 3600.0;
  double days = floor(hours / 24.0), h = hours - 24.0 * days;
  double g = 2.0 * GR_SM_PI * ((double)p->start_day + days - 1.0) / 365.0;
  double decl = 0.006918 - 0.399912 * cos(g) + 0.070257 * sin(g) - 0.006758 * cos(2.0 * g) +
                0.000907 * sin(2.0 * g) - 0.002697 * cos(3.0 * g) + 0.00148 * sin(3.0 * g);
  double ecc = 1.000110 + 0.034221 * cos(g) + 0.001280 * sin(g) + 0.000719 * cos(2.0 * g) +
               0.000077 * sin(2.0 * g);
  double w = (15.0 * (h - 12.0)) * GR_SM_PI / 180.0, phi = p->latitude * GR_SM_PI / 180.0;
  double east = -cos(decl) * sin(w);
  double north = sin(decl) * cos(phi) - cos(decl) * sin(phi) * cos(w);
  double up = sin(decl) * sin(phi) + cos(decl) * cos(phi) * cos(w);
  double az = atan2(east, north);
  if (az < 0.0)
    az += 2.0 * GR_SM_PI;
  double pos = az / (2.0 * GR_SM_PI) * p->horizon_sectors;
  if (pos >= p->horizon_sectors)
    pos = 0.0;
  int day = up > 0.0;
  rec[0] = (float)east;
  rec[1] = (float)north;
  rec[2] = (float)up;
  rec[3] = day ? (float)(GR_SM_SOLAR_CONSTANT * ecc) : 0.0f;
  rec[4] = day ? (float)(1.0 / up) : 0.0f;
  rec[5] = (float)pos;
  rec[6] = (float)asin(fmax(-1.0, fmin(1.0, up)));
  rec[7] = 0.0f;
}

/* ------------------------------------------------------------- stepping */

gr_status gr_sm_allreduce(gr_snow_melt *s, double *v, int n, gr_reduce_op op) {
  gr_status st = s->allreduce(s->allreduce_user, v, n, op);
  if (st != GR_OK)
    return gr_set_error(s->ctx, st,
                        "The snow melt's global reduction (the allreduce callback) failed after "
                        "step %lld with %s.",
                        s->steps, gr_status_string(st));
  return GR_OK;
}

/* The step kernel's arguments that hold for a whole advance with steps of dt
 * in ns sub-steps. */
static gr_status gr_sm_step_args(gr_snow_melt *s, double dt, cl_int ns) {
  const gr_snow_melt_params *p = &s->params;
  const gr_snow_melt_forcing *f = &s->forcing;
  const size_t m = sizeof(cl_mem);
  cl_int n = (cl_int)s->n, sectors = p->horizon_sectors, shadows = p->cast_shadows != 0;
  cl_int use_t = f->use_temperature_field != 0, use_p = f->use_precipitation_field != 0;
  cl_float t_ref = (cl_float)f->air_temperature, lapse_per_m = (cl_float)(p->lapse_rate / 1000.0);
  cl_float z_ref = (cl_float)p->reference_elevation;
  cl_float precip_m = (cl_float)(f->precipitation * dt / 3.6e6), field_m = (cl_float)(dt / 3.6e6);
  cl_float dt_h = (cl_float)(dt / 3600.0), mf_h = (cl_float)(p->melt_factor / 24.0);
  cl_float rad_factor = (cl_float)p->radiation_factor, t0 = (cl_float)p->threshold;
  cl_float ts = (cl_float)p->rain_snow_threshold, band = (cl_float)p->rain_snow_band;
  cl_float rho_new = (cl_float)p->new_snow_density, rho_max = (cl_float)p->max_density;
  cl_float settle = (cl_float)exp(-dt / p->settling_time);
  cl_float capacity = (cl_float)p->liquid_capacity;
  cl_float refreeze_h = (cl_float)(p->refreeze_factor / 24.0);
  /* c_w / L_f: the rain's heat, mm of melt per mm of rain per degC. */
  cl_float rain_heat = (cl_float)(4186.0 / 334000.0);
  cl_mem horizon = s->horizon ? s->horizon : s->scratch; /* bound, read with shadows only */
  const gr_sm_arg args[] = {
      {"frozen", m, &s->frozen},
      {"liquid", m, &s->liquid},
      {"density", m, &s->density},
      {"radiation", m, &s->radiation},
      {"acc", m, &s->acc},
      {"elevation", m, &s->elevation},
      {"normal", m, &s->normal},
      {"horizon", m, &horizon},
      {"temperature", m, &s->temperature},
      {"precipitation", m, &s->precipitation},
      {"table", m, &s->table},
      {"ns", sizeof(ns), &ns},
      {"n", sizeof(n), &n},
      {"sectors", sizeof(sectors), &sectors},
      {"shadows", sizeof(shadows), &shadows},
      {"use_t", sizeof(use_t), &use_t},
      {"use_p", sizeof(use_p), &use_p},
      {"t_ref", sizeof(t_ref), &t_ref},
      {"lapse_per_m", sizeof(lapse_per_m), &lapse_per_m},
      {"z_ref", sizeof(z_ref), &z_ref},
      {"precip_m", sizeof(precip_m), &precip_m},
      {"field_m", sizeof(field_m), &field_m},
      {"dt_h", sizeof(dt_h), &dt_h},
      {"mf_h", sizeof(mf_h), &mf_h},
      {"rad_factor", sizeof(rad_factor), &rad_factor},
      {"t0", sizeof(t0), &t0},
      {"ts", sizeof(ts), &ts},
      {"band", sizeof(band), &band},
      {"rho_new", sizeof(rho_new), &rho_new},
      {"rho_max", sizeof(rho_max), &rho_max},
      {"settle", sizeof(settle), &settle},
      {"capacity", sizeof(capacity), &capacity},
      {"refreeze_h", sizeof(refreeze_h), &refreeze_h},
      {"rain_heat", sizeof(rain_heat), &rain_heat},
  };
  return GR_SM_ARGS(s, s->step_k, args);
}

/* Steps `count` steps of dt in ns sub-steps: their sun records written to
 * the device (waits for the steps before), then the steps enqueued. */
static gr_status gr_sm_batch(gr_snow_melt *s, int count, double dt, int ns) {
  double t = s->time, sub = dt / ns;
  for (int k = 0; k < count; ++k, t += dt)
    for (int q = 0; q < ns; ++q)
      gr_sm_sun(&s->params, t + (q + 0.5) * sub,
                s->records + (size_t)(k * ns + q) * GR_SNOW_MELT_RECORD);
  gr_status st = gr_buffer_write(
      s->ctx, s->table, 0, sizeof(float) * GR_SNOW_MELT_RECORD * (size_t)(count * ns), s->records);
  for (int k = 0; st == GR_OK && k < count; ++k) {
    cl_int first = k * ns;
    st = gr_kernel_arg(s->ctx, s->step_k, "first", sizeof(first), &first);
    if (st == GR_OK)
      st = gr_sm_enqueue(s, s->step_k);
    if (st == GR_OK) {
      s->time += dt;
      s->steps += 1;
    }
  }
  return st;
}

static double gr_sm_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static gr_status gr_sm_advance_impl(gr_snow_melt *s, double duration, int *taken) {
  if (!(duration >= 0.0 && duration < HUGE_VAL))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The duration to advance the snow melt must be a finite number of "
                        "seconds, 0 or more (got %g).",
                        duration);
  if (s->params.cast_shadows && !s->has_terrain)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow melt casts shadows but has no terrain for its horizons: give "
                        "the whole domain's elevation with gr_snow_melt_set_terrain, or set "
                        "CastShadows to 0.");
  gr_status st = gr_sm_prepare(s);
  if (st != GR_OK || duration == 0.0)
    return st;
  double n = ceil(duration / s->params.time_step);
  if (n > (double)INT_MAX)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "Advancing the snow melt by %g s takes more than %d steps of %g s: "
                        "advance in parts.",
                        duration, INT_MAX, s->params.time_step);
  int total = n < 1.0 ? 1 : (int)n;
  double dt = duration / total;
  int ns = (int)ceil(dt / GR_SNOW_MELT_SUBSTEP_S);
  ns = ns < 1 ? 1 : ns;
  int per = GR_SNOW_MELT_TABLE_RECORDS / ns;
  per = per > GR_SM_BATCH_STEPS ? GR_SM_BATCH_STEPS : per;
  st = gr_sm_step_args(s, dt, ns);
  double last_call = gr_sm_now();
  for (int k = 0; st == GR_OK && k < total; k += per) {
    int count = total - k < per ? total - k : per;
    st = gr_sm_batch(s, count, dt, ns);
    if (st != GR_OK)
      break;
    *taken += count;
    int stop = 0;
    if (s->progress && k + count < total) {
      st = gr_finish(s->ctx);
      double now = gr_sm_now();
      if (st == GR_OK && now - last_call >= GR_SM_PROGRESS_EVERY) {
        last_call = now;
        stop = s->progress(s->progress_user, s->time) != 0;
      }
    }
    /* A stop asked on any piece stops every piece after the same batch. */
    if (st == GR_OK && s->allreduce && k + count < total) {
      double flag = stop;
      st = gr_sm_allreduce(s, &flag, 1, GR_REDUCE_MAX);
      stop = flag > 0.0;
    }
    if (st == GR_OK && stop)
      return gr_set_error(s->ctx, GR_ERR_ABORTED,
                          "The snow melt advance was stopped by its progress callback at %g s of "
                          "simulated time; the state is valid there.",
                          s->time);
  }
  return st;
}

gr_status gr_snow_melt_advance(gr_snow_melt *s, double duration, int *steps_taken) {
  if (steps_taken)
    *steps_taken = 0;
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT, "gr_snow_melt_advance needs a simulation.");
  int taken = 0;
  gr_status st = gr_sm_advance_impl(s, duration, &taken);
  if (steps_taken)
    *steps_taken = taken;
  return GR_SM_KEEP(s, st);
}

/* ------------------------------------------------------- mark and reading */

gr_status gr_snow_melt_mark(gr_snow_melt *s) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT, "gr_snow_melt_mark needs a simulation.");
  gr_status st = gr_sm_prepare(s);
  size_t row = 8 * s->n;
  if (st == GR_OK)
    st = gr_cl_check(s->ctx,
                     clEnqueueFillBuffer(gr_context_queue(s->ctx), s->acc, &(cl_uint){0},
                                         sizeof(cl_uint), GR_SNOW_MELT_ACC_MARK_MELT * row, 2 * row,
                                         0, NULL, NULL),
                     "Clearing the snow melt's sums since the mark");
  if (st == GR_OK)
    s->mark_time = s->time;
  return GR_SM_KEEP(s, st);
}

static gr_status gr_sm_get_impl(gr_snow_melt *s, gr_snow_melt_output o, float *host) {
  if ((int)o < 0 || o >= GR_SNOW_MELT_OUTPUT_COUNT)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow melt has no output %d; its outputs are snow_depth, "
                        "snow_density, swe, liquid_water, melt_rate, water_release, radiation "
                        "and released_depth.",
                        (int)o);
  gr_status st = gr_sm_prepare(s);
  if (st != GR_OK)
    return st;
  double span_h = (s->time - s->mark_time) / 3600.0;
  cl_float rate_scale =
      span_h > 0.0 ? (cl_float)(1000.0 / GR_SNOW_MELT_UNITS_PER_M / span_h) : 0.0f;
  static const cl_int what[GR_SNOW_MELT_OUTPUT_COUNT] = {
      GR_SNOW_MELT_DERIVE_DEPTH,     GR_SNOW_MELT_DERIVE_DENSITY,
      GR_SNOW_MELT_DERIVE_SWE,       GR_SNOW_MELT_DERIVE_LIQUID,
      GR_SNOW_MELT_DERIVE_MELT_RATE, GR_SNOW_MELT_DERIVE_RELEASE_RATE,
      GR_SNOW_MELT_DERIVE_RADIATION, GR_SNOW_MELT_DERIVE_RELEASED};
  cl_int n = (cl_int)s->n, w = what[o];
  const size_t m = sizeof(cl_mem);
  const gr_sm_arg args[] = {
      {"frozen", m, &s->frozen},
      {"liquid", m, &s->liquid},
      {"density", m, &s->density},
      {"radiation", m, &s->radiation},
      {"acc", m, &s->acc},
      {"out", m, &s->scratch},
      {"n", sizeof(n), &n},
      {"what", sizeof(w), &w},
      {"rate_scale", sizeof(rate_scale), &rate_scale},
  };
  st = GR_SM_ARGS(s, s->derive_k, args);
  if (st == GR_OK)
    st = gr_sm_enqueue(s, s->derive_k);
  if (st == GR_OK)
    st = gr_buffer_read(s->ctx, s->scratch, 0, 4 * s->n, host);
  return st;
}

gr_status gr_snow_melt_get(gr_snow_melt *s, gr_snow_melt_output o, float *host) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_melt_get needs a simulation and room for the output.");
  if (!host)
    return GR_SM_KEEP(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "gr_snow_melt_get needs a simulation and room for the "
                                      "output."));
  return GR_SM_KEEP(s, gr_sm_get_impl(s, o, host));
}

/* hi 2^24 + lo as a 128-bit integer. */
static gr_wide gr_sm_join(long long hi, long long lo) {
  gr_wide w = gr_wide_scale(gr_wide_mul(hi, 1), 1LL << GR_SNOW_MELT_SPLIT_BITS);
  gr_wide_add(&w, gr_wide_mul(lo, 1));
  return w;
}

static gr_status gr_sm_ledger_impl(gr_snow_melt *s, gr_snow_melt_ledger *out) {
  gr_status st = gr_sm_prepare(s);
  cl_int n = (cl_int)s->n;
  const size_t m = sizeof(cl_mem);
  const gr_sm_arg args[] = {{"frozen", m, &s->frozen},
                            {"liquid", m, &s->liquid},
                            {"acc", m, &s->acc},
                            {"n", sizeof(n), &n}};
  long long words[GR_SNOW_MELT_WORDS];
  if (st == GR_OK)
    st = GR_SM_ARGS(s, s->reduce_k, args);
  if (st == GR_OK)
    st = gr_reduction_i64_run(s->ctx, &s->ledger, s->reduce_k, words);
  if (st != GR_OK)
    return st;
  gr_wide initial = s->initial;
  if (s->allreduce) {
    double packed[GR_FIXED_PACKED(GR_SNOW_MELT_WORDS, 1)];
    gr_fixed_pack(words, GR_SNOW_MELT_WORDS, &initial, 1, packed);
    st = gr_sm_allreduce(s, packed, GR_FIXED_PACKED(GR_SNOW_MELT_WORDS, 1), GR_REDUCE_SUM);
    if (st != GR_OK)
      return st;
    gr_fixed_unpack(packed, words, GR_SNOW_MELT_WORDS, &initial, 1);
  }
  gr_wide q[GR_SNOW_MELT_SUMS];
  for (int k = 0; k < GR_SNOW_MELT_SUMS; ++k)
    q[k] = gr_sm_join(words[2 * k], words[2 * k + 1]);
  /* In minus stored and released, in the state's integers. */
  gr_wide balance = initial;
  gr_wide_add(&balance, q[2]);
  gr_wide_add(&balance, q[3]);
  gr_wide_add(&balance, gr_wide_scale(q[0], -1));
  gr_wide_add(&balance, gr_wide_scale(q[1], -1));
  gr_wide_add(&balance, gr_wide_scale(q[6], -1));
  const double area = s->grid.dx * s->grid.dy;
#define GR_SM_VOLUME(w) (gr_wide_value((w), 32) * area)
  memset(out, 0, sizeof(*out));
  out->time = s->time;
  out->steps = s->steps;
  out->snowfall_in = GR_SM_VOLUME(initial);
  out->stored_swe_volume = GR_SM_VOLUME(q[0]);
  out->stored_liquid_volume = GR_SM_VOLUME(q[1]);
  out->snowfall_volume = GR_SM_VOLUME(q[2]);
  out->rain_volume = GR_SM_VOLUME(q[3]);
  out->melt_volume = GR_SM_VOLUME(q[4]);
  out->refrozen_volume = GR_SM_VOLUME(q[5]);
  out->released_volume = GR_SM_VOLUME(q[6]);
  out->released_since_mark = GR_SM_VOLUME(q[7]);
  out->balance_error = GR_SM_VOLUME(balance);
#undef GR_SM_VOLUME
  return GR_OK;
}

gr_status gr_snow_melt_ledger_get(gr_snow_melt *s, gr_snow_melt_ledger *out) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_melt_ledger_get needs a simulation and a ledger to fill.");
  if (!out)
    return GR_SM_KEEP(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "gr_snow_melt_ledger_get needs a simulation and a ledger "
                                      "to fill."));
  return GR_SM_KEEP(s, gr_sm_ledger_impl(s, out));
}

gr_status gr_snow_melt_reset(gr_snow_melt *s) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT, "gr_snow_melt_reset needs a simulation.");
  s->state_ready = 0;
  s->time = s->mark_time = 0.0;
  s->steps = 0;
  return GR_OK;
}

/* ------------------------------------------------------------ checkpoints */

typedef struct gr_sm_state_header {
  uint32_t magic, version;
  int32_t nx, ny, j0, gny;
  int64_t steps;
  double time, mark_time;
  uint64_t initial_lo;
  int64_t initial_hi;
} gr_sm_state_header;

/* The state's buffers in the checkpoint's order, and their bytes. */
static int gr_sm_state_parts(const gr_snow_melt *s, cl_mem bufs[5], size_t bytes[5]) {
  size_t n = s->n;
  cl_mem b[5] = {s->frozen, s->liquid, s->density, s->radiation, s->acc};
  size_t z[5] = {8 * n, 8 * n, 4 * n, 4 * n, 8 * GR_SNOW_MELT_ACCS * n};
  memcpy(bufs, b, sizeof(b));
  memcpy(bytes, z, sizeof(z));
  return 5;
}

static size_t gr_sm_state_bytes(const gr_snow_melt *s) {
  return sizeof(gr_sm_state_header) + (8 + 8 + 4 + 4 + 8 * GR_SNOW_MELT_ACCS) * s->n;
}

gr_status gr_snow_melt_state_size(const gr_snow_melt *s, size_t *bytes) {
  if (!s || !bytes)
    return gr_set_error(s ? s->ctx : NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_melt_state_size needs a simulation and a place for the size.");
  *bytes = gr_sm_state_bytes(s);
  return GR_OK;
}

static gr_status gr_sm_save_impl(gr_snow_melt *s, void *host, size_t bytes) {
  size_t need = gr_sm_state_bytes(s);
  if (bytes != need)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The buffer for the snow melt state has %zu bytes but this state has %zu: "
                        "size it with gr_snow_melt_state_size.",
                        bytes, need);
  gr_status st = gr_sm_prepare(s);
  gr_sm_state_header hd;
  memset(&hd, 0, sizeof(hd));
  hd.magic = GR_SM_STATE_MAGIC;
  hd.version = GR_SM_STATE_VERSION;
  hd.nx = s->grid.nx, hd.ny = s->own_ny, hd.j0 = s->grid.j0, hd.gny = s->gny;
  hd.steps = s->steps;
  hd.time = s->time, hd.mark_time = s->mark_time;
  hd.initial_lo = s->initial.lo, hd.initial_hi = s->initial.hi;
  unsigned char *at = host;
  memcpy(at, &hd, sizeof(hd));
  at += sizeof(hd);
  cl_mem bufs[5];
  size_t sizes[5];
  int parts = gr_sm_state_parts(s, bufs, sizes);
  for (int k = 0; st == GR_OK && k < parts; at += sizes[k], ++k)
    st = gr_buffer_read(s->ctx, bufs[k], 0, sizes[k], at);
  return st;
}

gr_status gr_snow_melt_state_save(gr_snow_melt *s, void *host, size_t bytes) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_melt_state_save needs a simulation and a buffer.");
  if (!host)
    return GR_SM_KEEP(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "gr_snow_melt_state_save needs a simulation and a buffer."));
  return GR_SM_KEEP(s, gr_sm_save_impl(s, host, bytes));
}

static gr_status gr_sm_load_impl(gr_snow_melt *s, const void *host, size_t bytes) {
  size_t need = gr_sm_state_bytes(s);
  gr_sm_state_header hd;
  if (bytes < sizeof(hd))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow melt state has %zu bytes, fewer than its header: pass the bytes "
                        "gr_snow_melt_state_save wrote.",
                        bytes);
  memcpy(&hd, host, sizeof(hd));
  if (hd.magic != GR_SM_STATE_MAGIC || hd.version != GR_SM_STATE_VERSION)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The bytes given are not a snow melt state of this version: pass the "
                        "bytes gr_snow_melt_state_save wrote.");
  if (hd.nx != s->grid.nx || hd.ny != s->own_ny || hd.j0 != s->grid.j0 || hd.gny != s->gny ||
      bytes != need)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow melt state is of a %d x %d grid at row %d (%zu bytes) but this "
                        "simulation's is %d x %d at row %d (%zu bytes): load it into a simulation "
                        "of the grid (or piece) it was saved from.",
                        (int)hd.nx, (int)hd.ny, (int)hd.j0, bytes, s->grid.nx, s->own_ny,
                        s->grid.j0, need);
  if (!(hd.time >= 0.0 && hd.time < HUGE_VAL) || hd.steps < 0 || hd.steps > GR_STATE_MAX_STEPS ||
      !(hd.mark_time >= 0.0 && hd.mark_time <= hd.time))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow melt state's header is damaged (time %g s, %lld steps): pass "
                        "the bytes gr_snow_melt_state_save wrote.",
                        hd.time, (long long)hd.steps);
  /* The water's integers not negative (and summable), the densities as
   * set_field takes them, the radiation finite: checked before anything is
   * written, so that a refused state leaves the simulation as it was. */
  const double top = 4611686018427387904.0; /* 2^62 */
  const size_t n = s->n, o = sizeof(hd);
  const gr_state_part check[] = {
      {"frozen water", o, n, 'l', 0.0, top},
      {"liquid water", o + 8 * n, n, 'l', 0.0, top},
      {"snow density", o + 16 * n, n, 'f', 0.0, 1000.0},
      {"radiation", o + 20 * n, n, 'f', -HUGE_VAL, HUGE_VAL},
      {"accumulators", o + 24 * n, GR_SNOW_MELT_ACCS * n, 'l', 0.0, top}};
  gr_status st = gr_state_check("snow melt", "snow_melt", host, check, 5);
  if (st != GR_OK)
    return st;
  const unsigned char *at = (const unsigned char *)host + sizeof(hd);
  cl_mem bufs[5];
  size_t sizes[5];
  int parts = gr_sm_state_parts(s, bufs, sizes);
  for (int k = 0; st == GR_OK && k < parts; at += sizes[k], ++k)
    st = gr_buffer_write(s->ctx, bufs[k], 0, sizes[k], at);
  if (st != GR_OK)
    return st;
  s->steps = hd.steps;
  s->time = hd.time, s->mark_time = hd.mark_time;
  s->initial.lo = hd.initial_lo, s->initial.hi = hd.initial_hi;
  s->state_ready = 1;
  return GR_OK;
}

gr_status gr_snow_melt_state_load(gr_snow_melt *s, const void *host, size_t bytes) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_melt_state_load needs a simulation and the saved bytes.");
  if (!host)
    return GR_SM_KEEP(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "gr_snow_melt_state_load needs a simulation and the saved "
                                      "bytes."));
  return GR_SM_KEEP(s, gr_sm_load_impl(s, host, bytes));
}
