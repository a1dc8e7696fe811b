/* Snow melt core (Hock 1999's enhanced temperature-index melt): host side
 * of snow_melt.cl. The model is documented in graupel/snow_melt.h, the
 * constants both sides share in snow_melt_shared.h. This file: the
 * parameters, the handle, creation, the inputs and the terrain's horizons;
 * the sun, stepping, outputs, the ledger and checkpoints are in
 * snow_melt_step.c (around snow_melt_internal.h). */
#include "snow_melt_internal.h"

/* set_field's sanity bounds. */
#define GR_SM_MAX_ELEVATION 1.0e6
#define GR_SM_MAX_DEPTH 1.0e4
#define GR_SM_MAX_TEMPERATURE 100.0
#define GR_SM_MAX_PRECIPITATION 1000.0

/* The parameter table's rows, in gr_snow_melt_param_bounds' order. */
enum {
  GR_SM_P_LATITUDE,
  GR_SM_P_START_DAY,
  GR_SM_P_START_HOUR,
  GR_SM_P_TIME_STEP,
  GR_SM_P_MELT_FACTOR,
  GR_SM_P_RADIATION_FACTOR,
  GR_SM_P_THRESHOLD,
  GR_SM_P_LAPSE_RATE,
  GR_SM_P_REFERENCE_ELEVATION,
  GR_SM_P_TRANSMISSIVITY,
  GR_SM_P_RAIN_SNOW_THRESHOLD,
  GR_SM_P_RAIN_SNOW_BAND,
  GR_SM_P_NEW_SNOW_DENSITY,
  GR_SM_P_MAX_DENSITY,
  GR_SM_P_SETTLING_TIME,
  GR_SM_P_LIQUID_CAPACITY,
  GR_SM_P_REFREEZE_FACTOR,
  GR_SM_P_CAST_SHADOWS,
  GR_SM_P_HORIZON_SECTORS,
  GR_SM_P_COUNT
};

/* The one place each range is written. Latitude 46 deg and day 100 (10
 * April), an Alpine spring; MeltFactor 1.8 and RadiationFactor 0.0006 are
 * Hock's (1999) snow values for Storglaciaren (her model 3's order of
 * magnitude for snow); Transmissivity 0.75, hers for clear skies; the
 * lapse rate of the standard atmosphere; the rain/snow threshold 1 degC with
 * a 2 degC band (rain from 0 to 2 degC mixed with snow); new snow 100 kg/m^3
 * settling towards 450 kg/m^3 (a ripe spring pack) in about 10 days; 10 %
 * of the frozen SWE held as liquid; the refreezing rate Snow-17's negative
 * melt factor (see the header). */
static const gr_param_bound gr_sm_bounds[GR_SM_P_COUNT] = {
    {"Latitude", "deg", -90.0, 90.0, 46.0, 1.0, 0, 0},
    {"StartDayOfYear", "", 1.0, 366.0, 100.0, 1.0, 0, 1},
    {"StartHour", "h", 0.0, 24.0, 0.0, 1.0, 0, 0},
    {"TimeStep", "s", 1.0, 86400.0, 3600.0, 1.0, 0, 0},
    {"MeltFactor", "mm/(degC d)", 0.0, 20.0, 1.8, 1.0, 0, 0},
    {"RadiationFactor", "mm m^2/(W h degC)", 0.0, 0.01, 0.0006, 1.0, 0, 0},
    {"ThresholdTemperature", "degC", -10.0, 10.0, 0.0, 1.0, 0, 0},
    {"LapseRate", "degC/km", -20.0, 20.0, -6.5, 1.0, 0, 0},
    {"ReferenceElevation", "m", -1.1e4, 1.0e4, 0.0, 1.0, 0, 0},
    {"Transmissivity", "", 0.0, 1.0, 0.75, 1.0, 1, 0},
    {"RainSnowThreshold", "degC", -10.0, 10.0, 1.0, 1.0, 0, 0},
    {"RainSnowBand", "degC", 0.0, 10.0, 2.0, 1.0, 0, 0},
    {"NewSnowDensity", "kg/m^3", 20.0, 600.0, 100.0, 1.0, 0, 0},
    {"MaxDensity", "kg/m^3", 20.0, 917.0, 450.0, 1.0, 0, 0},
    {"SettlingTime", "d", 0.0, 365.0, 10.0, 86400.0, 1, 0},
    {"LiquidWaterCapacity", "", 0.0, 0.5, 0.1, 1.0, 0, 0},
    {"RefreezeFactor", "mm/(degC d)", 0.0, 20.0, 0.6, 1.0, 0, 0},
    {"CastShadows", "", 0.0, 1.0, 1.0, 1.0, 0, 1},
    {"HorizonSectors", "", 4.0, 360.0, 32.0, 1.0, 0, 1},
};

static const char *const gr_sm_names[GR_SNOW_MELT_OUTPUT_COUNT] = {
    "snow_depth", "snow_density",  "swe",       "liquid_water",
    "melt_rate",  "water_release", "radiation", "released_depth"};

const char *gr_snow_melt_output_name(gr_snow_melt_output o) {
  return (int)o >= 0 && o < GR_SNOW_MELT_OUTPUT_COUNT ? gr_sm_names[o] : NULL;
}

const gr_param_bound *gr_snow_melt_param_bounds(int *count) {
  if (count)
    *count = GR_SM_P_COUNT;
  return gr_sm_bounds;
}

/* The field of p behind each row, in the core's unit. */
static double *gr_sm_param_slot(gr_snow_melt_params *p, int row) {
  double *slots[GR_SM_P_COUNT] = {&p->latitude,
                                  NULL,
                                  &p->start_hour,
                                  &p->time_step,
                                  &p->melt_factor,
                                  &p->radiation_factor,
                                  &p->threshold,
                                  &p->lapse_rate,
                                  &p->reference_elevation,
                                  &p->transmissivity,
                                  &p->rain_snow_threshold,
                                  &p->rain_snow_band,
                                  &p->new_snow_density,
                                  &p->max_density,
                                  &p->settling_time,
                                  &p->liquid_capacity,
                                  &p->refreeze_factor,
                                  NULL,
                                  NULL};
  return slots[row];
}

static double gr_sm_param_value(const gr_snow_melt_params *p, int row) {
  if (row == GR_SM_P_START_DAY)
    return p->start_day;
  if (row == GR_SM_P_CAST_SHADOWS)
    return p->cast_shadows;
  if (row == GR_SM_P_HORIZON_SECTORS)
    return p->horizon_sectors;
  return *gr_sm_param_slot((gr_snow_melt_params *)p, row);
}

void gr_snow_melt_params_init(gr_snow_melt_params *p) {
  if (!p)
    return;
  memset(p, 0, sizeof(*p));
  for (int row = 0; row < GR_SM_P_COUNT; ++row) {
    double *slot = gr_sm_param_slot(p, row);
    if (slot)
      *slot = gr_sm_bounds[row].default_value * gr_sm_bounds[row].to_core;
  }
  p->start_day = (int)gr_sm_bounds[GR_SM_P_START_DAY].default_value;
  p->cast_shadows = (int)gr_sm_bounds[GR_SM_P_CAST_SHADOWS].default_value;
  p->horizon_sectors = (int)gr_sm_bounds[GR_SM_P_HORIZON_SECTORS].default_value;
}

gr_status gr_snow_melt_params_validate(const gr_snow_melt_params *p, char *msg, size_t msg_len) {
  const char *what = "Invalid snow melt parameters";
  if (!p)
    return gr_params_missing(what, msg, msg_len);
  double values[GR_SM_P_COUNT];
  for (int row = 0; row < GR_SM_P_COUNT; ++row)
    values[row] = gr_sm_param_value(p, row);
  gr_status st = gr_params_check_table(gr_sm_bounds, NULL, GR_SM_P_COUNT, values, what, NULL,
                                       GR_PARAM_SAY_GOT, msg, msg_len);
  if (st == GR_OK && p->max_density < p->new_snow_density) {
    if (msg && msg_len)
      snprintf(msg, msg_len,
               "%s: MaxDensity (%g kg/m^3) is below NewSnowDensity (%g kg/m^3); settling makes "
               "snow denser, so raise MaxDensity to at least NewSnowDensity.",
               what, p->max_density, p->new_snow_density);
    st = GR_ERR_INVALID_ARGUMENT;
  }
  return st;
}

/* ------------------------------------------------------------- the handle */

const char *gr_snow_melt_last_error(const gr_snow_melt *s) {
  return s ? s->error : "";
}

gr_status gr_sm_args(gr_snow_melt *s, cl_kernel k, const gr_sm_arg *args, size_t n) {
  gr_status st = GR_OK;
  for (size_t i = 0; st == GR_OK && i < n; ++i)
    st = gr_kernel_arg(s->ctx, k, args[i].name, args[i].size, args[i].value);
  return st;
}

gr_status gr_sm_enqueue(gr_snow_melt *s, cl_kernel k) {
  return gr_enqueue_1d(s->ctx, k, s->n);
}

gr_status gr_sm_zero(gr_snow_melt *s, cl_mem buf, size_t bytes) {
  cl_uint zero = 0;
  return gr_cl_check(s->ctx,
                     clEnqueueFillBuffer(gr_context_queue(s->ctx), buf, &zero, sizeof(zero), 0,
                                         bytes, 0, NULL, NULL),
                     "Filling a device buffer");
}

void gr_snow_melt_set_progress(gr_snow_melt *s, gr_progress_fn fn, void *user) {
  if (!s)
    return;
  s->progress = fn;
  s->progress_user = fn ? user : NULL;
}

void gr_snow_melt_set_allreduce(gr_snow_melt *s, gr_allreduce_fn fn, void *user) {
  if (!s)
    return;
  s->allreduce = fn;
  s->allreduce_user = fn ? user : NULL;
}

void gr_snow_melt_destroy(gr_snow_melt *s) {
  if (!s)
    return;
  cl_kernel kernels[] = {s->horizon_k, s->step_k, s->reduce_k, s->derive_k};
  for (size_t i = 0; i < sizeof(kernels) / sizeof(kernels[0]); ++i)
    if (kernels[i])
      clReleaseKernel(kernels[i]);
  cl_mem *bufs[] = {&s->frozen,      &s->liquid,        &s->density, &s->radiation,
                    &s->acc,         &s->elevation,     &s->normal,  &s->horizon,
                    &s->temperature, &s->precipitation, &s->table,   &s->scratch};
  for (size_t i = 0; i < sizeof(bufs) / sizeof(bufs[0]); ++i)
    gr_buffer_release(bufs[i]);
  gr_reduction_i64_release(&s->ledger);
  free(s->depth);
  free(s->snow_density);
  free(s->records);
  gr_context_release(s->ctx);
  free(s);
}

/* ---------------------------------------------------- creation and inputs */

gr_status gr_snow_melt_memory(const gr_grid *grid, const gr_snow_melt_params *p,
                              gr_memory_need *out) {
  if (!grid || !out)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_melt_memory needs a grid and a place for the answer.");
  int sectors = p ? p->horizon_sectors : (int)gr_sm_bounds[GR_SM_P_HORIZON_SECTORS].default_value;
  double n = (double)grid->nx * (double)grid->ny;
  double whole = (double)(grid->global_nx > 0 ? grid->global_nx : grid->nx) *
                 (double)(grid->global_ny > 0 ? grid->global_ny : grid->ny);
  memset(out, 0, sizeof(*out));
  out->points = n;
  /* frozen, liquid (8 each), density, radiation (4 each), 7 accumulators
   * (56), elevation, temperature, precipitation, scratch (4 each), the
   * normal (16): 112 bytes a point, and the horizons; the whole terrain
   * while the horizons are found. */
  out->device = (112.0 + 4.0 * sectors) * n + 4.0 * whole;
  out->largest = fmax(fmax(4.0 * sectors * n, 56.0 * n), 4.0 * whole);
  out->host = 8.0 * n + 8.0 * (double)grid->nx * ((double)grid->ny + 2.0);
  out->state = 80.0 * n + 64.0; /* the checkpoint: state and accumulators */
  return GR_OK;
}

/* The piece contract: strips of whole rows with a ring of 1 row. */
static gr_status gr_sm_piece_check(const gr_grid *g, int *ring_s, int *ring_n, char *msg,
                                   size_t len) {
  return gr_grid_strip_check(g, "snow melt", "", GR_SNOW_MELT_GHOST,
                             "for the slopes' central differences", ring_s, ring_n, msg, len);
}

static gr_status gr_sm_buffers(gr_snow_melt *s) {
  size_t n = s->n;
  cl_program prog = NULL;
  gr_status st = gr_program_get(s->ctx, "snow_melt", NULL, &prog);
  if (st == GR_OK)
    st = gr_kernel_create(s->ctx, prog, "snow_melt_horizon", &s->horizon_k);
  if (st == GR_OK)
    st = gr_kernel_create(s->ctx, prog, "snow_melt_step", &s->step_k);
  if (st == GR_OK)
    st = gr_kernel_create(s->ctx, prog, "snow_melt_reduce", &s->reduce_k);
  if (st == GR_OK)
    st = gr_kernel_create(s->ctx, prog, "snow_melt_derive", &s->derive_k);
  struct {
    cl_mem *buf;
    size_t bytes;
  } bufs[] = {{&s->frozen, 8 * n},
              {&s->liquid, 8 * n},
              {&s->density, 4 * n},
              {&s->radiation, 4 * n},
              {&s->acc, 8 * GR_SNOW_MELT_ACCS * n},
              {&s->elevation, 4 * n},
              {&s->normal, 16 * n},
              {&s->scratch, 4 * n},
              {&s->table, 4 * GR_SNOW_MELT_RECORD * GR_SNOW_MELT_TABLE_RECORDS}};
  for (size_t i = 0; st == GR_OK && i < sizeof(bufs) / sizeof(bufs[0]); ++i)
    st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, bufs[i].bytes, NULL, bufs[i].buf);
  for (size_t i = 0; st == GR_OK && i < sizeof(bufs) / sizeof(bufs[0]); ++i)
    st = gr_sm_zero(s, *bufs[i].buf, bufs[i].bytes);
  /* Unused until set, but bound: one float each. */
  if (st == GR_OK)
    st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, 4 * n, NULL, &s->temperature);
  if (st == GR_OK)
    st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, 4 * n, NULL, &s->precipitation);
  if (st == GR_OK)
    st = gr_reduction_i64_init(s->ctx, s->reduce_k, n, GR_SNOW_MELT_WORDS, &s->ledger);
  return st;
}

/* The unit normals of the own points from the local elevations (central
 * differences inside the domain, one-sided on its edges, as
 * terrain_analysis), with ln(Psi) P / P0 of the standard atmosphere in w;
 * uploads them and the own elevations. */
static gr_status gr_sm_upload_ground(gr_snow_melt *s, const float *local) {
  const int nx = s->grid.nx, rows = s->own_ny + s->ring_s + s->ring_n;
  float *nrm = malloc(16 * s->n), *own = malloc(4 * s->n);
  if (!nrm || !own) {
    free(nrm), free(own);
    return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  const double inv_dx = 1.0 / s->grid.dx, inv_dy = 1.0 / s->grid.dy;
  const double log_psi = log(s->params.transmissivity);
  for (int jj = 0; jj < s->own_ny; ++jj) {
    int r = jj + s->ring_s;
    for (int i = 0; i < nx; ++i) {
      const float *row = local + (size_t)r * nx;
      double z = row[i], gx = 0.0, gy = 0.0;
      if (nx > 1)
        gx = i == 0        ? (row[1] - z) * inv_dx
             : i == nx - 1 ? (z - row[i - 1]) * inv_dx
                           : ((double)row[i + 1] - row[i - 1]) * 0.5 * inv_dx;
      if (rows > 1) {
        double south = r > 0 ? row[i - nx] : z, north = r < rows - 1 ? row[i + nx] : z;
        gy = r == 0          ? (north - z) * inv_dy
             : r == rows - 1 ? (z - south) * inv_dy
                             : (north - south) * 0.5 * inv_dy;
      }
      double inv_len = 1.0 / sqrt(gx * gx + gy * gy + 1.0);
      double base = fmax(1.0 - 2.25577e-5 * z, 0.0);
      size_t c = (size_t)jj * nx + (size_t)i;
      nrm[4 * c] = (float)((0.0 - gx) * inv_len);
      nrm[4 * c + 1] = (float)((0.0 - gy) * inv_len);
      nrm[4 * c + 2] = (float)inv_len;
      nrm[4 * c + 3] = (float)(log_psi * pow(base, 5.25588));
      own[c] = (float)z;
    }
  }
  gr_status st = gr_buffer_write(s->ctx, s->normal, 0, 16 * s->n, nrm);
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, s->elevation, 0, 4 * s->n, own);
  free(nrm), free(own);
  return st;
}

gr_status gr_snow_melt_create(gr_context *ctx, const gr_grid *grid, const gr_snow_melt_params *p,
                              gr_snow_melt **out) {
  char msg[320];
  if (!ctx || !out)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_melt_create needs a context and a place for the simulation.");
  *out = NULL;
  if (gr_grid_validate(grid, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  if (gr_snow_melt_params_validate(p, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  int ring_s = 0, ring_n = 0;
  if (gr_sm_piece_check(grid, &ring_s, &ring_n, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  double whole = (double)(grid->global_nx > 0 ? grid->global_nx : grid->nx) *
                 (double)(grid->global_ny > 0 ? grid->global_ny : grid->ny);
  if ((double)grid->nx * grid->ny * p->horizon_sectors > (double)INT_MAX - 1048576.0 ||
      whole > (double)INT_MAX - 1048576.0)
    return gr_set_error(ctx, GR_ERR_TOO_LARGE,
                        "The snow melt grid of %d x %d points is too large: the kernels address "
                        "at most about 2.1e9 values (points times HorizonSectors); coarsen it.",
                        grid->nx, grid->ny);
  gr_memory_need need;
  gr_snow_melt_memory(grid, p, &need);
  if (gr_memory_check(ctx, &need, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_TOO_LARGE,
                        "The snow melt of a %d x %d grid %s: use a smaller grid or another device.",
                        grid->nx, grid->ny, msg);
  gr_snow_melt *s = calloc(1, sizeof(*s));
  if (!s)
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  s->ctx = gr_context_retain(ctx);
  s->grid = *grid;
  s->gnx = grid->nx;
  s->gny = grid->global_ny > 0 ? grid->global_ny : grid->ny;
  s->own_ny = grid->ny;
  s->ring_s = ring_s, s->ring_n = ring_n;
  s->n = (size_t)grid->nx * (size_t)grid->ny;
  s->params = *p;
  s->depth = calloc(s->n, sizeof(float));
  s->snow_density = malloc(s->n * sizeof(float));
  s->records = malloc(sizeof(float) * GR_SNOW_MELT_RECORD * GR_SNOW_MELT_TABLE_RECORDS);
  float *flat = calloc((size_t)grid->nx * (size_t)(grid->ny + ring_s + ring_n), sizeof(float));
  gr_status st = GR_OK;
  if (!s->depth || !s->snow_density || !s->records || !flat)
    st = gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  for (size_t c = 0; st == GR_OK && c < s->n; ++c)
    s->snow_density[c] = (float)p->new_snow_density;
  if (st == GR_OK)
    st = gr_sm_buffers(s);
  if (st == GR_OK)
    st = gr_sm_upload_ground(s, flat);
  if (st == GR_OK)
    st = gr_finish(ctx);
  free(flat);
  if (st != GR_OK) {
    gr_snow_melt_destroy(s);
    return st;
  }
  *out = s;
  return GR_OK;
}

/* The local arrays' points (own rows and rings). */
static size_t gr_sm_local_points(const gr_snow_melt *s) {
  return (size_t)s->grid.nx * (size_t)(s->own_ny + s->ring_s + s->ring_n);
}

/* Checks an input's floats: finite and within [lo, hi]; names the point. */
static gr_status gr_sm_check(gr_snow_melt *s, const char *name, const float *v, size_t n, size_t nx,
                             size_t row0, double lo, double hi, const char *rule) {
  for (size_t c = 0; c < n; ++c) {
    double x = v[c];
    if (isfinite(x) && x >= lo && x <= hi)
      continue;
    return gr_set_error(
        s->ctx, GR_ERR_INVALID_ARGUMENT, "The snow melt's %s has %s at point (%zu, %zu): %s.", name,
        isnan(x) ? "NaN" : (isinf(x) ? "an infinite value" : "a value out of range"), c % nx,
        c / nx + row0, rule);
  }
  return GR_OK;
}

static gr_status gr_sm_set_field_impl(gr_snow_melt *s, int field, const float *host) {
  const size_t nx = (size_t)s->grid.nx, own0 = nx * (size_t)s->ring_s;
  const size_t row0 = (size_t)(s->grid.j0 - s->ring_s), n = gr_sm_local_points(s);
  const float *own = host + own0;
  gr_status st;
  int snow = field == GR_FIELD_SNOW_DEPTH || field == GR_FIELD_SNOW_DENSITY;
  if (snow && s->steps > 0)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow melt's initial snow (%s) can be set only before the first step; "
                        "call gr_snow_melt_reset first.",
                        gr_field_name((gr_field)field));
  switch (field) {
  case GR_FIELD_ELEVATION:
    st = gr_sm_check(s, "elevation", host, n, nx, row0, -GR_SM_MAX_ELEVATION, GR_SM_MAX_ELEVATION,
                     "every elevation must be a finite number of metres within +-1e6 m");
    return st == GR_OK ? gr_sm_upload_ground(s, host) : st;
  case GR_FIELD_SNOW_DEPTH:
    st = gr_sm_check(s, "snow_depth", own, s->n, nx, row0 + s->ring_s, 0.0, GR_SM_MAX_DEPTH,
                     "every snow depth must be a finite number of metres from 0 to 1e4 m");
    if (st == GR_OK)
      memcpy(s->depth, own, 4 * s->n);
    break;
  case GR_FIELD_SNOW_DENSITY:
    st = gr_sm_check(s, "snow_density", own, s->n, nx, row0 + s->ring_s, 0.0, 1000.0,
                     "every snow density must be a finite number from 0 to 1000 kg/m^3");
    if (st == GR_OK)
      memcpy(s->snow_density, own, 4 * s->n);
    break;
  case GR_SNOW_MELT_TEMPERATURE:
    st = gr_sm_check(s, "air_temperature", own, s->n, nx, row0 + s->ring_s, -GR_SM_MAX_TEMPERATURE,
                     GR_SM_MAX_TEMPERATURE,
                     "every air temperature must be a finite number of degC within +-100");
    if (st == GR_OK)
      st = gr_buffer_write(s->ctx, s->temperature, 0, 4 * s->n, own);
    s->has_temperature |= st == GR_OK;
    return st;
  case GR_SNOW_MELT_PRECIPITATION:
    st = gr_sm_check(s, "precipitation", own, s->n, nx, row0 + s->ring_s, 0.0,
                     GR_SM_MAX_PRECIPITATION,
                     "every precipitation rate must be a finite number from 0 to 1000 mm/h");
    if (st == GR_OK)
      st = gr_buffer_write(s->ctx, s->precipitation, 0, 4 * s->n, own);
    s->has_precipitation |= st == GR_OK;
    return st;
  default:
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The field %d is not an input of the snow melt; its inputs are elevation, "
                        "snow_depth, snow_density, air_temperature and precipitation.",
                        field);
  }
  if (st == GR_OK)
    s->state_ready = 0;
  return st;
}

gr_status gr_snow_melt_set_field(gr_snow_melt *s, int field, const float *host) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_melt_set_field needs a simulation and the field's values.");
  if (!host)
    return GR_SM_KEEP(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "gr_snow_melt_set_field needs a simulation and the field's "
                                      "values."));
  return GR_SM_KEEP(s, gr_sm_set_field_impl(s, field, host));
}

static gr_status gr_sm_set_forcing_impl(gr_snow_melt *s, const gr_snow_melt_forcing *f) {
  if (!(fabs(f->air_temperature) <= GR_SM_MAX_TEMPERATURE))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow melt's forcing air temperature must be a finite number of degC "
                        "within +-100 (got %g).",
                        f->air_temperature);
  if (!(f->precipitation >= 0.0 && f->precipitation <= GR_SM_MAX_PRECIPITATION))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow melt's forcing precipitation must be a finite number from 0 to "
                        "1000 mm/h (got %g).",
                        f->precipitation);
  if ((f->use_temperature_field && !s->has_temperature) ||
      (f->use_precipitation_field && !s->has_precipitation))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow melt's forcing asks for the per-point %s field, which was never "
                        "set; set it with gr_snow_melt_set_field first.",
                        f->use_temperature_field && !s->has_temperature ? "air_temperature"
                                                                        : "precipitation");
  s->forcing = *f;
  return GR_OK;
}

gr_status gr_snow_melt_set_forcing(gr_snow_melt *s, const gr_snow_melt_forcing *f) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_melt_set_forcing needs a simulation and a forcing.");
  if (!f)
    return GR_SM_KEEP(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "gr_snow_melt_set_forcing needs a simulation and a "
                                      "forcing."));
  return GR_SM_KEEP(s, gr_sm_set_forcing_impl(s, f));
}

/* The horizons of the own points from the whole terrain (waits); the
 * terrain's buffer is released after. */
static gr_status gr_sm_set_terrain_impl(gr_snow_melt *s, const float *terrain) {
  size_t whole = (size_t)s->gnx * (size_t)s->gny;
  gr_status st = gr_sm_check(s, "terrain", terrain, whole, (size_t)s->gnx, 0, -GR_SM_MAX_ELEVATION,
                             GR_SM_MAX_ELEVATION,
                             "every elevation must be a finite number of metres within +-1e6 m");
  if (st != GR_OK)
    return st;
  if (!s->params.cast_shadows) {
    s->has_terrain = 1;
    return GR_OK;
  }
  /* Each block's highest point, over the block and one cell around it
   * (every point a bilinear read in the block touches). */
  const int nx_ = s->gnx, ny_ = s->gny, B = GR_SNOW_MELT_BLOCK;
  const int bnx = (nx_ + B - 1) / B, bny = (ny_ + B - 1) / B;
  float *bmax = malloc(sizeof(float) * (size_t)bnx * (size_t)bny);
  if (!bmax)
    return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  float h_max = terrain[0];
  for (int bj = 0; bj < bny; ++bj)
    for (int bi = 0; bi < bnx; ++bi) {
      float m = -INFINITY;
      int j1 = (bj + 1) * B < ny_ - 1 ? (bj + 1) * B : ny_ - 1;
      int i1 = (bi + 1) * B < nx_ - 1 ? (bi + 1) * B : nx_ - 1;
      for (int j = bj * B > 0 ? bj * B - 1 : 0; j <= j1; ++j)
        for (int i = bi * B > 0 ? bi * B - 1 : 0; i <= i1; ++i)
          m = terrain[(size_t)j * nx_ + i] > m ? terrain[(size_t)j * nx_ + i] : m;
      bmax[bj * bnx + bi] = m;
      h_max = m > h_max ? m : h_max;
    }
  cl_mem buf = NULL, blocks = NULL;
  size_t hbytes = 4 * s->n * (size_t)s->params.horizon_sectors;
  st = gr_buffer_create(s->ctx, CL_MEM_READ_ONLY, 4 * whole, terrain, &buf);
  if (st == GR_OK)
    st = gr_buffer_create(s->ctx, CL_MEM_READ_ONLY, sizeof(float) * (size_t)bnx * bny, bmax,
                          &blocks);
  free(bmax);
  if (st == GR_OK && !s->horizon)
    st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, hbytes, NULL, &s->horizon);
  cl_int nx = s->gnx, gny = s->gny, j0 = s->grid.j0, own_ny = s->own_ny;
  cl_int sectors = s->params.horizon_sectors;
  cl_float dx = (cl_float)s->grid.dx, dy = (cl_float)s->grid.dy;
  const size_t m = sizeof(cl_mem);
  const gr_sm_arg args[] = {
      {"terrain", m, &buf},
      {"block_max", m, &blocks},
      {"nx", sizeof(nx), &nx},
      {"gny", sizeof(gny), &gny},
      {"j0", sizeof(j0), &j0},
      {"own_ny", sizeof(own_ny), &own_ny},
      {"dx", sizeof(dx), &dx},
      {"dy", sizeof(dy), &dy},
      {"sectors", sizeof(sectors), &sectors},
      {"h_max", sizeof(h_max), &h_max},
      {"horizon", m, &s->horizon},
  };
  if (st == GR_OK)
    st = GR_SM_ARGS(s, s->horizon_k, args);
  if (st == GR_OK)
    st = gr_enqueue_2d(s->ctx, s->horizon_k, 0, 0, (size_t)nx, (size_t)own_ny, NULL);
  if (st == GR_OK)
    st = gr_finish(s->ctx);
  gr_buffer_release(&buf);
  gr_buffer_release(&blocks);
  if (st == GR_OK)
    s->has_terrain = 1;
  return st;
}

gr_status gr_snow_melt_set_terrain(gr_snow_melt *s, const float *elevation) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_melt_set_terrain needs a simulation and the whole terrain.");
  if (!elevation)
    return GR_SM_KEEP(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "gr_snow_melt_set_terrain needs a simulation and the whole "
                                      "terrain."));
  return GR_SM_KEEP(s, gr_sm_set_terrain_impl(s, elevation));
}

/* The initial snow as the state: frozen = depth density / 1000 in the
 * state's integers, no liquid, accumulators 0. */
gr_status gr_sm_prepare(gr_snow_melt *s) {
  if (s->state_ready)
    return GR_OK;
  size_t n = s->n;
  long long *frozen = malloc(8 * n);
  float *rho = malloc(4 * n);
  if (!frozen || !rho) {
    free(frozen), free(rho);
    return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  gr_wide total = {0, 0};
  gr_status st = GR_OK;
  for (size_t c = 0; c < n; ++c) {
    double d = s->depth[c], r = s->snow_density[c];
    if (d > 0.0 && r < 1.0) {
      st = gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow melt's snow_density is %g kg/m^3 at point (%zu, %zu) where the "
                        "snow is %g m deep: snow needs a density of at least 1 kg/m^3.",
                        r, c % (size_t)s->grid.nx, c / (size_t)s->grid.nx + (size_t)s->grid.j0, d);
      break;
    }
    frozen[c] = d > 0.0 ? llround(d * r / 1000.0 * GR_SNOW_MELT_UNITS_PER_M) : 0;
    rho[c] = frozen[c] > 0 ? (float)r : (float)s->params.new_snow_density;
    gr_wide_add(&total, gr_wide_mul(frozen[c], 1));
  }
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, s->frozen, 0, 8 * n, frozen);
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, s->density, 0, 4 * n, rho);
  cl_mem zeroed[] = {s->liquid, s->radiation, s->acc};
  size_t bytes[] = {8 * n, 4 * n, 8 * GR_SNOW_MELT_ACCS * n};
  for (int i = 0; st == GR_OK && i < 3; ++i)
    st = gr_sm_zero(s, zeroed[i], bytes[i]);
  free(frozen), free(rho);
  if (st == GR_OK) {
    s->initial = total;
    s->state_ready = 1;
  }
  return st;
}
