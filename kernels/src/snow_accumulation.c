/* Snow accumulation core (seed 002's thesis): host side of
 * snow_accumulation.cl. The model, its step order and its book-keeping are
 * documented in graupel/snow_accumulation.h; the constants both sides share
 * in snow_accumulation_shared.h. */
#include "graupel/snow_accumulation.h"
#include "graupel/cl_runtime.h"
#include "graupel/reduce.h"
#include "snow_accumulation_shared.h"

#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define GR_SNAC_MAX_ELEVATION 1.0e6
#define GR_SNAC_MAX_DEPTH 1.0e4
#define GR_SNAC_MIN_DT 1.0e-6
#define GR_SNAC_MAX_DT 86400.0
#define GR_SNAC_PI 3.14159265358979323846
/* Checkpoints: "GSA1". */
#define GR_SNAC_STATE_MAGIC 0x31415347u
#define GR_SNAC_STATE_VERSION 4u /* 3: a piece's j0 and the initial snow per row; 4: per face */
/* Per-point arrays of the state: depth, its low part, fallen and shed
 * snow (pairs) and the exposure. */
#define GR_SNAC_ARRAYS 7
/* The largest accumulation texture, texels across. */
#define GR_SNAC_MAX_TEXTURE 4096
/* The step waits for the device every this many steps, so that a long
 * loop of steps does not queue without bound. */
#define GR_SNAC_SYNC_EVERY 8

enum {
  GR_SNAC_P_FLUTTER,
  GR_SNAC_P_RATE,
  GR_SNAC_P_AMPLITUDE,
  GR_SNAC_P_SCALE,
  GR_SNAC_P_SEED,
  GR_SNAC_P_RESOLUTION,
  GR_SNAC_P_BLUR,
  GR_SNAC_P_DILATION,
  GR_SNAC_P_MAX_DEPTH,
  GR_SNAC_P_STABILITY,
  GR_SNAC_P_DENSITY,
  GR_SNAC_P_TEXTURE,
  GR_SNAC_P_COUNT
};

/* The one place each range is written. SnowfallRate: heavy snowfall is a
 * few cm/h, record falls about 20 cm/h. SnowDensity: fresh snow is 30 to
 * 200 kg/m^3, ice 900. */
static const gr_param_bound gr_snac_bounds[GR_SNAC_P_COUNT] = {
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

struct gr_snow_accumulation {
  gr_context *ctx;
  gr_grid grid;
  gr_snow_accumulation_params params;
  cl_kernel raster_terrain, raster_objects, exposure_k, noise_k, slope_k, blur, dilate, apply,
      objects_k, reduce, surface, row_sums, object_surface, object_exposure;
  /* A piece (graupel.h's contract, "Pieces of a split domain"): grid.nx,
   * grid.ny count the local arrays (own rows and rings); the domain has
   * gnx x gny points, local row 0 is its row row0, the own rows are local
   * rows ring_s .. ring_s + own_ny - 1. A whole grid: no rings, row0 0. */
  int gnx, gny, row0, own_ny, ring_s, ring_n;
  gr_allreduce_fn allreduce; /* NULL: this simulation is the whole domain */
  void *allreduce_user;
  gr_halo_exchange_fn halo_exchange;
  void *halo_user;
  /* The ledger's initial grid snow per own row (m, per unit area), and the
   * objects' (m^3): see "Pieces" in the header for why per row. */
  double *init_rows, initial_objects;
  /* Per local row, the row sums' 6 floats; per face or sample, the
   * snow surface under it or its exposure (pieces only). */
  cl_mem rows_buf, o_surface;
  size_t o_surface_cap;
  /* Pieces, the steps with the terrain in the view: which view rows the
   * pieces combine (1) this step, and whether the objects' exposure is
   * combined per point instead of through the view rows under them. */
  unsigned char *view_rows;
  double *view_cover;
  size_t view_rows_cap;
  int objects_by_point;
  /* The grid: ground, initial snow, the state pairs, exposure, growth and
   * a scratch array, the blur weights and the view. */
  cl_mem ground, depth0, arr[GR_SNAC_ARRAYS], growth, scratch, weights, view;
  /* The grid's noise and what it was made for (seed, then the lattice's
   * origin and spacing); noise_made 0 until the first step. */
  cl_mem noise;
  int noise_made;
  cl_uint noise_seed;
  float noise_key[4];
  size_t view_cap; /* ints */
  /* The objects: world triangles, per face (triangle) the world position
   * of its centroid and its normal, the noise coordinates, the area and
   * the state arrays: snow lives on the faces (object o's are trifirst[o]
   * .. trifirst[o + 1] - 1), the mesh points show it (gr_snac_points). */
  int nobjects, nv, ntri;
  int first[GR_SNOW_ACCUMULATION_MAX_OBJECTS + 1], nverts[GR_SNOW_ACCUMULATION_MAX_OBJECTS];
  gr_mesh_memo memo[GR_SNOW_ACCUMULATION_MAX_OBJECTS]; /* each object's mesh as last checked */
  cl_mem o_tri, o_pos, o_nrm, o_local, o_area, o_arr[GR_SNAC_ARRAYS];
  /* Accumulation textures: per object its size (0: none) and UVs, its
   * samples (first .. first + count - 1 of the sample arrays) and per
   * sample its texel, triangle and barycentric weights; the samples'
   * world positions (absolute) and the device arrays, like the mesh
   * points'. hlocal: the mesh points in their objects' frames. */
  int tsize[GR_SNOW_ACCUMULATION_MAX_OBJECTS], tfirst[GR_SNOW_ACCUMULATION_MAX_OBJECTS + 1];
  int trifirst[GR_SNOW_ACCUMULATION_MAX_OBJECTS + 1];
  float *tuv[GR_SNOW_ACCUMULATION_MAX_OBJECTS];
  int ns, tobjects, *stexel, *stri;
  float *sbar, *hlocal;
  double *sv;
  cl_mem t_pos, t_nrm, t_local, t_arr[GR_SNAC_ARRAYS];
  double *hv;                /* world vertices, 3 per mesh point, absolute */
  int *ht;                   /* triangles, indices into hv */
  float *hnrm;               /* world normals, 3 per face */
  float *harea;              /* face areas (the object's own frame) */
  double ob_lo[3], ob_hi[3]; /* the objects' world box */
  gr_reduction red, red_slope;
  double zref, bmin, bmax, init_max, snow_bound;
  double time, retired_fall, retired_shed, dropped;
  long long steps;
  gr_progress_fn progress;
  void *progress_user;
  int aborted;
  int timing;
  double t_mark;
  gr_snow_accumulation_timing tm;
  char error[1024];
};

#define GR_SNAC_KEEP_ERROR(s, st) gr_error_keep((s)->error, sizeof((s)->error), (st))

/* A named kernel argument. */
typedef struct gr_snac_arg {
  const char *name;
  size_t size;
  const void *value;
} gr_snac_arg;

#define GR_SNAC_MEM(name, m)                                                                       \
  { (name), sizeof(cl_mem), &(m) }
#define GR_SNAC_VAL(name, v)                                                                       \
  { (name), sizeof(v), &(v) }

static gr_status gr_snac_args(gr_snow_accumulation *s, cl_kernel k, const gr_snac_arg *args,
                              size_t n) {
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
  if (!p) {
    if (msg && msg_len)
      snprintf(msg, msg_len, "Invalid snow accumulation parameters: no parameters were given.");
    return GR_ERR_INVALID_ARGUMENT;
  }
  for (int row = 0; row < GR_SNAC_P_COUNT; ++row) {
    const gr_param_bound *r = &gr_snac_bounds[row];
    double v = gr_snac_param_value(p, row);
    if (gr_param_accepts(r, v))
      continue;
    gr_param_explain(r, v, "Invalid snow accumulation parameters", msg, msg_len);
    return GR_ERR_INVALID_ARGUMENT;
  }
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

static double gr_snac_now_ms(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return 1e3 * (double)ts.tv_sec + 1e-6 * (double)ts.tv_nsec;
}

/* With timing on: waits for the stage just enqueued and charges its time. */
static gr_status gr_snac_mark(gr_snow_accumulation *s, double *acc) {
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

static size_t gr_snac_cells(const gr_snow_accumulation *s) {
  return (size_t)s->grid.nx * (size_t)s->grid.ny;
}

static gr_status gr_snac_fill(gr_snow_accumulation *s, cl_mem buf, size_t n, float value) {
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
static gr_status gr_snac_sums(gr_snow_accumulation *s, int objects, int first, int n,
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

/* ------------------------------------------------------ pieces and rows */

int gr_snow_accumulation_ghost(const gr_snow_accumulation_params *p) {
  return p ? p->blur_radius + 2 : 0;
}

/* The piece contract (graupel.h, snow_accumulation.h): strips of whole rows,
 * a ring of grid->ghost rows toward each neighbour. */
static gr_status gr_snac_piece_check(const gr_grid *g, const gr_snow_accumulation_params *p,
                                     int *ring_s, int *ring_n, char *msg, size_t len) {
  char why[48];
  snprintf(why, sizeof(why), "for BlurRadius %d", p->blur_radius);
  return gr_grid_strip_check(g, "snow accumulation", " (its ledger adds whole rows)",
                             gr_snow_accumulation_ghost(p), why, ring_s, ring_n, msg, len);
}

static int gr_snac_pieced(const gr_snow_accumulation *s) {
  return s->ring_s > 0 || s->ring_n > 0;
}

void gr_snow_accumulation_set_allreduce(gr_snow_accumulation *s, gr_allreduce_fn fn, void *user) {
  if (!s)
    return;
  s->allreduce = fn;
  s->allreduce_user = fn ? user : NULL;
}

void gr_snow_accumulation_set_halo_exchange(gr_snow_accumulation *s, gr_halo_exchange_fn fn,
                                            void *user) {
  if (!s)
    return;
  s->halo_exchange = fn;
  s->halo_user = fn ? user : NULL;
}

/* The caller's allreduce over n values, in calls of at most
 * GR_SNOW_ACCUMULATION_REDUCE_CHUNK. */
static gr_status gr_snac_allreduce(gr_snow_accumulation *s, double *v, size_t n, gr_reduce_op op) {
  for (size_t at = 0; at < n; at += GR_SNOW_ACCUMULATION_REDUCE_CHUNK) {
    size_t m =
        n - at < GR_SNOW_ACCUMULATION_REDUCE_CHUNK ? n - at : GR_SNOW_ACCUMULATION_REDUCE_CHUNK;
    gr_status st = s->allreduce(s->allreduce_user, v + at, (int)m, op);
    if (st != GR_OK)
      return gr_set_error(s->ctx, st,
                          "The snow accumulation simulation's global reduction (the allreduce "
                          "callback) failed in step %lld with %s.",
                          s->steps + 1, gr_status_string(st));
  }
  return GR_OK;
}

/* Per own row: stored, fallen and shed snow (m, per unit area), 3 doubles
 * a row, each a row's sum in order along it (snow_accumulation_row_sums). */
static gr_status gr_snac_rows(gr_snow_accumulation *s, double *out) {
  cl_int nx = s->grid.nx, first = s->ring_s, rows = s->own_ny;
  const gr_snac_arg args[] = {GR_SNAC_MEM("depth", s->arr[0]), GR_SNAC_MEM("depth_lo", s->arr[1]),
                              GR_SNAC_MEM("fall", s->arr[2]),  GR_SNAC_MEM("fall_lo", s->arr[3]),
                              GR_SNAC_MEM("shed", s->arr[4]),  GR_SNAC_MEM("shed_lo", s->arr[5]),
                              GR_SNAC_VAL("nx", nx),           GR_SNAC_VAL("first", first),
                              GR_SNAC_VAL("rows", rows),       GR_SNAC_MEM("out", s->rows_buf)};
  size_t n = (size_t)rows * 2 * GR_SNAC_SUMS;
  float *f = malloc(n * sizeof(float));
  if (!f)
    return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  gr_status st = gr_snac_args(s, s->row_sums, args, sizeof(args) / sizeof(args[0]));
  if (st == GR_OK)
    st = gr_enqueue_1d(s->ctx, s->row_sums, (size_t)rows);
  if (st == GR_OK)
    st = gr_buffer_read(s->ctx, s->rows_buf, 0, n * sizeof(float), f);
  for (size_t r = 0; st == GR_OK && r < (size_t)rows; ++r)
    for (int q = 0; q < GR_SNAC_SUMS; ++q)
      out[GR_SNAC_SUMS * r + (size_t)q] = (double)f[2 * GR_SNAC_SUMS * r + 2 * (size_t)q] +
                                          (double)f[2 * GR_SNAC_SUMS * r + 2 * (size_t)q + 1];
  free(f);
  return st;
}

/* The grid's ledger sums, m per unit area: stored, fallen, shed and
 * initial snow. Each piece puts its rows' sums at their rows of the domain
 * (-inf elsewhere), a GR_REDUCE_MAX makes every row's the same on every
 * piece (one value and -infs: exact in any order and with any reduction
 * scheme, unlike a sum), and the rows are added in the domain's order: the
 * same bits however the domain is split. A piece without an allreduce
 * adds its own rows. */
static gr_status gr_snac_grid_sums(gr_snow_accumulation *s, double sums[4]) {
  int global = gr_snac_pieced(s) && s->allreduce;
  size_t R = global ? (size_t)s->gny : (size_t)s->own_ny;
  size_t base = global ? (size_t)(s->row0 + s->ring_s) : 0;
  double *rows = malloc(4 * R * sizeof(double));
  double *own = malloc((size_t)s->own_ny * GR_SNAC_SUMS * sizeof(double));
  gr_status st =
      rows && own ? GR_OK : gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  if (st == GR_OK)
    st = gr_snac_rows(s, own);
  for (size_t k = 0; st == GR_OK && k < 4 * R; ++k)
    rows[k] = -HUGE_VAL;
  for (size_t r = 0; st == GR_OK && r < (size_t)s->own_ny; ++r) {
    for (int q = 0; q < GR_SNAC_SUMS; ++q)
      rows[4 * (base + r) + (size_t)q] = own[GR_SNAC_SUMS * r + (size_t)q];
    rows[4 * (base + r) + 3] = s->init_rows[r];
  }
  if (st == GR_OK && global)
    st = gr_snac_allreduce(s, rows, 4 * R, GR_REDUCE_MAX);
  for (int q = 0; q < 4; ++q)
    sums[q] = 0.0;
  for (size_t r = 0; st == GR_OK && r < R; ++r)
    for (int q = 0; q < 4; ++q)
      sums[q] += rows[4 * r + (size_t)q];
  free(rows), free(own);
  return st;
}

/* The strip on `side`: rows of the local arrays and how many. */
static int gr_snac_strip(const gr_snow_accumulation *s, int side, int set, size_t *row0) {
  int G = s->grid.ghost;
  if (side == GR_SNOW_ACCUMULATION_SOUTH && s->ring_s) {
    *row0 = set ? 0 : (size_t)s->ring_s;
    return G;
  }
  if (side == GR_SNOW_ACCUMULATION_NORTH && s->ring_n) {
    *row0 = set ? (size_t)(s->grid.ny - G) : (size_t)(s->grid.ny - s->ring_n - G);
    return G;
  }
  return 0;
}

gr_status gr_snow_accumulation_halo_size(const gr_snow_accumulation *s, int side, size_t *bytes) {
  if (!s || !bytes)
    return gr_set_error(s ? s->ctx : NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_halo_size needs a simulation and a place for the "
                        "size.");
  size_t row0 = 0;
  *bytes = (size_t)gr_snac_strip(s, side, 0, &row0) * (size_t)s->grid.nx * sizeof(float);
  return GR_OK;
}

/* The strip's snow depth between the device and the host; waits. */
static gr_status gr_snac_halo_copy(gr_snow_accumulation *s, int side, void *host, size_t bytes,
                                   int set) {
  size_t row0 = 0;
  size_t rows = (size_t)gr_snac_strip(s, side, set, &row0);
  if (rows == 0)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow accumulation piece has no neighbour on side %d (2 south, 3 "
                        "north): only sides with a ring exchange a halo.",
                        side);
  size_t row = (size_t)s->grid.nx * sizeof(float), need = rows * row;
  if (!host || bytes != need)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The halo buffer has %zu bytes but side %d's strip has %zu: size it with "
                        "gr_snow_accumulation_halo_size.",
                        host ? bytes : 0, side, need);
  return set ? gr_buffer_write(s->ctx, s->arr[0], row0 * row, need, host)
             : gr_buffer_read(s->ctx, s->arr[0], row0 * row, need, host);
}

gr_status gr_snow_accumulation_halo_get(gr_snow_accumulation *s, int side, void *host,
                                        size_t bytes) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_halo_get needs a simulation.");
  gr_status st = gr_snac_halo_copy(s, side, host, bytes, 0);
  return st == GR_OK ? GR_OK : GR_SNAC_KEEP_ERROR(s, st);
}

gr_status gr_snow_accumulation_halo_set(gr_snow_accumulation *s, int side, const void *host,
                                        size_t bytes) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_halo_set needs a simulation.");
  /* The copy only reads host (set = 1). */
  gr_status st = gr_snac_halo_copy(s, side, (void *)host, bytes, 1);
  return st == GR_OK ? GR_OK : GR_SNAC_KEEP_ERROR(s, st);
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

static void gr_snac_release_textures(cl_mem *pos, cl_mem *nrm, cl_mem *local, cl_mem *arr);

static void gr_snac_release_objects(gr_snow_accumulation *s) {
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
static gr_status gr_snac_upload_geometry(gr_snow_accumulation *s) {
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

/* The new objects' geometry on the host: world vertices, triangles with
 * global indices, and per face its world normal, noise coordinates (its
 * centroid in the object's own frame) and area (in the object's own
 * frame); hlocal: the mesh points in their objects' frames. */
typedef struct gr_snac_geometry {
  double *hv;
  int *ht;
  float *nrm, *local, *area, *hlocal;
  double lo[3], hi[3];
} gr_snac_geometry;

static void gr_snac_geometry_free(gr_snac_geometry *g) {
  free(g->hv), free(g->ht), free(g->nrm), free(g->local), free(g->area), free(g->hlocal);
}

static gr_status gr_snac_build_geometry(gr_snow_accumulation *s, const gr_mesh *meshes, int n,
                                        const int *first, int nv, int nt, gr_snac_geometry *g) {
  size_t V = nv ? (size_t)nv : 1, T = nt ? (size_t)nt : 1;
  g->hv = malloc(V * 3 * sizeof(double));
  g->ht = malloc(T * 3 * sizeof(int));
  g->nrm = calloc(T * 3, sizeof(float));
  g->local = malloc(T * 3 * sizeof(float));
  g->area = calloc(T, sizeof(float));
  g->hlocal = malloc(V * 3 * sizeof(float));
  if (!g->hv || !g->ht || !g->nrm || !g->local || !g->area || !g->hlocal)
    return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  for (int a = 0; a < 3; ++a)
    g->lo[a] = HUGE_VAL, g->hi[a] = -HUGE_VAL;
  double inv_scale = 1.0 / s->params.noise_scale;
  size_t at = 0;
  for (int o = 0; o < n; ++o) {
    const gr_mesh *m = &meshes[o];
    const double *T4 = m->transform;
    for (int v = 0; v < m->nvertices; ++v) {
      const float *p = m->vertices + 3 * v;
      size_t k = (size_t)(first[o] + v);
      memcpy(g->hlocal + 3 * k, p, 3 * sizeof(float));
      for (int a = 0; a < 3; ++a) {
        double w = T4[a] * p[0] + T4[4 + a] * p[1] + T4[8 + a] * p[2] + T4[12 + a];
        g->hv[3 * k + a] = w;
        g->lo[a] = fmin(g->lo[a], w);
        g->hi[a] = fmax(g->hi[a], w);
      }
    }
    for (int t = 0; t < m->ntriangles; ++t, ++at) {
      int idx[3];
      for (int q = 0; q < 3; ++q) {
        idx[q] = first[o] + m->triangles[3 * t + q];
        g->ht[3 * at + q] = idx[q];
      }
      const double *A = g->hv + 3 * (size_t)idx[0], *B = g->hv + 3 * (size_t)idx[1],
                   *C = g->hv + 3 * (size_t)idx[2];
      double u[3] = {B[0] - A[0], B[1] - A[1], B[2] - A[2]};
      double w[3] = {C[0] - A[0], C[1] - A[1], C[2] - A[2]};
      double cr[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                      u[0] * w[1] - u[1] * w[0]};
      double len = sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
      const float *a = m->vertices + 3 * m->triangles[3 * t],
                  *b = m->vertices + 3 * m->triangles[3 * t + 1],
                  *c = m->vertices + 3 * m->triangles[3 * t + 2];
      double lu[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
      double lw[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      double lc[3] = {lu[1] * lw[2] - lu[2] * lw[1], lu[2] * lw[0] - lu[0] * lw[2],
                      lu[0] * lw[1] - lu[1] * lw[0]};
      g->area[at] = (float)(0.5 * sqrt(lc[0] * lc[0] + lc[1] * lc[1] + lc[2] * lc[2]));
      for (int e = 0; e < 3; ++e) {
        g->nrm[3 * at + e] = len > 0.0 ? (float)(cr[e] / len) : 0.0f;
        /* Per object a different stretch of the noise lattice. */
        double cen = ((double)a[e] + b[e] + c[e]) / 3.0;
        g->local[3 * at + e] =
            (float)fmod(cen * inv_scale + 97.0 * (double)o, GR_SNAC_NOISE_PERIOD);
      }
    }
  }
  return GR_OK;
}

/* What object o's mesh points show of its faces' snow (the state lives on
 * the faces): per point the mean of its faces' values (which = 0 the
 * depth, 6 the exposure) weighted by the area each turns to the sky, A
 * max(0, n . up), so that an edge between a roof and a wall or a cone's
 * side and its base shows the snow of the face that holds it; a point
 * whose faces all face sideways or down takes their plain area-weighted
 * mean. With offsets (3 floats a point), the same mean of the faces' unit
 * normals, made unit, times the depth. Waits. */
static gr_status gr_snac_points(gr_snow_accumulation *s, int o, int which, float *host, int n,
                                float *offsets) {
  int t0 = s->trifirst[o], nt = s->trifirst[o + 1] - t0, v0 = s->first[o];
  size_t N = n > 0 ? (size_t)n : 1;
  float *f = malloc((nt > 0 ? (size_t)nt : 1) * sizeof(float));
  double *acc = calloc(N * 10, sizeof(double));
  gr_status st = GR_OK;
  if (!f || !acc)
    st = gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  if (st == GR_OK && nt > 0)
    st = gr_buffer_read(s->ctx, s->o_arr[which], (size_t)t0 * sizeof(float),
                        (size_t)nt * sizeof(float), f);
  /* Per point: the sky-weighted sums (weight, value, normal) and the plain
   * ones (weight, value, normal). */
  for (int t = 0; st == GR_OK && t < nt; ++t) {
    const float *nr = s->hnrm + 3 * (size_t)(t0 + t);
    double area = s->harea[t0 + t], sky = area * fmax(0.0, (double)nr[2]);
    for (int q = 0; q < 3; ++q) {
      double *a = acc + 10 * (size_t)(s->ht[3 * (size_t)(t0 + t) + q] - v0);
      a[0] += sky, a[1] += sky * f[t];
      a[5] += area, a[6] += area * f[t];
      for (int e = 0; e < 3; ++e)
        a[2 + e] += sky * nr[e], a[7 + e] += area * nr[e];
    }
  }
  for (int v = 0; st == GR_OK && v < n; ++v) {
    const double *a = acc + 10 * (size_t)v;
    int k = a[0] > 0.0 ? 0 : 5;
    double value = a[k] > 0.0 ? a[k + 1] / a[k] : 0.0;
    host[v] = (float)value;
    if (offsets) {
      double len = sqrt(a[k + 2] * a[k + 2] + a[k + 3] * a[k + 3] + a[k + 4] * a[k + 4]);
      for (int e = 0; e < 3; ++e)
        offsets[3 * v + e] = len > 0.0 ? (float)(a[k + 2 + e] / len * value) : 0.0f;
    }
  }
  free(f), free(acc);
  return st;
}

/* ------------------------------------------------- accumulation textures */

static void gr_snac_release_textures(cl_mem *pos, cl_mem *nrm, cl_mem *local, cl_mem *arr) {
  gr_buffer_release(pos);
  gr_buffer_release(nrm);
  gr_buffer_release(local);
  for (int a = 0; a < GR_SNAC_ARRAYS; ++a)
    gr_buffer_release(&arr[a]);
}

/* The samples being built: per sample its texel, triangle and barycentric
 * weights. */
typedef struct gr_snac_samples {
  size_t n, cap;
  int *texel, *tri;
  float *bar;
} gr_snac_samples;

static int gr_snac_push(gr_snac_samples *q, int texel, int tri, double l0, double l1, double l2) {
  if (q->n == q->cap) {
    size_t cap = q->cap ? 2 * q->cap : 1024;
    int *a = realloc(q->texel, cap * sizeof(int));
    if (a)
      q->texel = a;
    int *b = a ? realloc(q->tri, cap * sizeof(int)) : NULL;
    if (b)
      q->tri = b;
    float *c = b ? realloc(q->bar, cap * 3 * sizeof(float)) : NULL;
    if (!c)
      return 0;
    q->bar = c;
    q->cap = cap;
  }
  q->texel[q->n] = texel;
  q->tri[q->n] = tri;
  q->bar[3 * q->n] = (float)l0, q->bar[3 * q->n + 1] = (float)l1, q->bar[3 * q->n + 2] = (float)l2;
  q->n++;
  return 1;
}

/* Object o's samples: one per texel whose centre falls in one of its
 * triangles' UV triangles (the first such triangle; texels on no triangle
 * get none). */
static int gr_snac_object_samples(const gr_snow_accumulation *s, int o, gr_snac_samples *q) {
  int R = s->tsize[o];
  unsigned char *cov = calloc((size_t)R * (size_t)R, 1);
  if (!cov)
    return 0;
  const float *uv = s->tuv[o];
  const double eps = 1e-9;
  for (int t = s->trifirst[o]; t < s->trifirst[o + 1]; ++t) {
    const float *a = uv + 2 * (size_t)(s->ht[3 * t] - s->first[o]),
                *b = uv + 2 * (size_t)(s->ht[3 * t + 1] - s->first[o]),
                *c = uv + 2 * (size_t)(s->ht[3 * t + 2] - s->first[o]);
    double e1u = (double)b[0] - a[0], e1v = (double)b[1] - a[1];
    double e2u = (double)c[0] - a[0], e2v = (double)c[1] - a[1];
    double det = e1u * e2v - e1v * e2u;
    if (fabs(det) < 1e-20)
      continue;
    double umin = fmin(a[0], fmin(b[0], c[0])), umax = fmax(a[0], fmax(b[0], c[0]));
    double vmin = fmin(a[1], fmin(b[1], c[1])), vmax = fmax(a[1], fmax(b[1], c[1]));
    int i0 = (int)fmax(0.0, ceil(umin * R - 0.5)), i1 = (int)fmin(R - 1.0, floor(umax * R - 0.5));
    int j0 = (int)fmax(0.0, ceil(vmin * R - 0.5)), j1 = (int)fmin(R - 1.0, floor(vmax * R - 0.5));
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        int texel = j * R + i;
        if (cov[texel])
          continue;
        double du = (i + 0.5) / R - a[0], dv = (j + 0.5) / R - a[1];
        double l1 = (du * e2v - dv * e2u) / det, l2 = (e1u * dv - e1v * du) / det;
        double l0 = 1.0 - l1 - l2;
        if (l0 < -eps || l1 < -eps || l2 < -eps)
          continue;
        cov[texel] = 1;
        if (!gr_snac_push(q, texel, t, l0, l1, l2)) {
          free(cov);
          return 0;
        }
      }
  }
  free(cov);
  return 1;
}

/* Rebuilds the samples of every textured object from the objects set now;
 * object o's samples keep their snow when kept[o] and it has as many as
 * before, else start at 0. All or nothing: a failure leaves the textures
 * as they were. The positions go up with gr_snac_upload_geometry. */
static gr_status gr_snac_textures(gr_snow_accumulation *s, const unsigned char *kept) {
  gr_snac_samples q;
  memset(&q, 0, sizeof(q));
  int tfirst[GR_SNOW_ACCUMULATION_MAX_OBJECTS + 1];
  for (int o = 0; o < s->nobjects; ++o) {
    tfirst[o] = (int)q.n;
    if (s->tsize[o] > 0 && !gr_snac_object_samples(s, o, &q)) {
      free(q.texel), free(q.tri), free(q.bar);
      return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
    }
    if (q.n > (size_t)(INT_MAX / 4)) {
      free(q.texel), free(q.tri), free(q.bar);
      return gr_set_error(s->ctx, GR_ERR_TOO_LARGE,
                          "The accumulation textures have more than %d covered texels, more "
                          "than the core addresses; lower AccumulationTextureSize.",
                          INT_MAX / 4);
    }
  }
  tfirst[s->nobjects] = (int)q.n;
  size_t ns = q.n, S = ns ? ns : 1;
  double *sv = malloc(S * 3 * sizeof(double));
  float *nrm = calloc(S * 3, sizeof(float)), *lat = malloc(S * 3 * sizeof(float));
  gr_status st = GR_OK;
  if (!sv || !nrm || !lat)
    st = gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  double inv_scale = 1.0 / s->params.noise_scale;
  for (int o = 0; st == GR_OK && o < s->nobjects; ++o)
    for (int k = tfirst[o]; k < tfirst[o + 1]; ++k) {
      const int *ix = s->ht + 3 * (size_t)q.tri[k];
      const float *b = q.bar + 3 * (size_t)k;
      /* The triangle's own normal: a texel lies on one face (the mesh
       * points' normals average their faces). */
      const double *A = s->hv + 3 * (size_t)ix[0], *B = s->hv + 3 * (size_t)ix[1],
                   *C = s->hv + 3 * (size_t)ix[2];
      double u[3] = {B[0] - A[0], B[1] - A[1], B[2] - A[2]};
      double w[3] = {C[0] - A[0], C[1] - A[1], C[2] - A[2]};
      double cr[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                      u[0] * w[1] - u[1] * w[0]};
      double len = sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
      for (int a = 0; a < 3; ++a) {
        sv[3 * (size_t)k + a] = b[0] * A[a] + b[1] * B[a] + b[2] * C[a];
        nrm[3 * (size_t)k + a] = len > 0.0 ? (float)(cr[a] / len) : 0.0f;
        double p = b[0] * (double)s->hlocal[3 * (size_t)ix[0] + a] +
                   b[1] * (double)s->hlocal[3 * (size_t)ix[1] + a] +
                   b[2] * (double)s->hlocal[3 * (size_t)ix[2] + a];
        lat[3 * (size_t)k + a] =
            (float)fmod(p * inv_scale + 97.0 * (double)o, GR_SNAC_NOISE_PERIOD);
      }
    }
  /* The same layout keeps the buffers; otherwise new ones, the kept
   * objects' snow copied over. */
  int same = (int)ns == s->ns && s->t_arr[0] != NULL;
  for (int o = 0; same && o < s->nobjects; ++o)
    same = kept[o] && o < s->tobjects && tfirst[o] == s->tfirst[o] &&
           tfirst[o + 1] == s->tfirst[o + 1];
  cl_mem tp = NULL, tn = NULL, tl = NULL, ta[GR_SNAC_ARRAYS];
  memset(ta, 0, sizeof(ta));
  if (st == GR_OK && !same && ns > 0) {
    st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, S * 3 * sizeof(float), NULL, &tp);
    if (st == GR_OK)
      st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, S * 3 * sizeof(float), NULL, &tn);
    if (st == GR_OK)
      st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, S * 3 * sizeof(float), NULL, &tl);
    for (int a = 0; st == GR_OK && a < GR_SNAC_ARRAYS; ++a) {
      st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, S * sizeof(float), NULL, &ta[a]);
      if (st == GR_OK)
        st = gr_snac_fill(s, ta[a], S, 0.0f);
    }
    for (int o = 0; st == GR_OK && o < s->nobjects && o < s->tobjects; ++o) {
      int cnt = tfirst[o + 1] - tfirst[o];
      if (!kept[o] || cnt == 0 || cnt != s->tfirst[o + 1] - s->tfirst[o] || !s->t_arr[0])
        continue;
      for (int a = 0; st == GR_OK && a < GR_SNAC_ARRAYS; ++a)
        st = gr_cl_check(s->ctx,
                         clEnqueueCopyBuffer(gr_context_queue(s->ctx), s->t_arr[a], ta[a],
                                             (size_t)s->tfirst[o] * sizeof(float),
                                             (size_t)tfirst[o] * sizeof(float),
                                             (size_t)cnt * sizeof(float), 0, NULL, NULL),
                         "Copying an object's accumulation texture");
    }
  }
  if (st == GR_OK && ns > 0) {
    st = gr_buffer_write(s->ctx, same ? s->t_nrm : tn, 0, ns * 3 * sizeof(float), nrm);
    if (st == GR_OK)
      st = gr_buffer_write(s->ctx, same ? s->t_local : tl, 0, ns * 3 * sizeof(float), lat);
  }
  free(nrm), free(lat);
  if (st != GR_OK) {
    gr_snac_release_textures(&tp, &tn, &tl, ta);
    free(sv), free(q.texel), free(q.tri), free(q.bar);
    return st;
  }
  if (!same) {
    gr_snac_release_textures(&s->t_pos, &s->t_nrm, &s->t_local, s->t_arr);
    s->t_pos = tp, s->t_nrm = tn, s->t_local = tl;
    memcpy(s->t_arr, ta, sizeof(ta));
  }
  free(s->sv), free(s->stexel), free(s->stri), free(s->sbar);
  s->sv = sv, s->stexel = q.texel, s->stri = q.tri, s->sbar = q.bar;
  s->ns = (int)ns;
  s->tobjects = s->nobjects;
  memcpy(s->tfirst, tfirst, (size_t)(s->nobjects + 1) * sizeof(int));
  return GR_OK;
}

static gr_status gr_snac_set_objects_impl(gr_snow_accumulation *s, const gr_mesh *meshes, int n) {
  char msg[320];
  if (n < 0 || n > GR_SNOW_ACCUMULATION_MAX_OBJECTS || (n > 0 && !meshes))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_set_objects takes 0 to %d objects with their meshes "
                        "(got %d%s).",
                        GR_SNOW_ACCUMULATION_MAX_OBJECTS, n,
                        n > 0 && !meshes ? " and no meshes" : "");
  int first[GR_SNOW_ACCUMULATION_MAX_OBJECTS + 1];
  long long nv = 0, nt = 0;
  for (int o = 0; o < n; ++o) {
    if (gr_mesh_check(&s->memo[o], &meshes[o], 0, msg, sizeof(msg)) != GR_OK)
      return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT, "Object %d: %s", o, msg);
    first[o] = (int)nv;
    nv += meshes[o].nvertices;
    nt += meshes[o].ntriangles;
    if (nv > INT_MAX / 4 || nt > INT_MAX / 16)
      return gr_set_error(s->ctx, GR_ERR_TOO_LARGE,
                          "The objects have more than %d mesh points or %d triangles, more than "
                          "the core addresses; simplify the meshes.",
                          INT_MAX / 4, INT_MAX / 16);
  }
  first[n] = (int)nv;
  /* Which objects keep their snow: the same index with as many points and
   * faces (the snow lives on the faces). */
  unsigned char kept[GR_SNOW_ACCUMULATION_MAX_OBJECTS];
  int trifirst[GR_SNOW_ACCUMULATION_MAX_OBJECTS + 1];
  trifirst[0] = 0;
  for (int o = 0; o < n; ++o) {
    kept[o] = (unsigned char)(o < s->nobjects && meshes[o].nvertices == s->nverts[o] &&
                              meshes[o].ntriangles == s->trifirst[o + 1] - s->trifirst[o]);
    trifirst[o + 1] = trifirst[o] + meshes[o].ntriangles;
  }
  int same = n == s->nobjects;
  for (int o = 0; same && o < n; ++o)
    same = kept[o];
  gr_snac_geometry g;
  memset(&g, 0, sizeof(g));
  gr_status st = gr_snac_build_geometry(s, meshes, n, first, (int)nv, (int)nt, &g);
  cl_mem nb[5] = {NULL, NULL, NULL, NULL, NULL}, na[GR_SNAC_ARRAYS];
  memset(na, 0, sizeof(na));
  size_t T = nt ? (size_t)nt : 1;
  if (!same) {
    size_t sizes[5] = {T * 9, T * 3, T * 3, T * 3, T};
    for (int b = 0; st == GR_OK && b < 5; ++b)
      st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, sizes[b] * sizeof(float), NULL, &nb[b]);
    for (int a = 0; st == GR_OK && a < GR_SNAC_ARRAYS; ++a)
      st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, T * sizeof(float), NULL, &na[a]);
    /* Kept objects' state to their new place, the rest zero; the snow of
     * objects that go is dropped (counted). */
    for (int a = 0; st == GR_OK && a < GR_SNAC_ARRAYS; ++a) {
      float zero = 0.0f;
      st = gr_cl_check(s->ctx,
                       clEnqueueFillBuffer(gr_context_queue(s->ctx), na[a], &zero, sizeof(zero), 0,
                                           T * sizeof(float), 0, NULL, NULL),
                       "Clearing the objects' snow");
    }
    double fall = 0.0, shed = 0.0, stored = 0.0;
    for (int o = 0; st == GR_OK && o < s->nobjects; ++o) {
      int keep = o < n && kept[o], faces = s->trifirst[o + 1] - s->trifirst[o];
      if (keep && faces > 0) {
        for (int a = 0; st == GR_OK && a < GR_SNAC_ARRAYS; ++a)
          st = gr_cl_check(s->ctx,
                           clEnqueueCopyBuffer(gr_context_queue(s->ctx), s->o_arr[a], na[a],
                                               (size_t)s->trifirst[o] * sizeof(float),
                                               (size_t)trifirst[o] * sizeof(float),
                                               (size_t)faces * sizeof(float), 0, NULL, NULL),
                           "Copying an object's snow");
      } else if (!keep) {
        double sums[GR_SNAC_SUMS];
        st = gr_snac_sums(s, 1, s->trifirst[o], faces, sums);
        stored += sums[0], fall += sums[1], shed += sums[2];
      }
    }
    if (st == GR_OK) {
      s->retired_fall += fall;
      s->retired_shed += shed;
      s->dropped += stored;
    }
  }
  if (st != GR_OK) {
    for (int b = 0; b < 5; ++b)
      gr_buffer_release(&nb[b]);
    for (int a = 0; a < GR_SNAC_ARRAYS; ++a)
      gr_buffer_release(&na[a]);
    gr_snac_geometry_free(&g);
    return st;
  }
  if (!same) {
    gr_snac_release_objects(s);
    s->o_tri = nb[0], s->o_pos = nb[1], s->o_nrm = nb[2], s->o_local = nb[3], s->o_area = nb[4];
    memcpy(s->o_arr, na, sizeof(na));
  }
  free(s->hv), free(s->ht), free(s->hnrm), free(s->harea), free(s->hlocal);
  s->hv = g.hv, s->ht = g.ht, s->hnrm = g.nrm, s->harea = g.area, s->hlocal = g.hlocal;
  s->nobjects = n;
  s->nv = (int)nv;
  s->ntri = (int)nt;
  for (int o = 0; o < n; ++o)
    s->nverts[o] = meshes[o].nvertices;
  memcpy(s->first, first, (size_t)(n + 1) * sizeof(int));
  memcpy(s->ob_lo, g.lo, sizeof(g.lo));
  memcpy(s->ob_hi, g.hi, sizeof(g.hi));
  memcpy(s->trifirst, trifirst, (size_t)(n + 1) * sizeof(int));
  /* A texture goes with its object; a kept object keeps its texture (its
   * samples move with it). */
  for (int o = 0; o < GR_SNOW_ACCUMULATION_MAX_OBJECTS; ++o)
    if (s->tsize[o] > 0 && (o >= n || !kept[o])) {
      free(s->tuv[o]);
      s->tuv[o] = NULL;
      s->tsize[o] = 0;
    }
  st = gr_snac_textures(s, kept);
  if (st == GR_OK && nt > 0) {
    st = gr_buffer_write(s->ctx, s->o_nrm, 0, (size_t)nt * 3 * sizeof(float), g.nrm);
    if (st == GR_OK)
      st = gr_buffer_write(s->ctx, s->o_local, 0, (size_t)nt * 3 * sizeof(float), g.local);
    if (st == GR_OK)
      st = gr_buffer_write(s->ctx, s->o_area, 0, (size_t)nt * sizeof(float), g.area);
    if (st == GR_OK)
      st = gr_snac_upload_geometry(s);
  }
  free(g.local);
  return st;
}

gr_status gr_snow_accumulation_set_objects(gr_snow_accumulation *s, const gr_mesh *meshes, int n) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_set_objects needs a simulation.");
  return GR_SNAC_KEEP_ERROR(s, gr_snac_set_objects_impl(s, meshes, n));
}

static gr_status gr_snac_check_object(gr_snow_accumulation *s, const char *what, int o, int n,
                                      const void *host) {
  if (o < 0 || o >= s->nobjects)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "%s: there is no object %d (%d are set); pass an index from 0 to %d.", what,
                        o, s->nobjects, s->nobjects - 1);
  if (!host || n != s->nverts[o])
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "%s: object %d has %d mesh points but %d were given%s; pass one value per "
                        "mesh point.",
                        what, o, s->nverts[o], n, host ? "" : " (and no array)");
  return GR_OK;
}

gr_status gr_snow_accumulation_get_object_field(gr_snow_accumulation *s, int o, gr_field f,
                                                float *host, int n) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_get_object_field needs a simulation.");
  gr_status st = gr_snac_check_object(s, "gr_snow_accumulation_get_object_field", o, n, host);
  if (st == GR_OK && f != GR_FIELD_SNOW_DEPTH && f != GR_FIELD_EXPOSURE) {
    const char *name = gr_field_name(f);
    st = gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                      "The objects of the snow accumulation have no field '%s'; they give "
                      "snow_depth and exposure.",
                      name ? name : "(unknown field)");
  }
  if (st == GR_OK && n > 0)
    st = gr_snac_points(s, o, f == GR_FIELD_SNOW_DEPTH ? 0 : 6, host, n, NULL);
  return st == GR_OK ? GR_OK : GR_SNAC_KEEP_ERROR(s, st);
}

gr_status gr_snow_accumulation_get_object_offsets(gr_snow_accumulation *s, int o, float *xyz,
                                                  int n) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_get_object_offsets needs a simulation.");
  gr_status st = gr_snac_check_object(s, "gr_snow_accumulation_get_object_offsets", o, n, xyz);
  float *depth = st == GR_OK && n > 0 ? malloc((size_t)n * sizeof(float)) : NULL;
  if (st == GR_OK && n > 0 && !depth)
    st = gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  if (st == GR_OK && n > 0)
    st = gr_snac_points(s, o, 0, depth, n, xyz);
  free(depth);
  return st == GR_OK ? GR_OK : GR_SNAC_KEEP_ERROR(s, st);
}

gr_status gr_snow_accumulation_set_object_snow(gr_snow_accumulation *s, int o, const float *depth,
                                               int n) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_set_object_snow needs a simulation.");
  gr_status st = gr_snac_check_object(s, "gr_snow_accumulation_set_object_snow", o, n, depth);
  char msg[400];
  if (st == GR_OK && gr_snow_accumulation_field_validate(GR_FIELD_SNOW_DEPTH, depth, (size_t)n, 0,
                                                         msg, sizeof(msg)) != GR_OK)
    st = gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT, "Object %d: %s", o, msg);
  if (st != GR_OK || n == 0)
    return st == GR_OK ? GR_OK : GR_SNAC_KEEP_ERROR(s, st);
  /* The snow lives on the faces: each gets the mean of its corners'. */
  int t0 = s->trifirst[o], nt = s->trifirst[o + 1] - t0;
  if (nt == 0)
    return GR_OK;
  float *faces = malloc((size_t)nt * sizeof(float));
  if (!faces)
    return GR_SNAC_KEEP_ERROR(s, gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory."));
  for (int t = 0; t < nt; ++t) {
    const int *ix = s->ht + 3 * (size_t)(t0 + t);
    faces[t] = (float)(((double)depth[ix[0] - s->first[o]] + depth[ix[1] - s->first[o]] +
                        depth[ix[2] - s->first[o]]) /
                       3.0);
  }
  double before[GR_SNAC_SUMS], after[GR_SNAC_SUMS];
  size_t off = (size_t)t0 * sizeof(float), bytes = (size_t)nt * sizeof(float);
  float zero = 0.0f;
  st = gr_snac_sums(s, 1, t0, nt, before);
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, s->o_arr[0], off, bytes, faces);
  if (st == GR_OK)
    st = gr_cl_check(s->ctx,
                     clEnqueueFillBuffer(gr_context_queue(s->ctx), s->o_arr[1], &zero, sizeof(zero),
                                         off, bytes, 0, NULL, NULL),
                     "Clearing an object's snow");
  if (st == GR_OK)
    st = gr_snac_sums(s, 1, t0, nt, after);
  free(faces);
  if (st == GR_OK)
    s->initial_objects += after[0] - before[0];
  return st == GR_OK ? GR_OK : GR_SNAC_KEEP_ERROR(s, st);
}

gr_status gr_snow_accumulation_set_object_texture(gr_snow_accumulation *s, int o, const float *uv,
                                                  int size) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_set_object_texture needs a simulation.");
  const char *what = "gr_snow_accumulation_set_object_texture";
  gr_status st = GR_OK;
  char msg[400];
  if (o < 0 || o >= s->nobjects)
    st = gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                      "%s: there is no object %d (%d are set); pass an index from 0 to %d.", what,
                      o, s->nobjects, s->nobjects - 1);
  else if (!gr_param_accepts(&gr_snac_bounds[GR_SNAC_P_TEXTURE], (double)size)) {
    gr_param_explain(&gr_snac_bounds[GR_SNAC_P_TEXTURE], (double)size,
                     "Invalid accumulation texture", msg, sizeof(msg));
    st = gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT, "Object %d: %s", o, msg);
  } else if (size > 0 && !uv && s->nverts[o] > 0)
    st = gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                      "%s: object %d needs texture coordinates, 2 per mesh point (%d); pass "
                      "them or size 0 for no texture.",
                      what, o, s->nverts[o]);
  for (int k = 0; st == GR_OK && size > 0 && k < 2 * s->nverts[o]; ++k)
    if (!isfinite(uv[k]))
      st = gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "Object %d: texture coordinate %d of mesh point %d is %g; give finite "
                        "texture coordinates.",
                        o, k % 2, k / 2, (double)uv[k]);
  if (st != GR_OK)
    return GR_SNAC_KEEP_ERROR(s, st);
  size_t bytes = (size_t)s->nverts[o] * 2 * sizeof(float);
  /* The same texture again keeps its snow. */
  if (size == s->tsize[o] && (size == 0 || bytes == 0 || memcmp(uv, s->tuv[o], bytes) == 0))
    return GR_OK;
  float *copy = NULL;
  if (size > 0) {
    copy = malloc(bytes ? bytes : 1);
    if (!copy)
      return GR_SNAC_KEEP_ERROR(s,
                                gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory."));
    if (bytes)
      memcpy(copy, uv, bytes);
  }
  float *old_uv = s->tuv[o];
  int old_size = s->tsize[o];
  unsigned char kept[GR_SNOW_ACCUMULATION_MAX_OBJECTS];
  memset(kept, 1, sizeof(kept));
  kept[o] = 0;
  s->tuv[o] = copy, s->tsize[o] = size;
  st = gr_snac_textures(s, kept);
  if (st == GR_OK)
    st = gr_snac_upload_geometry(s);
  if (st != GR_OK) {
    s->tuv[o] = old_uv, s->tsize[o] = old_size;
    free(copy);
    return GR_SNAC_KEEP_ERROR(s, st);
  }
  free(old_uv);
  return GR_OK;
}

gr_status gr_snow_accumulation_get_object_texture(gr_snow_accumulation *s, int o, float *texels,
                                                  int size) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_get_object_texture needs a simulation.");
  gr_status st = GR_OK;
  if (o < 0 || o >= s->nobjects)
    st = gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                      "gr_snow_accumulation_get_object_texture: there is no object %d (%d are "
                      "set); pass an index from 0 to %d.",
                      o, s->nobjects, s->nobjects - 1);
  else if (s->tsize[o] == 0 || size != s->tsize[o] || !texels)
    st = gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                      "gr_snow_accumulation_get_object_texture: object %d has %s%d texels "
                      "across but %d were asked for%s; pass its size and size x size floats.",
                      o, s->tsize[o] ? "" : "no texture, ", s->tsize[o], size,
                      texels ? "" : " (and no array)");
  if (st != GR_OK)
    return GR_SNAC_KEEP_ERROR(s, st);
  size_t R = (size_t)size;
  memset(texels, 0, R * R * sizeof(float));
  int first = s->tfirst[o], cnt = s->tfirst[o + 1] - first;
  if (cnt == 0)
    return GR_OK;
  float *d = malloc((size_t)cnt * sizeof(float));
  if (!d)
    return GR_SNAC_KEEP_ERROR(s, gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory."));
  st = gr_buffer_read(s->ctx, s->t_arr[0], (size_t)first * sizeof(float),
                      (size_t)cnt * sizeof(float), d);
  for (int k = 0; st == GR_OK && k < cnt; ++k)
    texels[s->stexel[first + k]] = d[k];
  free(d);
  return st == GR_OK ? GR_OK : GR_SNAC_KEEP_ERROR(s, st);
}

/* A 64-bit mix (splitmix64): the flutter's random numbers per step. */
static uint64_t gr_snac_mix(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

/* This step's unit snow direction: SnowDirection turned by up to Flutter,
 * uniformly over the cone's disc, seeded by Seed and the step's number. */
static void gr_snac_direction(const gr_snow_accumulation *s, double d[3]) {
  const double *p = s->params.direction;
  double len = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
  for (int a = 0; a < 3; ++a)
    d[a] = p[a] / len;
  if (!(s->params.flutter > 0.0))
    return;
  uint64_t h = gr_snac_mix(((uint64_t)(uint32_t)s->params.seed << 32) ^ (uint64_t)s->steps);
  double u1 = (double)(h >> 11) / 9007199254740992.0;
  double u2 = (double)(gr_snac_mix(h) >> 11) / 9007199254740992.0;
  double alpha = s->params.flutter * sqrt(u1), beta = 2.0 * GR_SNAC_PI * u2;
  /* e1, e2: unit vectors across d. */
  double e1[3] = {1.0, 0.0, 0.0};
  if (fabs(d[0]) > 0.9)
    e1[0] = 0.0, e1[1] = 1.0;
  double dot = e1[0] * d[0] + e1[1] * d[1] + e1[2] * d[2];
  for (int a = 0; a < 3; ++a)
    e1[a] -= dot * d[a];
  double l1 = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
  for (int a = 0; a < 3; ++a)
    e1[a] /= l1;
  double e2[3] = {d[1] * e1[2] - d[2] * e1[1], d[2] * e1[0] - d[0] * e1[2],
                  d[0] * e1[1] - d[1] * e1[0]};
  for (int a = 0; a < 3; ++a)
    d[a] = cos(alpha) * d[a] + sin(alpha) * (cos(beta) * e1[a] + sin(beta) * e2[a]);
}

/* The view of one step: where rays along d cross z = 0 (tau), the extent
 * of the terrain's and the objects' crossings, and the texel. */
typedef struct gr_snac_view {
  float tau_x, tau_y, qx0, qy0, inv_texel, texel;
  int vw, vh;
} gr_snac_view;

static void gr_snac_view_of(const gr_snow_accumulation *s, const double d[3], gr_snac_view *v) {
  const gr_grid *g = &s->grid;
  double tx = -d[0] / d[2], ty = -d[1] / d[2];
  /* The domain's extent (a piece's view is the whole domain's). */
  double W = (s->gnx - 1) * g->dx, H = (s->gny - 1) * g->dy;
  double box[2][3][2] = {
      {{0.0, W}, {0.0, H}, {s->bmin - s->zref, s->bmax + s->snow_bound - s->zref}},
      {{0, 0}, {0, 0}, {0, 0}}};
  int nbox = 1;
  if (s->nv > 0) {
    /* The objects, but no further than half the grid beyond it: an object
     * far away would coarsen the view of the terrain. */
    double lox = s->ob_lo[0] - g->x0, hix = s->ob_hi[0] - g->x0;
    double loy = s->ob_lo[1] - g->y0, hiy = s->ob_hi[1] - g->y0;
    box[1][0][0] = fmax(lox, -0.5 * W - g->dx), box[1][0][1] = fmin(hix, 1.5 * W + g->dx);
    box[1][1][0] = fmax(loy, -0.5 * H - g->dy), box[1][1][1] = fmin(hiy, 1.5 * H + g->dy);
    box[1][2][0] = s->ob_lo[2] - s->zref, box[1][2][1] = s->ob_hi[2] - s->zref;
    nbox = box[1][0][0] <= box[1][0][1] && box[1][1][0] <= box[1][1][1] ? 2 : 1;
  }
  double qlo[2] = {HUGE_VAL, HUGE_VAL}, qhi[2] = {-HUGE_VAL, -HUGE_VAL};
  for (int b = 0; b < nbox; ++b)
    for (int k = 0; k < 8; ++k) {
      double x = box[b][0][k & 1], y = box[b][1][(k >> 1) & 1], z = box[b][2][(k >> 2) & 1];
      double q[2] = {x + z * tx, y + z * ty};
      for (int a = 0; a < 2; ++a)
        qlo[a] = fmin(qlo[a], q[a]), qhi[a] = fmax(qhi[a], q[a]);
    }
  int res = s->params.exposure_resolution;
  double span = fmax(qhi[0] - qlo[0], qhi[1] - qlo[1]);
  double texel = span > 0.0 ? span / res : fmax(g->dx, g->dy) / res;
  int m = GR_SNAC_VIEW_MARGIN;
  v->tau_x = (float)tx, v->tau_y = (float)ty;
  v->texel = (float)texel;
  v->inv_texel = (float)(1.0 / texel);
  v->qx0 = (float)(qlo[0] - m * texel);
  v->qy0 = (float)(qlo[1] - m * texel);
  v->vw = (int)fmin(ceil((qhi[0] - qlo[0]) / texel), (double)res) + 2 * m + 1;
  v->vh = (int)fmin(ceil((qhi[1] - qlo[1]) / texel), (double)res) + 2 * m + 1;
}

/* The view rows [lo, hi] that points projected between heights zlo and
 * zhi (relative to zref) at y from ylo to yhi (relative to grid point
 * (0, 0)) can fall in, with two rows to spare beyond the float rounding of
 * the kernels' projection; lo > hi when none. */
static void gr_snac_band(const gr_snac_view *v, double ylo, double yhi, double zlo, double zhi,
                         int *lo, int *hi) {
  double ty = v->tau_y, qy0 = v->qy0, inv = v->inv_texel, qmin = HUGE_VAL, qmax = -HUGE_VAL;
  for (int k = 0; k < 4; ++k) {
    double y = k & 1 ? yhi : ylo, z = k & 2 ? zhi : zlo;
    double q = (y + z * ty - qy0) * inv;
    qmin = fmin(qmin, q), qmax = fmax(qmax, q);
  }
  double big = fmax(fabs(ylo), fabs(yhi)) + fmax(fabs(zlo), fabs(zhi)) * fabs(ty) + fabs(qy0);
  double slack = 2.0 + 1e-5 * big * inv;
  double a = floor(qmin - slack), b = ceil(qmax + slack);
  *lo = a < 0.0 ? 0 : (int)fmin(a, (double)v->vh);
  *hi = b > v->vh - 1.0 ? v->vh - 1 : (int)fmax(b, -1.0);
}

/* The pieces' views combined, texel by texel, with a maximum (ints travel
 * exactly as doubles), in the rows where that can change a texel that a
 * piece reads. A piece draws its local cells (ring included) into rows of
 * a band its rows and the surface's height range bound, and its grid
 * points read only there; outside every other piece's band the others'
 * views hold the objects alone, which every piece draws the same, so a
 * piece's own texel is already the maximum. The rows two or more bands
 * cover are found by one reduction of 2 values a row (the highest and
 * lowest piece covering it) and only they are combined: a band of about
 * the ring plus the relief times the snow's slope across the cut, instead
 * of the whole view. The objects' points read rows anywhere: their
 * exposure is combined per point (snow_accumulation_object_exposure),
 * unless combining the rows under them costs fewer values. Waits. */
static gr_status gr_snac_view_reduce(gr_snow_accumulation *s, const gr_snac_view *v) {
  size_t vh = (size_t)v->vh, vw = (size_t)v->vw;
  if (vh > s->view_rows_cap) {
    unsigned char *r = realloc(s->view_rows, vh);
    if (r)
      s->view_rows = r;
    double *c = r ? realloc(s->view_cover, 2 * vh * sizeof(double)) : NULL;
    if (c)
      s->view_cover = c;
    if (!r || !c)
      return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
    s->view_rows_cap = vh;
  }
  unsigned char *rows = s->view_rows;
  double *cover = s->view_cover;
  /* This piece's band: its local rows, every height the view's box allows. */
  double zlo = fmin(0.0, s->bmin - s->zref), zhi = s->bmax + s->snow_bound - s->zref;
  int lo, hi;
  gr_snac_band(v, (double)s->row0 * s->grid.dy, (double)(s->row0 + s->grid.ny - 1) * s->grid.dy,
               zlo, zhi, &lo, &hi);
  double id = (double)(s->row0 + s->ring_s); /* the first own row: one per piece */
  for (size_t r = 0; r < vh; ++r) {
    int in = (int)r >= lo && (int)r <= hi;
    cover[2 * r] = in ? id : -HUGE_VAL;
    cover[2 * r + 1] = in ? -id : -HUGE_VAL;
  }
  gr_status st = gr_snac_allreduce(s, cover, 2 * vh, GR_REDUCE_MAX);
  if (st != GR_OK)
    return st;
  for (size_t r = 0; r < vh; ++r)
    rows[r] = cover[2 * r] > -HUGE_VAL && cover[2 * r] != -cover[2 * r + 1];
  /* The objects: the rows under their box (the same on every piece), or a
   * value per face and sample, whichever is fewer values. */
  s->objects_by_point = 0;
  size_t points = (size_t)s->ntri + (size_t)s->ns;
  if (points > 0) {
    double half = GR_SNAC_NORMAL_OFFSET * v->texel; /* a face's test position */
    gr_snac_band(v, s->ob_lo[1] - s->grid.y0 - half, s->ob_hi[1] - s->grid.y0 + half,
                 s->ob_lo[2] - s->zref - half, s->ob_hi[2] - s->zref + half, &lo, &hi);
    size_t extra = 0;
    for (int r = lo; r <= hi; ++r)
      extra += !rows[r];
    if (extra * vw > points)
      s->objects_by_point = 1;
    else
      for (int r = lo; r <= hi; ++r)
        rows[r] = 1;
  }
  size_t longest = 0, run = 0;
  for (size_t r = 0; r < vh; ++r) {
    run = rows[r] ? run + 1 : 0;
    longest = run > longest ? run : longest;
  }
  if (longest == 0)
    return GR_OK;
  cl_int *keys = malloc(longest * vw * sizeof(cl_int));
  double *vals = malloc(longest * vw * sizeof(double));
  if (!keys || !vals)
    st = gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  for (size_t r = 0; st == GR_OK && r < vh;) {
    if (!rows[r]) {
      ++r;
      continue;
    }
    size_t r1 = r;
    while (r1 < vh && rows[r1])
      ++r1;
    size_t n = (r1 - r) * vw, at = r * vw;
    st = gr_buffer_read(s->ctx, s->view, at * sizeof(cl_int), n * sizeof(cl_int), keys);
    for (size_t t = 0; st == GR_OK && t < n; ++t)
      vals[t] = (double)keys[t];
    if (st == GR_OK)
      st = gr_snac_allreduce(s, vals, n, GR_REDUCE_MAX);
    for (size_t t = 0; st == GR_OK && t < n; ++t)
      keys[t] = (cl_int)vals[t];
    if (st == GR_OK)
      st = gr_buffer_write(s->ctx, s->view, at * sizeof(cl_int), n * sizeof(cl_int), keys);
    r = r1;
  }
  free(keys), free(vals);
  return st;
}

/* Room for n values per face or sample in s->o_surface. */
static gr_status gr_snac_point_buffer(gr_snow_accumulation *s, size_t n) {
  if (n <= s->o_surface_cap)
    return GR_OK;
  gr_buffer_release(&s->o_surface);
  s->o_surface_cap = 0;
  gr_status st =
      gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, n * sizeof(float), NULL, &s->o_surface);
  if (st == GR_OK)
    s->o_surface_cap = n;
  return st;
}

/* The exposure of n faces (or samples) at pos, nrm in the pieces'
 * combined view into s->o_surface: each piece's from its own view, the
 * minimum over the pieces (snow_accumulation_object_exposure). Waits. */
static gr_status gr_snac_object_exposure(gr_snow_accumulation *s, cl_mem pos, cl_mem nrm, cl_int nv,
                                         const gr_snac_view *v, const float dir[3]) {
  gr_status st = gr_snac_point_buffer(s, (size_t)nv);
  if (st != GR_OK)
    return st;
  cl_int vw = v->vw, vh = v->vh;
  const gr_snac_arg a[] = {GR_SNAC_MEM("pos", pos),
                           GR_SNAC_MEM("nrm", nrm),
                           GR_SNAC_VAL("nv", nv),
                           GR_SNAC_VAL("dir_x", dir[0]),
                           GR_SNAC_VAL("dir_y", dir[1]),
                           GR_SNAC_VAL("dir_z", dir[2]),
                           GR_SNAC_VAL("tau_x", v->tau_x),
                           GR_SNAC_VAL("tau_y", v->tau_y),
                           GR_SNAC_VAL("qx0", v->qx0),
                           GR_SNAC_VAL("qy0", v->qy0),
                           GR_SNAC_VAL("inv_texel", v->inv_texel),
                           GR_SNAC_VAL("texel", v->texel),
                           GR_SNAC_VAL("vw", vw),
                           GR_SNAC_VAL("vh", vh),
                           GR_SNAC_MEM("view", s->view),
                           GR_SNAC_MEM("exposure", s->o_surface)};
  st = gr_snac_args(s, s->object_exposure, a, sizeof(a) / sizeof(a[0]));
  if (st == GR_OK)
    st = gr_enqueue_1d(s->ctx, s->object_exposure, (size_t)nv);
  float *f = malloc((size_t)nv * sizeof(float));
  double *d = malloc((size_t)nv * sizeof(double));
  if (st == GR_OK && (!f || !d))
    st = gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  if (st == GR_OK)
    st = gr_buffer_read(s->ctx, s->o_surface, 0, (size_t)nv * sizeof(float), f);
  for (cl_int k = 0; st == GR_OK && k < nv; ++k)
    d[k] = -(double)f[k];
  if (st == GR_OK)
    st = gr_snac_allreduce(s, d, (size_t)nv, GR_REDUCE_MAX);
  for (cl_int k = 0; st == GR_OK && k < nv; ++k)
    f[k] = (float)-d[k];
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, s->o_surface, 0, (size_t)nv * sizeof(float), f);
  free(f), free(d);
  return st;
}

/* The snow surface under n faces (or samples) at pos, nrm into
 * s->o_surface: each piece gives the points over its own cells, the
 * allreduce the rest (snow_accumulation_object_surface). Waits. */
static gr_status gr_snac_object_surface(gr_snow_accumulation *s, cl_mem pos, cl_mem nrm, cl_int nv,
                                        float texel) {
  gr_status st = gr_snac_point_buffer(s, (size_t)nv);
  if (st != GR_OK)
    return st;
  cl_int gnx = s->gnx, gny = s->gny, row0 = s->row0, own_lo = s->row0 + s->ring_s;
  cl_int own_hi = own_lo + s->own_ny - 1;
  float gdx = (float)s->grid.dx, gdy = (float)s->grid.dy, zref = (float)s->zref;
  const gr_snac_arg a[] = {GR_SNAC_MEM("pos", pos),
                           GR_SNAC_MEM("nrm", nrm),
                           GR_SNAC_VAL("nv", nv),
                           GR_SNAC_VAL("texel", texel),
                           GR_SNAC_MEM("ground", s->ground),
                           GR_SNAC_MEM("gdepth", s->arr[0]),
                           GR_SNAC_VAL("gnx", gnx),
                           GR_SNAC_VAL("gny", gny),
                           GR_SNAC_VAL("row0", row0),
                           GR_SNAC_VAL("own_lo", own_lo),
                           GR_SNAC_VAL("own_hi", own_hi),
                           GR_SNAC_VAL("gdx", gdx),
                           GR_SNAC_VAL("gdy", gdy),
                           GR_SNAC_VAL("zref", zref),
                           GR_SNAC_MEM("surface", s->o_surface)};
  st = gr_snac_args(s, s->object_surface, a, sizeof(a) / sizeof(a[0]));
  if (st == GR_OK)
    st = gr_enqueue_1d(s->ctx, s->object_surface, (size_t)nv);
  float *f = malloc((size_t)nv * sizeof(float));
  double *d = malloc((size_t)nv * sizeof(double));
  if (st == GR_OK && (!f || !d))
    st = gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  if (st == GR_OK)
    st = gr_buffer_read(s->ctx, s->o_surface, 0, (size_t)nv * sizeof(float), f);
  for (cl_int k = 0; st == GR_OK && k < nv; ++k)
    d[k] = (double)f[k];
  if (st == GR_OK)
    st = gr_snac_allreduce(s, d, (size_t)nv, GR_REDUCE_MAX);
  for (cl_int k = 0; st == GR_OK && k < nv; ++k)
    f[k] = (float)d[k];
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, s->o_surface, 0, (size_t)nv * sizeof(float), f);
  free(f), free(d);
  return st;
}

static gr_status gr_snac_step_impl(gr_snow_accumulation *s, double dt) {
  gr_context *ctx = s->ctx;
  const gr_grid *g = &s->grid;
  double t0 = gr_snac_now_ms();
  if (s->timing) {
    gr_status st = gr_finish(ctx);
    if (st != GR_OK)
      return st;
    t0 = s->t_mark = gr_snac_now_ms();
  }
  double dd[3];
  gr_snac_direction(s, dd);
  cl_int nx = g->nx, ny = g->ny, gi0 = 0, gj0 = s->row0;
  float dx = (float)g->dx, dy = (float)g->dy;
  int pieced = gr_snac_pieced(s);
  if (pieced && (!s->allreduce || !s->halo_exchange))
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "A snow accumulation piece with neighbours steps only with an allreduce "
                        "and a halo exchange set (gr_snow_accumulation_set_allreduce, "
                        "gr_snow_accumulation_set_halo_exchange).");

  /* The terrain is drawn into the view only where it could hide itself:
   * where a triangle of the snow surface rises faster than the snow falls
   * steeply (snow_accumulation_slope_reduce). Snow straight down, or a
   * surface gentler than the snow's descent, leaves a view of the objects
   * alone, and a far cheaper step. A piece's cells (its local arrays, ring
   * included, are all the domain's) give its share of the maximum. */
  cl_int terrain_drawn = 1;
  double horiz = hypot(dd[0], dd[1]);
  double g2[2] = {0.0, 0.0};
  {
    cl_int cells = nx * ny;
    const gr_snac_arg sa[] = {GR_SNAC_MEM("ground", s->ground),
                              GR_SNAC_MEM("depth", s->arr[0]),
                              GR_SNAC_VAL("nx", nx),
                              GR_SNAC_VAL("ny", ny),
                              GR_SNAC_VAL("dx", dx),
                              GR_SNAC_VAL("dy", dy),
                              GR_SNAC_VAL("n", cells)};
    /* Snow straight down cannot be hidden by the surface: no reduction
     * (and no read-back) that step. */
    gr_status sst =
        horiz == 0.0 ? GR_OK : gr_snac_args(s, s->slope_k, sa, sizeof(sa) / sizeof(sa[0]));
    if (sst == GR_OK && horiz > 0.0)
      sst = gr_reduction_run(ctx, &s->red_slope, s->slope_k, NULL, g2);
    if (sst != GR_OK)
      return sst;
  }
  if (pieced) {
    /* What the view's box and the drawing decision rest on, over the
     * domain: every piece then sets up the same view as the whole grid. */
    double m[6] = {g2[0], g2[1], -s->bmin, s->bmax, s->init_max, s->snow_bound};
    gr_status rst = gr_snac_allreduce(s, m, 6, GR_REDUCE_MAX);
    if (rst != GR_OK)
      return rst;
    g2[0] = m[0], g2[1] = m[1];
    s->bmin = -m[2], s->bmax = m[3], s->init_max = m[4], s->snow_bound = m[5];
    if (s->zref != s->bmin) {
      s->zref = s->bmin;
      rst = gr_snac_upload_geometry(s);
      if (rst != GR_OK)
        return rst;
    }
  }
  double steepest = sqrt(g2[0] * g2[0] + g2[1] * g2[1]);
  if (horiz == 0.0 || steepest * (1.0 + GR_SNAC_SLOPE_MARGIN) * horiz < fabs(dd[2]))
    terrain_drawn = 0;
  gr_snac_view v;
  gr_snac_view_of(s, dd, &v);
  cl_int vw = v.vw, vh = v.vh;
  float zref = (float)s->zref;
  float dir_x = (float)dd[0], dir_y = (float)dd[1], dir_z = (float)dd[2];
  const gr_snow_accumulation_params *p = &s->params;
  float rate_dt = (float)(p->snowfall_rate * dt), amplitude = (float)p->noise_amplitude;
  float max_depth = (float)p->max_depth;
  /* Stability as a relaxation rate: k = -ln(1 - f), so that an excess
   * alone keeps (1 - f)^t after t seconds; the step integrates it with the
   * growth (snac_settle) from keep = e^-k dt and k dt. f = 1: k infinite
   * (kdt 1e30), all the excess goes. */
  double krate = p->stability_factor >= 1.0 ? HUGE_VAL : -log1p(-p->stability_factor);
  float kdt = (float)fmin(krate * dt, 1.0e30);
  float keep = (float)exp(-krate * dt);
  cl_uint seed = (cl_uint)p->seed;
  double inv_scale = 1.0 / p->noise_scale;
  float noise_x0 = (float)fmod(g->x0 * inv_scale, GR_SNAC_NOISE_PERIOD);
  float noise_y0 = (float)fmod(g->y0 * inv_scale, GR_SNAC_NOISE_PERIOD);
  float noise_dx = (float)(g->dx * inv_scale), noise_dy = (float)(g->dy * inv_scale);
  /* The noise is fixed in space: made again only for another seed or
   * scale. */
  gr_status nst = GR_OK;
  if (!s->noise_made || s->noise_seed != seed || s->noise_key[0] != noise_x0 ||
      s->noise_key[1] != noise_y0 || s->noise_key[2] != noise_dx || s->noise_key[3] != noise_dy) {
    const gr_snac_arg na[] = {GR_SNAC_VAL("nx", nx),
                              GR_SNAC_VAL("ny", ny),
                              GR_SNAC_VAL("gi0", gi0),
                              GR_SNAC_VAL("gj0", gj0),
                              GR_SNAC_VAL("noise_x0", noise_x0),
                              GR_SNAC_VAL("noise_y0", noise_y0),
                              GR_SNAC_VAL("noise_dx", noise_dx),
                              GR_SNAC_VAL("noise_dy", noise_dy),
                              GR_SNAC_VAL("seed", seed),
                              GR_SNAC_MEM("noise", s->noise)};
    nst = gr_snac_args(s, s->noise_k, na, sizeof(na) / sizeof(na[0]));
    if (nst == GR_OK)
      nst = gr_enqueue_2d(ctx, s->noise_k, 0, 0, (size_t)nx, (size_t)ny, NULL);
    if (nst == GR_OK) {
      s->noise_made = 1;
      s->noise_seed = seed;
      s->noise_key[0] = noise_x0, s->noise_key[1] = noise_y0;
      s->noise_key[2] = noise_dx, s->noise_key[3] = noise_dy;
    }
  }
  if (s->timing)
    s->tm.host_ms += gr_snac_now_ms() - t0, s->t_mark = gr_snac_now_ms();
  if (nst != GR_OK)
    return nst;

  /* 1. the view */
  cl_int empty = GR_SNAC_EMPTY;
  gr_status st =
      gr_cl_check(ctx,
                  clEnqueueFillBuffer(gr_context_queue(ctx), s->view, &empty, sizeof(empty), 0,
                                      (size_t)vw * (size_t)vh * sizeof(cl_int), 0, NULL, NULL),
                  "Clearing the exposure view");
  const gr_snac_arg rt[] = {GR_SNAC_MEM("ground", s->ground),
                            GR_SNAC_MEM("depth", s->arr[0]),
                            GR_SNAC_VAL("nx", nx),
                            GR_SNAC_VAL("ny", ny),
                            GR_SNAC_VAL("gi0", gi0),
                            GR_SNAC_VAL("gj0", gj0),
                            GR_SNAC_VAL("dx", dx),
                            GR_SNAC_VAL("dy", dy),
                            GR_SNAC_VAL("zref", zref),
                            GR_SNAC_VAL("tau_x", v.tau_x),
                            GR_SNAC_VAL("tau_y", v.tau_y),
                            GR_SNAC_VAL("qx0", v.qx0),
                            GR_SNAC_VAL("qy0", v.qy0),
                            GR_SNAC_VAL("inv_texel", v.inv_texel),
                            GR_SNAC_VAL("vw", vw),
                            GR_SNAC_VAL("vh", vh),
                            GR_SNAC_MEM("view", s->view)};
  if (st == GR_OK)
    st = gr_snac_args(s, s->raster_terrain, rt, sizeof(rt) / sizeof(rt[0]));
  if (st == GR_OK && nx > 1 && ny > 1 && terrain_drawn)
    st = gr_enqueue_2d(ctx, s->raster_terrain, 0, 0, (size_t)(nx - 1), (size_t)(ny - 1), NULL);
  cl_int ntri = s->ntri;
  if (st == GR_OK && ntri > 0) {
    const gr_snac_arg ro[] = {GR_SNAC_MEM("tri", s->o_tri),
                              GR_SNAC_VAL("ntri", ntri),
                              GR_SNAC_VAL("tau_x", v.tau_x),
                              GR_SNAC_VAL("tau_y", v.tau_y),
                              GR_SNAC_VAL("qx0", v.qx0),
                              GR_SNAC_VAL("qy0", v.qy0),
                              GR_SNAC_VAL("inv_texel", v.inv_texel),
                              GR_SNAC_VAL("vw", vw),
                              GR_SNAC_VAL("vh", vh),
                              GR_SNAC_MEM("view", s->view)};
    st = gr_snac_args(s, s->raster_objects, ro, sizeof(ro) / sizeof(ro[0]));
    if (st == GR_OK)
      st = gr_enqueue_1d(ctx, s->raster_objects, (size_t)ntri);
  }
  /* A piece drew its own cells: the views' maximum over the pieces, texel
   * by texel, is the whole grid's view (see "Pieces" in the header). */
  s->objects_by_point = 0;
  if (st == GR_OK && pieced && terrain_drawn)
    st = gr_snac_view_reduce(s, &v);
  if (st == GR_OK)
    st = gr_snac_mark(s, &s->tm.view_ms);

  /* 2-3. exposure and growth of the grid points */
  const gr_snac_arg ex[] = {GR_SNAC_MEM("ground", s->ground),
                            GR_SNAC_MEM("depth", s->arr[0]),
                            GR_SNAC_VAL("nx", nx),
                            GR_SNAC_VAL("ny", ny),
                            GR_SNAC_VAL("gi0", gi0),
                            GR_SNAC_VAL("gj0", gj0),
                            GR_SNAC_VAL("dx", dx),
                            GR_SNAC_VAL("dy", dy),
                            GR_SNAC_VAL("zref", zref),
                            GR_SNAC_VAL("dir_x", dir_x),
                            GR_SNAC_VAL("dir_y", dir_y),
                            GR_SNAC_VAL("dir_z", dir_z),
                            GR_SNAC_VAL("tau_x", v.tau_x),
                            GR_SNAC_VAL("tau_y", v.tau_y),
                            GR_SNAC_VAL("qx0", v.qx0),
                            GR_SNAC_VAL("qy0", v.qy0),
                            GR_SNAC_VAL("inv_texel", v.inv_texel),
                            GR_SNAC_VAL("texel", v.texel),
                            GR_SNAC_VAL("vw", vw),
                            GR_SNAC_VAL("vh", vh),
                            GR_SNAC_MEM("view", s->view),
                            GR_SNAC_VAL("rate_dt", rate_dt),
                            GR_SNAC_VAL("amplitude", amplitude),
                            GR_SNAC_MEM("noise", s->noise),
                            GR_SNAC_MEM("exposure", s->arr[6]),
                            GR_SNAC_MEM("growth", s->growth)};
  if (st == GR_OK)
    st = gr_snac_args(s, s->exposure_k, ex, sizeof(ex) / sizeof(ex[0]));
  if (st == GR_OK)
    st = gr_enqueue_2d(ctx, s->exposure_k, 0, 0, (size_t)nx, (size_t)ny, NULL);
  if (st == GR_OK)
    st = gr_snac_mark(s, &s->tm.exposure_ms);

  /* 4. blur and dilation, between growth and scratch */
  cl_mem cur = s->growth, other = s->scratch;
  cl_int radius = p->blur_radius;
  for (cl_int axis = 0; st == GR_OK && radius > 0 && axis < 2; ++axis) {
    const gr_snac_arg bl[] = {GR_SNAC_MEM("in", cur),    GR_SNAC_VAL("nx", nx),
                              GR_SNAC_VAL("ny", ny),     GR_SNAC_VAL("radius", radius),
                              GR_SNAC_VAL("axis", axis), GR_SNAC_MEM("w", s->weights),
                              GR_SNAC_MEM("out", other)};
    st = gr_snac_args(s, s->blur, bl, sizeof(bl) / sizeof(bl[0]));
    if (st == GR_OK)
      st = gr_enqueue_2d(ctx, s->blur, 0, 0, (size_t)nx, (size_t)ny, NULL);
    cl_mem t = cur;
    cur = other, other = t;
  }
  if (st == GR_OK && p->dilation) {
    const gr_snac_arg dl[] = {GR_SNAC_MEM("in", cur), GR_SNAC_VAL("nx", nx), GR_SNAC_VAL("ny", ny),
                              GR_SNAC_MEM("out", other)};
    st = gr_snac_args(s, s->dilate, dl, sizeof(dl) / sizeof(dl[0]));
    if (st == GR_OK)
      st = gr_enqueue_2d(ctx, s->dilate, 0, 0, (size_t)nx, (size_t)ny, NULL);
    cl_mem t = cur;
    cur = other, other = t;
  }
  if (st == GR_OK)
    st = gr_snac_mark(s, &s->tm.blur_ms);

  /* 5. increment and stability */
  const gr_snac_arg ap[] = {GR_SNAC_MEM("ground", s->ground),
                            GR_SNAC_VAL("nx", nx),
                            GR_SNAC_VAL("ny", ny),
                            GR_SNAC_VAL("dx", dx),
                            GR_SNAC_VAL("dy", dy),
                            GR_SNAC_MEM("growth", cur),
                            GR_SNAC_VAL("max_depth", max_depth),
                            GR_SNAC_VAL("keep", keep),
                            GR_SNAC_VAL("kdt", kdt),
                            GR_SNAC_MEM("depth", s->arr[0]),
                            GR_SNAC_MEM("depth_lo", s->arr[1]),
                            GR_SNAC_MEM("fall", s->arr[2]),
                            GR_SNAC_MEM("fall_lo", s->arr[3]),
                            GR_SNAC_MEM("shed", s->arr[4]),
                            GR_SNAC_MEM("shed_lo", s->arr[5])};
  if (st == GR_OK)
    st = gr_snac_args(s, s->apply, ap, sizeof(ap) / sizeof(ap[0]));
  if (st == GR_OK)
    st = gr_enqueue_2d(ctx, s->apply, 0, 0, (size_t)nx, (size_t)ny, NULL);
  if (st == GR_OK)
    st = gr_snac_mark(s, &s->tm.apply_ms);
  /* A piece's ring: the snow depth the next step's normals, blur and view
   * (and this step's objects) read beyond its own rows. */
  if (st == GR_OK && pieced) {
    st = s->halo_exchange(s->halo_user);
    if (st != GR_OK)
      st = gr_set_error(ctx, st,
                        "The snow accumulation piece's halo exchange (the callback given to "
                        "gr_snow_accumulation_set_halo_exchange) failed in step %lld with %s; the "
                        "piece's ring is not fresh, so restore a checkpoint before stepping on.",
                        s->steps + 1, gr_status_string(st));
  }

  /* the objects' faces (their centroids), then the accumulation textures'
   * samples: the same exposure, growth and stability, on their own arrays */
  for (int pass = 0; pass < 2; ++pass) {
    cl_int nv = pass ? s->ns : s->ntri;
    if (st != GR_OK || nv == 0)
      continue;
    const cl_mem *A = pass ? s->t_arr : s->o_arr;
    const cl_mem *P = pass ? &s->t_pos : &s->o_pos, *N = pass ? &s->t_nrm : &s->o_nrm,
                 *L = pass ? &s->t_local : &s->o_local;
    const gr_snac_arg ob[] = {GR_SNAC_MEM("pos", *P),
                              GR_SNAC_MEM("nrm", *N),
                              GR_SNAC_MEM("lattice", *L),
                              GR_SNAC_VAL("nv", nv),
                              GR_SNAC_VAL("dir_x", dir_x),
                              GR_SNAC_VAL("dir_y", dir_y),
                              GR_SNAC_VAL("dir_z", dir_z),
                              GR_SNAC_VAL("tau_x", v.tau_x),
                              GR_SNAC_VAL("tau_y", v.tau_y),
                              GR_SNAC_VAL("qx0", v.qx0),
                              GR_SNAC_VAL("qy0", v.qy0),
                              GR_SNAC_VAL("inv_texel", v.inv_texel),
                              GR_SNAC_VAL("texel", v.texel),
                              GR_SNAC_VAL("vw", vw),
                              GR_SNAC_VAL("vh", vh),
                              GR_SNAC_MEM("view", s->view),
                              GR_SNAC_VAL("rate_dt", rate_dt),
                              GR_SNAC_VAL("amplitude", amplitude),
                              GR_SNAC_VAL("seed", seed),
                              GR_SNAC_VAL("max_depth", max_depth),
                              GR_SNAC_VAL("keep", keep),
                              GR_SNAC_VAL("kdt", kdt),
                              GR_SNAC_VAL("terrain_drawn", terrain_drawn),
                              GR_SNAC_MEM("ground", s->ground),
                              GR_SNAC_MEM("gdepth", s->arr[0]),
                              GR_SNAC_VAL("gnx", nx),
                              GR_SNAC_VAL("gny", ny),
                              GR_SNAC_VAL("gdx", dx),
                              GR_SNAC_VAL("gdy", dy),
                              GR_SNAC_VAL("zref", zref),
                              GR_SNAC_MEM("exposure", A[6]),
                              GR_SNAC_MEM("depth", A[0]),
                              GR_SNAC_MEM("depth_lo", A[1]),
                              GR_SNAC_MEM("fall", A[2]),
                              GR_SNAC_MEM("fall_lo", A[3]),
                              GR_SNAC_MEM("shed", A[4]),
                              GR_SNAC_MEM("shed_lo", A[5])};
    /* On a piece, the surface under the points when the objects kernel
     * needs it (no terrain in the view) comes from the pieces that hold
     * it. */
    cl_int have_surface = pieced && !terrain_drawn;
    cl_int have_exposure = pieced && terrain_drawn && s->objects_by_point;
    if (have_surface)
      st = gr_snac_object_surface(s, *P, *N, nv, v.texel);
    if (have_exposure) {
      const float dir[3] = {dir_x, dir_y, dir_z};
      st = gr_snac_object_exposure(s, *P, *N, nv, &v, dir);
    }
    cl_mem surf = have_surface || have_exposure ? s->o_surface : s->ground;
    const gr_snac_arg ob2[] = {GR_SNAC_VAL("have_surface", have_surface),
                               GR_SNAC_VAL("have_exposure", have_exposure),
                               GR_SNAC_MEM("surface", surf)};
    if (st == GR_OK)
      st = gr_snac_args(s, s->objects_k, ob, sizeof(ob) / sizeof(ob[0]));
    if (st == GR_OK)
      st = gr_snac_args(s, s->objects_k, ob2, sizeof(ob2) / sizeof(ob2[0]));
    if (st == GR_OK)
      st = gr_enqueue_1d(ctx, s->objects_k, (size_t)nv);
    if (st == GR_OK)
      st = gr_snac_mark(s, &s->tm.objects_ms);
  }
  if (st == GR_OK && s->timing)
    s->tm.steps++;
  if (st == GR_OK && (s->steps + 1) % GR_SNAC_SYNC_EVERY == 0)
    st = gr_finish(ctx);
  return st;
}

gr_status gr_snow_accumulation_step(gr_snow_accumulation *s, double dt) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_step needs a simulation.");
  if (!(dt >= GR_SNAC_MIN_DT && dt <= GR_SNAC_MAX_DT))
    return GR_SNAC_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow accumulation time step must lie between 1e-6 and 86400 s (got "
                        "%g s).",
                        dt));
  if (s->aborted)
    return GR_SNAC_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_ABORTED,
                        "The snow accumulation was stopped by its progress callback; set the "
                        "callback again or reset to go on."));
  gr_status st = gr_snac_step_impl(s, dt);
  if (st != GR_OK)
    return GR_SNAC_KEEP_ERROR(s, st);
  s->time += dt;
  s->steps++;
  /* The view's z range: snow never stands above this (it only grows by the
   * fall, and with StabilityFactor 1 never above the larger of MaxDepth and
   * the initial snow). */
  double grow = s->params.snowfall_rate * (1.0 + s->params.noise_amplitude) * dt;
  s->snow_bound += grow;
  if (s->params.stability_factor >= 1.0)
    s->snow_bound = fmin(s->snow_bound, fmax(s->params.max_depth, s->init_max) + grow);
  if (s->progress && s->progress(s->progress_user, s->time) != 0)
    s->aborted = 1;
  /* A stop asked on any piece stops every piece after this step. */
  if (gr_snac_pieced(s)) {
    double flag = s->aborted ? 1.0 : 0.0;
    st = gr_snac_allreduce(s, &flag, 1, GR_REDUCE_MAX);
    if (st != GR_OK)
      return GR_SNAC_KEEP_ERROR(s, st);
    s->aborted = flag != 0.0;
  }
  return GR_OK;
}

gr_status gr_snow_accumulation_get_field(gr_snow_accumulation *s, gr_field f, float *host) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_get_field needs a simulation.");
  if (!host)
    return GR_SNAC_KEEP_ERROR(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                              "gr_snow_accumulation_get_field needs a place for "
                                              "the values (got NULL)."));
  /* The own rows (a piece's local arrays hold its rings around them). */
  size_t cells = gr_snac_cells(s), own = (size_t)s->grid.nx * (size_t)s->own_ny;
  size_t offset = (size_t)s->ring_s * (size_t)s->grid.nx * sizeof(float);
  cl_mem src = NULL;
  gr_status st = GR_OK;
  switch (f) {
  case GR_FIELD_SNOW_DEPTH:
    src = s->arr[0];
    break;
  case GR_FIELD_EXPOSURE:
    src = s->arr[6];
    break;
  case GR_FIELD_ELEVATION:
    src = s->ground;
    break;
  case GR_FIELD_SNOW_DENSITY:
    for (size_t c = 0; c < own; ++c)
      host[c] = (float)s->params.snow_density;
    return GR_OK;
  case GR_FIELD_SNOW_SURFACE: {
    cl_int n = (cl_int)cells;
    const gr_snac_arg sa[] = {GR_SNAC_MEM("ground", s->ground), GR_SNAC_MEM("depth", s->arr[0]),
                              GR_SNAC_VAL("n", n), GR_SNAC_MEM("out", s->scratch)};
    st = gr_snac_args(s, s->surface, sa, sizeof(sa) / sizeof(sa[0]));
    if (st == GR_OK)
      st = gr_enqueue_1d(s->ctx, s->surface, cells);
    src = s->scratch;
    break;
  }
  default: {
    const char *name = gr_field_name(f);
    return GR_SNAC_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow accumulation simulation has no output field '%s'; it gives "
                        "snow_depth, snow_surface, snow_density, exposure and elevation.",
                        name ? name : "(unknown field)"));
  }
  }
  if (st == GR_OK)
    st = gr_buffer_read(s->ctx, src, offset, own * sizeof(float), host);
  return st == GR_OK ? GR_OK : GR_SNAC_KEEP_ERROR(s, st);
}

gr_status gr_snow_accumulation_ledger_get(gr_snow_accumulation *s,
                                          gr_snow_accumulation_ledger *out) {
  if (!s || !out)
    return s ? GR_SNAC_KEEP_ERROR(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                                  "gr_snow_accumulation_ledger_get needs a place "
                                                  "for the ledger."))
             : gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                            "gr_snow_accumulation_ledger_get needs a simulation.");
  /* The grid's sums over the domain's rows in order (collective on a
   * piece); the objects' are the same on every piece and count once. */
  double gs[4], os[GR_SNAC_SUMS];
  gr_status st = gr_snac_grid_sums(s, gs);
  if (st == GR_OK)
    st = gr_snac_sums(s, 1, 0, s->ntri, os);
  if (st != GR_OK)
    return GR_SNAC_KEEP_ERROR(s, st);
  double a = s->grid.dx * s->grid.dy;
  memset(out, 0, sizeof(*out));
  out->time = s->time;
  out->steps = s->steps;
  out->initial_volume = gs[3] * a + s->initial_objects;
  out->stored_volume_terrain = gs[0] * a;
  out->stored_volume_objects = os[0];
  out->stored_volume = out->stored_volume_terrain + out->stored_volume_objects;
  out->snowfall_volume = gs[1] * a + os[1] + s->retired_fall;
  out->shed_volume = gs[2] * a + os[2] + s->retired_shed;
  out->dropped_volume = s->dropped;
  out->balance_error = out->initial_volume + out->snowfall_volume - out->shed_volume -
                       out->dropped_volume - out->stored_volume;
  return GR_OK;
}

void gr_snow_accumulation_set_progress(gr_snow_accumulation *s, gr_progress_fn fn, void *user) {
  if (!s)
    return;
  s->progress = fn;
  s->progress_user = user;
  s->aborted = 0;
}

/* ---------------------------------------------------------- checkpoints */

typedef struct gr_snac_state_header {
  uint32_t magic, version;
  int32_t nx, ny, nobjects, nv, ns, j0, ntri, pad;
  int64_t steps;
  double time, initial_objects, retired_fall, retired_shed, dropped, snow_bound;
} gr_snac_state_header;

static size_t gr_snac_state_bytes(const gr_snow_accumulation *s) {
  return sizeof(gr_snac_state_header) +
         GR_SNAC_ARRAYS * (gr_snac_cells(s) + (size_t)s->ntri + (size_t)s->ns) * sizeof(float) +
         (size_t)s->own_ny * sizeof(double);
}

gr_status gr_snow_accumulation_state_size(const gr_snow_accumulation *s, size_t *bytes) {
  if (!s || !bytes)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_state_size needs a simulation and a place for the "
                        "size.");
  *bytes = gr_snac_state_bytes(s);
  return GR_OK;
}

gr_status gr_snow_accumulation_state_save(gr_snow_accumulation *s, void *host, size_t bytes) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_state_save needs a simulation.");
  size_t need = gr_snac_state_bytes(s);
  if (!host || bytes != need)
    return GR_SNAC_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The buffer for the snow accumulation state has %zu bytes but this "
                        "simulation's state has %zu: size it with "
                        "gr_snow_accumulation_state_size.",
                        host ? bytes : 0, need));
  gr_snac_state_header hd;
  memset(&hd, 0, sizeof(hd));
  hd.magic = GR_SNAC_STATE_MAGIC;
  hd.version = GR_SNAC_STATE_VERSION;
  hd.nx = s->grid.nx, hd.ny = s->grid.ny, hd.nobjects = s->nobjects, hd.nv = s->nv;
  hd.ns = s->ns;
  hd.j0 = s->grid.j0;
  hd.ntri = s->ntri;
  hd.steps = s->steps;
  hd.time = s->time;
  hd.initial_objects = s->initial_objects;
  hd.retired_fall = s->retired_fall;
  hd.retired_shed = s->retired_shed;
  hd.dropped = s->dropped;
  hd.snow_bound = s->snow_bound;
  memcpy(host, &hd, sizeof(hd));
  char *at = (char *)host + sizeof(hd);
  size_t gb = gr_snac_cells(s) * sizeof(float), ob = (size_t)s->ntri * sizeof(float);
  size_t tb = (size_t)s->ns * sizeof(float);
  gr_status st = GR_OK;
  for (int a = 0; st == GR_OK && a < GR_SNAC_ARRAYS; ++a, at += gb)
    st = gr_buffer_read(s->ctx, s->arr[a], 0, gb, at);
  /* Per array the faces, then the textures' samples. */
  for (int a = 0; st == GR_OK && ob + tb > 0 && a < GR_SNAC_ARRAYS; ++a, at += ob + tb) {
    if (ob > 0)
      st = gr_buffer_read(s->ctx, s->o_arr[a], 0, ob, at);
    if (st == GR_OK && tb > 0)
      st = gr_buffer_read(s->ctx, s->t_arr[a], 0, tb, at + ob);
  }
  /* The initial snow per own row, last. */
  if (st == GR_OK)
    memcpy(at, s->init_rows, (size_t)s->own_ny * sizeof(double));
  return st == GR_OK ? GR_OK : GR_SNAC_KEEP_ERROR(s, st);
}

gr_status gr_snow_accumulation_state_load(gr_snow_accumulation *s, const void *host, size_t bytes) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_state_load needs a simulation.");
  size_t need = gr_snac_state_bytes(s);
  gr_snac_state_header hd;
  if (!host || bytes != need)
    return GR_SNAC_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow accumulation state has %zu bytes but this simulation (%d x %d "
                        "points, %d mesh points) needs %zu: load a state saved with the same grid "
                        "and objects.",
                        host ? bytes : 0, s->grid.nx, s->grid.ny, s->nv, need));
  memcpy(&hd, host, sizeof(hd));
  if (hd.magic != GR_SNAC_STATE_MAGIC || hd.version != GR_SNAC_STATE_VERSION ||
      hd.nx != s->grid.nx || hd.ny != s->grid.ny || hd.nobjects != s->nobjects || hd.nv != s->nv ||
      hd.ns != s->ns || hd.j0 != s->grid.j0 || hd.ntri != s->ntri)
    return GR_SNAC_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_FORMAT,
                        "The bytes are not a snow accumulation state of a %d x %d grid (a piece "
                        "from row %d) with %d objects (version %u); load one saved by "
                        "gr_snow_accumulation_state_save on the same piece with the same objects "
                        "set.",
                        s->grid.nx, s->grid.ny, s->grid.j0, s->nobjects, GR_SNAC_STATE_VERSION));
  const char *base = (const char *)host + sizeof(hd);
  size_t gcells = gr_snac_cells(s), gb = gcells * sizeof(float),
         ob = (size_t)s->ntri * sizeof(float);
  size_t tb = (size_t)s->ns * sizeof(float);
  /* Depths (the hi parts) must be finite and not negative. */
  for (int part = 0; part < 2; ++part) {
    const char *p = part ? base + GR_SNAC_ARRAYS * gb : base;
    size_t n = part ? (size_t)s->ntri + (size_t)s->ns : gcells;
    for (size_t c = 0; c < n; ++c) {
      float v;
      memcpy(&v, p + c * sizeof(float), sizeof(v));
      if (!isfinite(v) || v < -1e-6f)
        return GR_SNAC_KEEP_ERROR(
            s, gr_set_error(s->ctx, GR_ERR_FORMAT,
                            "The snow accumulation state holds a snow depth of %g: it is "
                            "damaged; load an intact one.",
                            (double)v));
    }
  }
  gr_status st = GR_OK;
  const char *at = base;
  for (int a = 0; st == GR_OK && a < GR_SNAC_ARRAYS; ++a, at += gb)
    st = gr_buffer_write(s->ctx, s->arr[a], 0, gb, at);
  for (int a = 0; st == GR_OK && ob + tb > 0 && a < GR_SNAC_ARRAYS; ++a, at += ob + tb) {
    if (ob > 0)
      st = gr_buffer_write(s->ctx, s->o_arr[a], 0, ob, at);
    if (st == GR_OK && tb > 0)
      st = gr_buffer_write(s->ctx, s->t_arr[a], 0, tb, at + ob);
  }
  if (st != GR_OK)
    return GR_SNAC_KEEP_ERROR(s, st);
  memcpy(s->init_rows, at, (size_t)s->own_ny * sizeof(double));
  s->steps = hd.steps;
  s->time = hd.time;
  s->initial_objects = hd.initial_objects;
  s->retired_fall = hd.retired_fall;
  s->retired_shed = hd.retired_shed;
  s->dropped = hd.dropped;
  s->snow_bound = hd.snow_bound;
  s->aborted = 0;
  return GR_OK;
}

gr_status gr_snow_accumulation_reset(gr_snow_accumulation *s) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_reset needs a simulation.");
  gr_status st = gr_snac_initial_state(s);
  return st == GR_OK ? GR_OK : GR_SNAC_KEEP_ERROR(s, st);
}
