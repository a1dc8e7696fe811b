/* Snow accumulation core (seed 002's thesis): host side of
 * snow_accumulation.cl. The model, its step order and its book-keeping are
 * documented in graupel/snow_accumulation.h; the constants both sides share
 * in snow_accumulation_shared.h; the handle and the helpers the host files
 * share in snow_accumulation_internal.h. This file: the parameter table,
 * timing, the device arrays' helpers, and the handle's life cycle (memory,
 * create, destroy, parameters, fields, reset). */
#include "snow_accumulation_internal.h"
#include "runtime_internal.h"

/* The one place each range is written. SnowfallRate: heavy snowfall is a
 * few cm/h, record falls about 20 cm/h. SnowDensity: fresh snow is 30 to
 * 200 kg/m^3, ice 900. */
const gr_param_bound gr_snac_bounds[GR_SNAC_P_COUNT] = {
    {"Flutter", "deg", 0.0, 10.0, 0.0, GR_SNAC_PI / 180.0, 0, 0},
    {"SnowfallRate", "cm/h", 0.0, 1000.0, 2.0, 0.01 / 3600.0, 0, 0},
    {"NoiseAmplitude", "", 0.0, 1.0, 0.2, 1.0, 0, 0},
    {"NoiseScale", "m", 0.0, 1.0e4, 1.0, 1.0, 1, 0},
    {"Seed", "", 0.0, 2147483647.0, 0.0, 1.0, 0, 1},
    {"ExposureResolution", "", 16.0, 65536.0, 1024.0, 1.0, 0, 1},
    {"BlurRadius", "", 0.0, (double)GR_SNAC_MAX_BLUR, 1.0, 1.0, 0, 1},
    {"Dilation", "", 0.0, 1.0, 0.0, 1.0, 0, 1},
    {"MaxDepth", "m", 0.0, 100.0, 1.0, 1.0, 1, 0},
    {"StabilityFactor", "1/s", 0.0, 1.0, 1.0, 1.0, 0, 0},
    {"SnowDensity", "kg/m^3", 1.0, 1000.0, 100.0, 1.0, 0, 0},
    {"AccumulationTextureSize", "", 0.0, (double)GR_SNAC_MAX_TEXTURE, 256.0, 1.0, 0, 1},
};

gr_status gr_snac_args(gr_snow_accumulation *s, cl_kernel k, const gr_snac_arg *args, size_t n) {
  gr_status st = GR_OK;
  for (size_t q = 0; st == GR_OK && q < n; ++q)
    st = gr_kernel_arg(s->ctx, k, args[q].name, args[q].size, args[q].value);
  return st;
}

const gr_param_bound *gr_snow_accumulation_param_bounds(int *count) {
  if (count)
    *count = GR_SNAC_P_COUNT;
  return gr_snac_bounds;
}

const char *gr_snow_accumulation_last_error(const gr_snow_accumulation *s) {
  return s ? s->error : "";
}

void gr_snow_accumulation_params_init(gr_snow_accumulation_params *p) {
  if (!p)
    return;
  memset(p, 0, sizeof(*p));
  const gr_param_bound *t = gr_snac_bounds;
  p->direction[2] = -1.0;
  p->flutter = t[GR_SNAC_P_FLUTTER].default_value * t[GR_SNAC_P_FLUTTER].to_core;
  p->snowfall_rate = t[GR_SNAC_P_RATE].default_value * t[GR_SNAC_P_RATE].to_core;
  p->noise_amplitude = t[GR_SNAC_P_AMPLITUDE].default_value;
  p->noise_scale = t[GR_SNAC_P_SCALE].default_value;
  p->seed = (int)t[GR_SNAC_P_SEED].default_value;
  p->exposure_resolution = (int)t[GR_SNAC_P_RESOLUTION].default_value;
  p->blur_radius = (int)t[GR_SNAC_P_BLUR].default_value;
  p->dilation = (int)t[GR_SNAC_P_DILATION].default_value;
  p->max_depth = t[GR_SNAC_P_MAX_DEPTH].default_value;
  p->stability_factor = t[GR_SNAC_P_STABILITY].default_value;
  p->snow_density = t[GR_SNAC_P_DENSITY].default_value;
  p->texture_size = (int)t[GR_SNAC_P_TEXTURE].default_value;
}

static double gr_snac_param_value(const gr_snow_accumulation_params *p, int row) {
  switch (row) {
  case GR_SNAC_P_FLUTTER:
    return p->flutter;
  case GR_SNAC_P_RATE:
    return p->snowfall_rate;
  case GR_SNAC_P_AMPLITUDE:
    return p->noise_amplitude;
  case GR_SNAC_P_SCALE:
    return p->noise_scale;
  case GR_SNAC_P_SEED:
    return (double)p->seed;
  case GR_SNAC_P_RESOLUTION:
    return (double)p->exposure_resolution;
  case GR_SNAC_P_BLUR:
    return (double)p->blur_radius;
  case GR_SNAC_P_DILATION:
    return (double)p->dilation;
  case GR_SNAC_P_MAX_DEPTH:
    return p->max_depth;
  case GR_SNAC_P_STABILITY:
    return p->stability_factor;
  case GR_SNAC_P_DENSITY:
    return p->snow_density;
  default:
    return (double)p->texture_size;
  }
}

gr_status gr_snow_accumulation_params_validate(const gr_snow_accumulation_params *p, char *msg,
                                               size_t msg_len) {
  const char *what = "Invalid snow accumulation parameters";
  if (!p)
    return gr_params_missing(what, msg, msg_len);
  double values[GR_SNAC_P_COUNT];
  for (int row = 0; row < GR_SNAC_P_COUNT; ++row)
    values[row] = gr_snac_param_value(p, row);
  if (gr_params_check_table(gr_snac_bounds, NULL, GR_SNAC_P_COUNT, values, what, NULL,
                            GR_PARAM_SAY_GOT, msg, msg_len) != GR_OK)
    return GR_ERR_INVALID_ARGUMENT;
  const double *d = p->direction;
  double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (!isfinite(d[0]) || !isfinite(d[1]) || !isfinite(d[2]) || !isfinite(len) || len < 1e-9 ||
      -d[2] / len < cos(GR_SNOW_ACCUMULATION_MAX_TILT * GR_SNAC_PI / 180.0)) {
    if (msg && msg_len)
      snprintf(msg, msg_len,
               "Invalid snow accumulation parameters: SnowDirection (%g, %g, %g) must point "
               "down, at most %g degrees from straight down (0 0 -1); give a direction with a "
               "negative z component.",
               d[0], d[1], d[2], GR_SNOW_ACCUMULATION_MAX_TILT);
    return GR_ERR_INVALID_ARGUMENT;
  }
  return GR_OK;
}

gr_status gr_snow_accumulation_field_validate(gr_field f, const float *values, size_t n, size_t nx,
                                              char *msg, size_t msg_len) {
  double lo, hi;
  const char *rule;
  const char *name = gr_field_name(f);
  if (!name)
    name = "(unknown field)";
  if (f == GR_FIELD_ELEVATION) {
    lo = -GR_SNAC_MAX_ELEVATION, hi = GR_SNAC_MAX_ELEVATION;
    rule = "elevations must be finite and within +-1e6 m";
  } else if (f == GR_FIELD_SNOW_DEPTH) {
    lo = 0.0, hi = GR_SNAC_MAX_DEPTH;
    rule = "snow depths must be finite, at least 0 and at most 1e4 m";
  } else {
    if (msg && msg_len)
      snprintf(msg, msg_len,
               "The field '%s' is not an input of the snow accumulation simulation; its inputs "
               "are elevation and snow_depth.",
               name);
    return GR_ERR_INVALID_ARGUMENT;
  }
  return gr_field_check_range(name, values, n, nx, lo, hi, rule, msg, msg_len);
}

double gr_snac_now_ms(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return 1e3 * (double)ts.tv_sec + 1e-6 * (double)ts.tv_nsec;
}

/* With timing on: waits for the stage just enqueued and charges its time. */
gr_status gr_snac_mark(gr_snow_accumulation *s, double *acc) {
  if (!s->timing)
    return GR_OK;
  gr_status st = gr_finish(s->ctx);
  double t = gr_snac_now_ms();
  *acc += t - s->t_mark;
  s->t_mark = t;
  return st;
}

void gr_snow_accumulation_set_timing(gr_snow_accumulation *s, int on) {
  if (!s)
    return;
  s->timing = on != 0;
  memset(&s->tm, 0, sizeof(s->tm));
}

gr_status gr_snow_accumulation_timing_get(const gr_snow_accumulation *s,
                                          gr_snow_accumulation_timing *out) {
  if (!s || !out)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_timing_get needs a simulation and a place for the "
                        "times.");
  *out = s->tm;
  return GR_OK;
}

size_t gr_snac_cells(const gr_snow_accumulation *s) {
  return (size_t)s->grid.nx * (size_t)s->grid.ny;
}

gr_status gr_snac_fill(gr_snow_accumulation *s, cl_mem buf, size_t n, float value) {
  if (n == 0)
    return GR_OK;
  return gr_cl_check(s->ctx,
                     clEnqueueFillBuffer(gr_context_queue(s->ctx), buf, &value, sizeof(value), 0,
                                         n * sizeof(float), 0, NULL, NULL),
                     "Filling a device buffer");
}

gr_status gr_snow_accumulation_max_resolution(gr_context *ctx, int *out) {
  if (!ctx || !out)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_max_resolution needs a context and a place for the "
                        "answer.");
  cl_device_id dev = gr_context_device(ctx);
  cl_bool images = CL_FALSE;
  size_t width = 0;
  cl_ulong max_alloc = 0;
  cl_int err = clGetDeviceInfo(dev, CL_DEVICE_IMAGE_SUPPORT, sizeof(images), &images, NULL);
  if (err == CL_SUCCESS && images)
    err = clGetDeviceInfo(dev, CL_DEVICE_IMAGE2D_MAX_WIDTH, sizeof(width), &width, NULL);
  if (err == CL_SUCCESS)
    err = clGetDeviceInfo(dev, CL_DEVICE_MAX_MEM_ALLOC_SIZE, sizeof(max_alloc), &max_alloc, NULL);
  if (err != CL_SUCCESS)
    return gr_cl_check(ctx, err, "Querying the device's image and buffer limits");
  /* The view holds (res + 2 margin + 1)^2 ints. */
  double side = floor(sqrt((double)max_alloc / 4.0)) - 2.0 * GR_SNAC_VIEW_MARGIN - 1.0;
  double limit = side;
  if (images && width > 0 && (double)width < limit)
    limit = (double)width;
  if (limit > 65536.0)
    limit = 65536.0;
  *out = limit < 0.0 ? 0 : (int)limit;
  return GR_OK;
}

/* The view buffer for the parameters' resolution, and the blur weights. */
static gr_status gr_snac_prepare(gr_snow_accumulation *s, const gr_snow_accumulation_params *p) {
  int limit = 0;
  gr_status st = gr_snow_accumulation_max_resolution(s->ctx, &limit);
  if (st != GR_OK)
    return st;
  if (p->exposure_resolution > limit)
    return gr_set_error(s->ctx, GR_ERR_TOO_LARGE,
                        "ExposureResolution %d is beyond the device '%s': its exposure view can "
                        "be at most %d texels across (its widest 2-D image and largest buffer); "
                        "lower ExposureResolution or pick another device.",
                        p->exposure_resolution, gr_context_device_name(s->ctx), limit);
  size_t side = (size_t)p->exposure_resolution + 2 * GR_SNAC_VIEW_MARGIN + 1;
  size_t need = side * side;
  if (need > s->view_cap) {
    cl_mem view = NULL;
    st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, need * sizeof(cl_int), NULL, &view);
    if (st != GR_OK)
      return st;
    gr_buffer_release(&s->view);
    s->view = view;
    s->view_cap = need;
  }
  /* Binomial weights C(2r + 4, r + 2 + k), k = 0 .. r (r = 4: the
   * thesis' 9 taps); normalised on the device over the taps on the grid. */
  float w[GR_SNAC_MAX_BLUR + 1];
  int r = p->blur_radius, m = 2 * r + 4;
  for (int k = 0; k <= r; ++k) {
    double c = 1.0;
    for (int q = 1; q <= r + 2 + k; ++q)
      c = c * (double)(m - (r + 2 + k) + q) / (double)q;
    w[k] = (float)c;
  }
  return gr_buffer_write(s->ctx, s->weights, 0, (size_t)(r + 1) * sizeof(float), w);
}

/* sums[0..2]: stored, fallen, shed over points first .. first + n - 1 of
 * the grid (area 1: the caller multiplies by dx dy) or of the objects. */
gr_status gr_snac_sums(gr_snow_accumulation *s, int objects, int first, int n,
                       double sums[GR_SNAC_SUMS]) {
  for (int q = 0; q < GR_SNAC_SUMS; ++q)
    sums[q] = 0.0;
  if (n <= 0)
    return GR_OK;
  cl_mem *a = objects ? s->o_arr : s->arr;
  cl_mem area = objects ? s->o_area : s->ground;
  cl_int weighted = objects != 0;
  const gr_snac_arg args[] = {GR_SNAC_MEM("depth", a[0]),  GR_SNAC_MEM("depth_lo", a[1]),
                              GR_SNAC_MEM("fall", a[2]),   GR_SNAC_MEM("fall_lo", a[3]),
                              GR_SNAC_MEM("shed", a[4]),   GR_SNAC_MEM("shed_lo", a[5]),
                              GR_SNAC_MEM("area", area),   GR_SNAC_VAL("weighted", weighted),
                              GR_SNAC_VAL("first", first), GR_SNAC_VAL("n", n)};
  gr_status st = gr_snac_args(s, s->reduce, args, sizeof(args) / sizeof(args[0]));
  if (st == GR_OK)
    st = gr_reduction_run(s->ctx, &s->red, s->reduce, sums, NULL);
  return st;
}

static gr_status gr_snac_initial_state(gr_snow_accumulation *s) {
  size_t cells = gr_snac_cells(s);
  gr_status st = gr_cl_check(s->ctx,
                             clEnqueueCopyBuffer(gr_context_queue(s->ctx), s->depth0, s->arr[0], 0,
                                                 0, cells * sizeof(float), 0, NULL, NULL),
                             "Copying the initial snow");
  for (int a = 1; st == GR_OK && a < GR_SNAC_ARRAYS; ++a)
    st = gr_snac_fill(s, s->arr[a], cells, 0.0f);
  for (int a = 0; st == GR_OK && a < GR_SNAC_ARRAYS && s->ntri > 0; ++a)
    st = gr_snac_fill(s, s->o_arr[a], (size_t)s->ntri, 0.0f);
  for (int a = 0; st == GR_OK && a < GR_SNAC_ARRAYS && s->ns > 0; ++a)
    st = gr_snac_fill(s, s->t_arr[a], (size_t)s->ns, 0.0f);
  s->time = s->retired_fall = s->retired_shed = s->dropped = 0.0;
  s->steps = 0;
  s->aborted = 0;
  s->snow_bound = s->init_max;
  s->initial_objects = 0.0;
  double *rows = malloc((size_t)s->own_ny * GR_SNAC_SUMS * sizeof(double));
  if (st == GR_OK && !rows)
    st = gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  if (st == GR_OK)
    st = gr_snac_rows(s, rows);
  for (int r = 0; st == GR_OK && r < s->own_ny; ++r)
    s->init_rows[r] = rows[GR_SNAC_SUMS * (size_t)r];
  free(rows);
  return st;
}

gr_status gr_snow_accumulation_memory(const gr_grid *grid, const gr_snow_accumulation_params *p,
                                      gr_memory_need *out) {
  if (!grid || !p || !out)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_memory needs a grid, parameters and a place for "
                        "the answer.");
  /* A piece's ring (at most grid->ghost rows each way). */
  double rows = (double)grid->ny + 2.0 * (grid->ghost > 0 ? grid->ghost : 0);
  double n = (double)grid->nx * rows;
  double side = (double)p->exposure_resolution + 2.0 * GR_SNAC_VIEW_MARGIN + 1.0;
  double view = sizeof(cl_int) * side * side;
  memset(out, 0, sizeof(*out));
  out->points = (double)grid->nx * (double)grid->ny;
  /* The buffers gr_snow_accumulation_create makes, and the view (gr_snac_prepare). */
  out->device =
      sizeof(float) * (5.0 + GR_SNAC_ARRAYS) * n + view + sizeof(float) * 2.0 * GR_SNAC_SUMS * rows;
  out->largest = sizeof(float) * n > view ? sizeof(float) * n : view;
  out->host = sizeof(double) * (1.0 + GR_SNAC_SUMS) * rows; /* init_rows, the rows' sums */
  out->state = sizeof(float) * GR_SNAC_ARRAYS * n + sizeof(double) * rows; /* gr_snac_state_bytes */
  return GR_OK;
}

gr_status gr_snow_accumulation_create(gr_context *ctx, const gr_grid *grid,
                                      const gr_snow_accumulation_params *p,
                                      gr_snow_accumulation **out) {
  char msg[400];
  if (!ctx || !out)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_create needs a context and a place for the "
                        "simulation.");
  *out = NULL;
  if (gr_grid_validate(grid, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  if (gr_snow_accumulation_params_validate(p, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  int ring_s = 0, ring_n = 0;
  if (gr_snac_piece_check(grid, p, &ring_s, &ring_n, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  if ((double)grid->nx * ((double)grid->ny + ring_s + ring_n) > (double)INT_MAX / 2)
    return gr_set_error(ctx, GR_ERR_TOO_LARGE,
                        "The snow accumulation grid of %d x %d points is too large: the kernels "
                        "address at most about 1e9 points; coarsen it.",
                        grid->nx, grid->ny);
  gr_memory_need need;
  gr_snow_accumulation_memory(grid, p, &need);
  if (gr_memory_check(ctx, &need, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_TOO_LARGE,
                        "The snow accumulation of a %d x %d grid %s: use a smaller grid, a "
                        "lower ExposureResolution or another device.",
                        grid->nx, grid->ny, msg);
  gr_snow_accumulation *s = calloc(1, sizeof(*s));
  if (!s)
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  s->ctx = gr_context_retain(ctx);
  s->grid = *grid;
  s->gnx = grid->nx;
  s->gny = grid->global_ny > 0 ? grid->global_ny : grid->ny;
  s->own_ny = grid->ny;
  s->ring_s = ring_s, s->ring_n = ring_n;
  s->row0 = grid->j0 - ring_s;
  s->grid.ny = grid->ny + ring_s + ring_n;
  s->params = *p;
  s->init_rows = calloc((size_t)grid->ny, sizeof(double));
  size_t cells = gr_snac_cells(s), bytes = cells * sizeof(float);
  cl_program prog = NULL;
  gr_status st = gr_program_get(ctx, "snow_accumulation", NULL, &prog);
  struct {
    const char *name;
    cl_kernel *k;
  } ks[] = {{"snow_accumulation_raster_terrain", &s->raster_terrain},
            {"snow_accumulation_raster_objects", &s->raster_objects},
            {"snow_accumulation_exposure", &s->exposure_k},
            {"snow_accumulation_blur", &s->blur},
            {"snow_accumulation_dilate", &s->dilate},
            {"snow_accumulation_apply", &s->apply},
            {"snow_accumulation_objects", &s->objects_k},
            {"snow_accumulation_reduce", &s->reduce},
            {"snow_accumulation_surface", &s->surface},
            {"snow_accumulation_noise", &s->noise_k},
            {"snow_accumulation_slope_reduce", &s->slope_k},
            {"snow_accumulation_row_sums", &s->row_sums},
            {"snow_accumulation_object_surface", &s->object_surface},
            {"snow_accumulation_object_exposure", &s->object_exposure}};
  for (size_t i = 0; st == GR_OK && i < sizeof(ks) / sizeof(ks[0]); ++i)
    st = gr_kernel_create(ctx, prog, ks[i].name, ks[i].k);
  cl_mem *bufs[] = {&s->ground, &s->depth0, &s->growth, &s->scratch, &s->noise};
  for (size_t i = 0; st == GR_OK && i < sizeof(bufs) / sizeof(bufs[0]); ++i)
    st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, bytes, NULL, bufs[i]);
  for (int a = 0; st == GR_OK && a < GR_SNAC_ARRAYS; ++a)
    st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, bytes, NULL, &s->arr[a]);
  if (st == GR_OK)
    st = gr_buffer_create(ctx, CL_MEM_READ_ONLY, (GR_SNAC_MAX_BLUR + 1) * sizeof(float), NULL,
                          &s->weights);
  if (st == GR_OK)
    st =
        gr_buffer_create(ctx, CL_MEM_READ_WRITE,
                         (size_t)s->grid.ny * 2 * GR_SNAC_SUMS * sizeof(float), NULL, &s->rows_buf);
  if (st == GR_OK && !s->init_rows)
    st = gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  if (st == GR_OK)
    st = gr_snac_prepare(s, p);
  /* The objects' sums: a launch chosen for the domain's size, so that
   * every piece of it adds the faces in the same groups. */
  if (st == GR_OK)
    st = gr_reduction_init(ctx, s->reduce, (size_t)s->gnx * (size_t)s->gny, GR_SNAC_SUMS, 0,
                           &s->red);
  if (st == GR_OK)
    st = gr_reduction_init(ctx, s->slope_k, cells, 0, 2, &s->red_slope);
  if (st == GR_OK)
    st = gr_snac_fill(s, s->ground, cells, 0.0f);
  if (st == GR_OK)
    st = gr_snac_fill(s, s->depth0, cells, 0.0f);
  if (st == GR_OK)
    st = gr_snac_initial_state(s);
  if (st != GR_OK) {
    gr_snow_accumulation_destroy(s);
    return st;
  }
  *out = s;
  return GR_OK;
}

void gr_snac_release_objects(gr_snow_accumulation *s) {
  cl_mem *bufs[] = {&s->o_tri, &s->o_pos, &s->o_nrm, &s->o_local, &s->o_area};
  for (size_t i = 0; i < sizeof(bufs) / sizeof(bufs[0]); ++i)
    gr_buffer_release(bufs[i]);
  for (int a = 0; a < GR_SNAC_ARRAYS; ++a)
    gr_buffer_release(&s->o_arr[a]);
}

void gr_snow_accumulation_destroy(gr_snow_accumulation *s) {
  if (!s)
    return;
  cl_kernel ks[] = {s->raster_terrain, s->raster_objects, s->exposure_k, s->blur,
                    s->dilate,         s->apply,          s->objects_k,  s->reduce,
                    s->surface,        s->noise_k,        s->slope_k,    s->row_sums,
                    s->object_surface, s->object_exposure};
  for (size_t i = 0; i < sizeof(ks) / sizeof(ks[0]); ++i)
    if (ks[i])
      clReleaseKernel(ks[i]);
  cl_mem *bufs[] = {&s->ground, &s->depth0, &s->growth,   &s->scratch,  &s->weights,
                    &s->view,   &s->noise,  &s->rows_buf, &s->o_surface};
  for (size_t i = 0; i < sizeof(bufs) / sizeof(bufs[0]); ++i)
    gr_buffer_release(bufs[i]);
  for (int a = 0; a < GR_SNAC_ARRAYS; ++a)
    gr_buffer_release(&s->arr[a]);
  gr_snac_release_objects(s);
  gr_snac_release_textures(&s->t_pos, &s->t_nrm, &s->t_local, s->t_arr);
  for (int o = 0; o < GR_SNOW_ACCUMULATION_MAX_OBJECTS; ++o)
    free(s->tuv[o]);
  free(s->sv), free(s->stexel), free(s->stri), free(s->sbar), free(s->hlocal);
  gr_reduction_release(&s->red);
  gr_reduction_release(&s->red_slope);
  free(s->hv);
  free(s->ht);
  free(s->hnrm);
  free(s->harea);
  free(s->view_rows), free(s->view_cover);
  free(s->init_rows);
  for (int o = 0; o < GR_SNOW_ACCUMULATION_MAX_OBJECTS; ++o)
    gr_mesh_memo_free(&s->memo[o]);
  gr_context_release(s->ctx);
  free(s);
}

gr_status gr_snow_accumulation_set_params(gr_snow_accumulation *s,
                                          const gr_snow_accumulation_params *p) {
  char msg[400];
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_set_params needs a simulation.");
  if (gr_snow_accumulation_params_validate(p, msg, sizeof(msg)) != GR_OK)
    return GR_SNAC_KEEP_ERROR(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg));
  if (gr_snac_pieced(s) && gr_snow_accumulation_ghost(p) > s->grid.ghost)
    return GR_SNAC_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "Invalid snow accumulation parameters: BlurRadius %d needs a ghost ring "
                        "of %d rows but this piece has %d; keep BlurRadius at most %d or make "
                        "the piece again with a wider ring.",
                        p->blur_radius, gr_snow_accumulation_ghost(p), s->grid.ghost,
                        s->grid.ghost - 2));
  gr_status st = gr_snac_prepare(s, p);
  if (st != GR_OK)
    return GR_SNAC_KEEP_ERROR(s, st);
  s->params = *p;
  return GR_OK;
}

/* Uploads the objects' world geometry relative to grid point (0, 0) and
 * zref (again whenever zref moves): the triangles, and the faces' centroids
 * (where a face is exposed and grows). */
gr_status gr_snac_upload_geometry(gr_snow_accumulation *s) {
  if (s->nv == 0 || s->ntri == 0)
    return GR_OK;
  size_t nv = (size_t)s->nv, nt = (size_t)s->ntri;
  float *pos = malloc(nv * 3 * sizeof(float)), *tri = malloc(nt * 9 * sizeof(float));
  float *cen = malloc(nt * 3 * sizeof(float));
  if (!pos || !tri || !cen) {
    free(pos), free(tri), free(cen);
    return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  double off[3] = {s->grid.x0, s->grid.y0, s->zref};
  for (size_t v = 0; v < nv; ++v)
    for (int a = 0; a < 3; ++a)
      pos[3 * v + a] = (float)(s->hv[3 * v + a] - off[a]);
  for (size_t t = 0; t < nt; ++t) {
    const int *ix = s->ht + 3 * t;
    for (int k = 0; k < 3; ++k)
      memcpy(tri + 9 * t + 3 * k, pos + 3 * (size_t)ix[k], 3 * sizeof(float));
    for (int a = 0; a < 3; ++a)
      cen[3 * t + a] = (float)((s->hv[3 * (size_t)ix[0] + a] + s->hv[3 * (size_t)ix[1] + a] +
                                s->hv[3 * (size_t)ix[2] + a]) /
                                   3.0 -
                               off[a]);
  }
  gr_status st = gr_buffer_write(s->ctx, s->o_pos, 0, nt * 3 * sizeof(float), cen);
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, s->o_tri, 0, nt * 9 * sizeof(float), tri);
  free(pos), free(tri), free(cen);
  if (st != GR_OK || s->ns == 0)
    return st;
  size_t ns = (size_t)s->ns;
  float *sp = malloc(ns * 3 * sizeof(float));
  if (!sp)
    return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  for (size_t k = 0; k < ns; ++k)
    for (int a = 0; a < 3; ++a)
      sp[3 * k + a] = (float)(s->sv[3 * k + a] - off[a]);
  st = gr_buffer_write(s->ctx, s->t_pos, 0, ns * 3 * sizeof(float), sp);
  free(sp);
  return st;
}

static gr_status gr_snac_set_field_impl(gr_snow_accumulation *s, gr_field f, const float *host) {
  size_t cells = gr_snac_cells(s), nx = (size_t)s->grid.nx;
  char msg[512];
  if (gr_snow_accumulation_field_validate(f, host, cells, nx, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  size_t bytes = cells * sizeof(float);
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  for (size_t c = 0; c < cells; ++c) {
    lo = fmin(lo, (double)host[c]);
    hi = fmax(hi, (double)host[c]);
  }
  if (f == GR_FIELD_ELEVATION) {
    gr_status st = gr_buffer_write(s->ctx, s->ground, 0, bytes, host);
    if (st != GR_OK)
      return st;
    s->bmin = lo, s->bmax = hi;
    if (s->zref != lo) {
      s->zref = lo;
      st = gr_snac_upload_geometry(s);
    }
    return st;
  }
  /* The new snow replaces what lies on the grid: the ledger's initial
   * volume moves by the change, so the balance still closes. */
  size_t nr = (size_t)s->own_ny * GR_SNAC_SUMS;
  double *before = malloc(nr * sizeof(double)), *after = malloc(nr * sizeof(double));
  gr_status st = before && after
                     ? gr_snac_rows(s, before)
                     : gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, s->depth0, 0, bytes, host);
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, s->arr[0], 0, bytes, host);
  if (st == GR_OK)
    st = gr_snac_fill(s, s->arr[1], cells, 0.0f);
  if (st == GR_OK)
    st = gr_snac_rows(s, after);
  for (int r = 0; st == GR_OK && r < s->own_ny; ++r)
    s->init_rows[r] += after[GR_SNAC_SUMS * (size_t)r] - before[GR_SNAC_SUMS * (size_t)r];
  free(before), free(after);
  if (st == GR_OK) {
    s->init_max = hi;
    s->snow_bound = fmax(s->snow_bound, hi);
  }
  return st;
}

gr_status gr_snow_accumulation_set_field(gr_snow_accumulation *s, gr_field f, const float *host) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_set_field needs a simulation.");
  if (!host)
    return GR_SNAC_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_set_field needs the field's values (got NULL)."));
  return GR_SNAC_KEEP_ERROR(s, gr_snac_set_field_impl(s, f, host));
}

gr_status gr_snow_accumulation_reset(gr_snow_accumulation *s) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_reset needs a simulation.");
  gr_status st = gr_snac_initial_state(s);
  return st == GR_OK ? GR_OK : GR_SNAC_KEEP_ERROR(s, st);
}
