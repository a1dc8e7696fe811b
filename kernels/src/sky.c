/* The sky core (seed 001): lightning bolts on the host, the cloud cover's
 * host side of sky.cl. The models are documented in graupel/sky.h. */
#include "graupel/sky.h"
#include "graupel/cl_runtime.h"
#include "sky_shared.h"
#include "runtime_internal.h"

#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define GR_SKY_PI 3.14159265358979323846

/* Lattice coordinates must stay well inside int range in every octave. */
#define GR_SKY_LATTICE_LIMIT 1.0e9

/* ------------------------------------------------------------ the table */

enum {
  GR_SKY_CONTROL_POINTS,
  GR_SKY_STRANDS,
  GR_SKY_JITTER,
  GR_SKY_SEED,
  GR_SKY_FLICKER_RATE,
  GR_SKY_COVER,
  GR_SKY_SCALE,
  GR_SKY_SHARPNESS,
  GR_SKY_WIND_SPEED,
  GR_SKY_WIND_DIRECTION,
  GR_SKY_RESOLUTION,
  GR_SKY_SIZE,
  GR_SKY_ROWS
};

/* The one place the ranges are written. ControlPoints: the seed's 50; its
 * open min 1 (at least 2, a line needs two ends) and Resolution's open min
 * 0 leave a too-small value to the validator's sentence rather than to a
 * silent clamp. Jitter 0.1: a lateral spread of 5 % of the bolt's length at
 * its middle, jagged but clearly one stroke (seed 001 gives no value,
 * notes C). Sharpness 0.96: inside Elias's 0.95 .. 0.99. Scale 2 km and
 * Size 20 km: cumulus-sized cells over a valley-wide sky. WindSpeed 10 m/s
 * towards the east: a fresh breeze at cloud height. */
static const gr_param_bound gr_sky_bounds[GR_SKY_ROWS] = {
    {"ControlPoints", "", 1.0, 10000.0, 50.0, 1.0, 1, 1},
    {"Strands", "", 0.0, 100.0, 4.0, 1.0, 0, 1},
    {"Jitter", "", 0.0, 1.0, 0.1, 1.0, 0, 0},
    {"Seed", "", (double)INT_MIN, (double)INT_MAX, 0.0, 1.0, 0, 1},
    {"FlickerRate", "1/s", 0.0, 100.0, 0.0, 1.0, 0, 0},
    {"Cover", "", 0.0, 1.0, 0.5, 1.0, 0, 0},
    {"Scale", "m", 0.0, 1e7, 2000.0, 1.0, 1, 0},
    {"Sharpness", "", 0.5, 0.999, 0.96, 1.0, 0, 0},
    {"WindSpeed", "m/s", 0.0, 100.0, 10.0, 1.0, 0, 0},
    {"WindDirection", "deg", 0.0, 360.0, 90.0, 1.0, 0, 0},
    {"Resolution", "", 0.0, 16384.0, 512.0, 1.0, 1, 1},
    {"Size", "m", 0.0, 1e7, 20000.0, 1.0, 1, 0},
};

static const char *const gr_sky_hints[GR_SKY_ROWS] = {
    [GR_SKY_CONTROL_POINTS] = " (points of the main strand)",
    [GR_SKY_STRANDS] = " (branches)",
    [GR_SKY_JITTER] = " (lateral displacement relative to the bolt's length)",
    [GR_SKY_FLICKER_RATE] = " (reshapes per second)",
    [GR_SKY_COVER] = " (the fraction of the sky clouded)",
    [GR_SKY_SCALE] = " (the clouds' wavelength)",
    [GR_SKY_WIND_DIRECTION] = " (the bearing the clouds move towards)",
    [GR_SKY_RESOLUTION] = " (pixels per side)",
    [GR_SKY_SIZE] = " (the image's width)",
};

const gr_param_bound *gr_sky_param_bounds(int *count) {
  if (count)
    *count = GR_SKY_ROWS;
  return gr_sky_bounds;
}

/* ------------------------------------------------------------ lightning */

void gr_lightning_params_init(gr_lightning_params *p) {
  if (!p)
    return;
  memset(p, 0, sizeof(*p));
  p->control_points = (int)gr_sky_bounds[GR_SKY_CONTROL_POINTS].default_value;
  p->strands = (int)gr_sky_bounds[GR_SKY_STRANDS].default_value;
  p->jitter = gr_sky_bounds[GR_SKY_JITTER].default_value;
  p->seed = (int)gr_sky_bounds[GR_SKY_SEED].default_value;
  p->flicker_rate = gr_sky_bounds[GR_SKY_FLICKER_RATE].default_value;
  p->start[2] = 1000.0;
}

gr_status gr_lightning_params_validate(const gr_lightning_params *p, char *msg, size_t msg_len) {
  const char *what = "Invalid lightning parameters";
  if (!p)
    return gr_params_missing(what, msg, msg_len);
  const int rows[] = {GR_SKY_CONTROL_POINTS, GR_SKY_STRANDS, GR_SKY_JITTER, GR_SKY_SEED,
                      GR_SKY_FLICKER_RATE};
  const double values[] = {p->control_points, p->strands, p->jitter, p->seed, p->flicker_rate};
  if (gr_params_check_table(gr_sky_bounds, rows, 5, values, what, gr_sky_hints,
                            GR_PARAM_SAY_IS_WHOLE_FIRST, msg, msg_len) != GR_OK)
    return GR_ERR_INVALID_ARGUMENT;
  if (!isfinite(p->time)) {
    if (msg && msg_len)
      snprintf(msg, msg_len, "Invalid lightning parameters: the time is %g s but must be finite.",
               p->time);
    return GR_ERR_INVALID_ARGUMENT;
  }
  double len2 = 0.0;
  for (int c = 0; c < 3; ++c) {
    if (!isfinite(p->start[c]) || !isfinite(p->end[c])) {
      if (msg && msg_len)
        snprintf(msg, msg_len,
                 "Invalid lightning parameters: Start (%g, %g, %g) and End (%g, %g, %g) must be "
                 "finite points in metres.",
                 p->start[0], p->start[1], p->start[2], p->end[0], p->end[1], p->end[2]);
      return GR_ERR_INVALID_ARGUMENT;
    }
    double d = p->end[c] - p->start[c];
    len2 += d * d;
  }
  if (!(len2 > 0.0)) {
    if (msg && msg_len)
      snprintf(msg, msg_len,
               "Invalid lightning parameters: Start and End are the same point (%g, %g, %g); "
               "put the Start in the sky above the End.",
               p->start[0], p->start[1], p->start[2]);
    return GR_ERR_INVALID_ARGUMENT;
  }
  return GR_OK;
}

int gr_lightning_shape(const gr_lightning_params *p) {
  if (!p)
    return 0;
  double k = floor(p->time * p->flicker_rate);
  double shape = (double)p->variant + (isfinite(k) ? k : 0.0);
  return shape >= (double)INT_MAX ? INT_MAX : shape <= (double)INT_MIN ? INT_MIN : (int)shape;
}

int gr_lightning_branch_points(int control_points) {
  return control_points / 2 > 2 ? control_points / 2 : 2;
}

long gr_lightning_point_count(const gr_lightning_params *p) {
  if (gr_lightning_params_validate(p, NULL, 0) != GR_OK)
    return 0;
  return (long)p->control_points + (long)p->strands * gr_lightning_branch_points(p->control_points);
}

/* The random numbers: hashes of (seed, shape, strand, point, purpose), so
 * every number is a pure function of where it is used. */
enum { GR_LH_WALK_X, GR_LH_WALK_Y, GR_LH_ATTACH, GR_LH_ANGLE, GR_LH_AZIMUTH, GR_LH_LENGTH };

static uint64_t gr_mix64(uint64_t z) {
  /* splitmix64's finaliser: full avalanche. */
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

static uint64_t gr_lhash(int seed, int variant, long strand, long k, int purpose) {
  uint64_t h = gr_mix64((uint64_t)(uint32_t)seed);
  h = gr_mix64(h ^ ((uint64_t)(uint32_t)variant << 1));
  h = gr_mix64(h ^ (((uint64_t)(uint32_t)strand << 32) | (uint64_t)(uint32_t)k));
  return gr_mix64(h ^ (uint64_t)purpose);
}

/* Uniform in [0, 1). */
static double gr_unit(uint64_t h) {
  return (double)(h >> 11) * (1.0 / 9007199254740992.0);
}

/* A standard normal pair (Box-Muller) for point k of a strand. */
static void gr_gauss2(int seed, int shape, long strand, long k, double g[2]) {
  double u1 = 1.0 - gr_unit(gr_lhash(seed, shape, strand, k, GR_LH_WALK_X));
  double u2 = gr_unit(gr_lhash(seed, shape, strand, k, GR_LH_WALK_Y));
  double r = sqrt(-2.0 * log(u1));
  g[0] = r * cos(2.0 * GR_SKY_PI * u2);
  g[1] = r * sin(2.0 * GR_SKY_PI * u2);
}

/* Two unit vectors v, w across the unit vector u (u, v, w right-handed). */
static void gr_across(const double u[3], double v[3], double w[3]) {
  /* Cross with the axis u is least aligned with: z for a level bolt, x for
   * the usual steep one. */
  double a[3] = {0.0, 0.0, 0.0};
  a[fabs(u[2]) > 0.7 ? 0 : 2] = 1.0;
  v[0] = u[1] * a[2] - u[2] * a[1];
  v[1] = u[2] * a[0] - u[0] * a[2];
  v[2] = u[0] * a[1] - u[1] * a[0];
  double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  for (int c = 0; c < 3; ++c)
    v[c] /= n;
  w[0] = u[1] * v[2] - u[2] * v[1];
  w[1] = u[2] * v[0] - u[0] * v[2];
  w[2] = u[0] * v[1] - u[1] * v[0];
}

gr_status gr_lightning_generate(const gr_lightning_params *p, double *xyz, float *intensity,
                                int *strand, char *msg, size_t msg_len) {
  gr_status st = gr_lightning_params_validate(p, msg, msg_len);
  if (st != GR_OK)
    return st;
  if (!xyz) {
    if (msg && msg_len)
      snprintf(msg, msg_len, "gr_lightning_generate needs room for the points.");
    return GR_ERR_INVALID_ARGUMENT;
  }
  const int n = p->control_points, m = gr_lightning_branch_points(n);
  const int shape = gr_lightning_shape(p);
  double d[3], u[3], v[3], w[3];
  double len = 0.0;
  for (int c = 0; c < 3; ++c) {
    d[c] = p->end[c] - p->start[c];
    len += d[c] * d[c];
  }
  len = sqrt(len);
  for (int c = 0; c < 3; ++c)
    u[c] = d[c] / len;
  gr_across(u, v, w);

  /* Main strand: the walk W first (into the lateral slots of xyz), then the
   * bridge W_k - t_k W_last, which needs the walk's end. */
  const double step = sqrt(1.0 / (n - 1));
  double walk[2] = {0.0, 0.0};
  for (int k = 0; k < n; ++k) {
    if (k > 0) {
      double g[2];
      gr_gauss2(p->seed, shape, 0, k, g);
      walk[0] += step * g[0];
      walk[1] += step * g[1];
    }
    xyz[3 * k + 0] = walk[0];
    xyz[3 * k + 1] = walk[1];
  }
  const double last[2] = {walk[0], walk[1]};
  for (int k = 0; k < n; ++k) {
    double t = (double)k / (n - 1);
    double bx = p->jitter * len * (xyz[3 * k + 0] - t * last[0]);
    double by = p->jitter * len * (xyz[3 * k + 1] - t * last[1]);
    for (int c = 0; c < 3; ++c)
      xyz[3 * k + c] = p->start[c] + t * d[c] + bx * v[c] + by * w[c];
    if (intensity)
      intensity[k] = 1.0f;
    if (strand)
      strand[k] = 0;
  }
  for (int c = 0; c < 3; ++c) {
    xyz[c] = p->start[c];
    xyz[3 * (n - 1) + c] = p->end[c];
  }

  /* Branches, each from a point of the main strand. */
  const int kmax = n - 2 < (int)(0.8 * (n - 1)) ? n - 2 : (int)(0.8 * (n - 1));
  const double bstep = sqrt(1.0 / (m - 1));
  for (int s = 1; s <= p->strands; ++s) {
    int k = (int)(gr_unit(gr_lhash(p->seed, shape, s, 0, GR_LH_ATTACH)) * (kmax + 1));
    k = k > kmax ? kmax : k;
    double theta =
        (20.0 + 25.0 * gr_unit(gr_lhash(p->seed, shape, s, 0, GR_LH_ANGLE))) * GR_SKY_PI / 180.0;
    double phi = 2.0 * GR_SKY_PI * gr_unit(gr_lhash(p->seed, shape, s, 0, GR_LH_AZIMUTH));
    double blen = (0.15 + 0.25 * gr_unit(gr_lhash(p->seed, shape, s, 0, GR_LH_LENGTH))) * len *
                  (1.0 - (double)k / (n - 1));
    double bd[3], bv[3], bw[3];
    for (int c = 0; c < 3; ++c)
      bd[c] = cos(theta) * u[c] + sin(theta) * (cos(phi) * v[c] + sin(phi) * w[c]);
    gr_across(bd, bv, bw);
    const double *root = xyz + 3 * k;
    double *q = xyz + 3 * ((long)n + (long)(s - 1) * m);
    long first = (long)n + (long)(s - 1) * m;
    walk[0] = walk[1] = 0.0;
    for (int j = 0; j < m; ++j) {
      if (j > 0) {
        double g[2];
        gr_gauss2(p->seed, shape, s, j, g);
        walk[0] += bstep * g[0];
        walk[1] += bstep * g[1];
      }
      double t = (double)j / (m - 1);
      for (int c = 0; c < 3; ++c)
        q[3 * j + c] = j == 0 ? root[c]
                              : root[c] + t * blen * bd[c] +
                                    p->jitter * blen * (walk[0] * bv[c] + walk[1] * bw[c]);
      if (intensity)
        intensity[first + j] = (float)(0.5 - 0.35 * t);
      if (strand)
        strand[first + j] = s;
    }
  }
  return GR_OK;
}

long gr_lightning_strike_index(int seed, int shape, long npoints) {
  if (npoints < 1)
    return -1;
  long k = (long)(gr_unit(gr_lhash(seed, shape, -1, 0, GR_LH_ATTACH)) * (double)npoints);
  return k < npoints ? k : npoints - 1;
}

void gr_lightning_start_over(int seed, int shape, const double bounds[6], const double end[3],
                             double start[3]) {
  double xr = bounds[1] - bounds[0], yr = bounds[3] - bounds[2];
  double h = 0.5 * (xr > yr ? xr : yr);
  h = h > 100.0 ? h : 100.0;
  double r = h / 3.0 * gr_unit(gr_lhash(seed, shape, -1, 0, GR_LH_LENGTH));
  double phi = 2.0 * GR_SKY_PI * gr_unit(gr_lhash(seed, shape, -1, 0, GR_LH_AZIMUTH));
  start[0] = end[0] + r * cos(phi);
  start[1] = end[1] + r * sin(phi);
  start[2] = (bounds[5] > end[2] ? bounds[5] : end[2]) + h;
}

/* ---------------------------------------------------------- cloud cover */

struct gr_cloud_cover {
  gr_context *ctx;
  gr_cloud_cover_params params;
  gr_grid grid;
  cl_kernel noise_kernel, shade_kernel;
  cl_mem noise, cloud, rgb;
  cl_mem table, lattice; /* per octave, as procedural_terrain's */
  float *sorted;         /* the Seed's noise sample, ascending */
  double threshold;
  int computed_rows; /* rows computed since the last parameters */
  char error[1024];
};

void gr_cloud_cover_params_init(gr_cloud_cover_params *p) {
  if (!p)
    return;
  memset(p, 0, sizeof(*p));
  const gr_param_bound *b = gr_sky_bounds;
  p->cover = b[GR_SKY_COVER].default_value;
  p->scale = b[GR_SKY_SCALE].default_value;
  p->sharpness = b[GR_SKY_SHARPNESS].default_value;
  p->wind_speed = b[GR_SKY_WIND_SPEED].default_value;
  p->wind_direction = b[GR_SKY_WIND_DIRECTION].default_value;
  p->resolution = (int)b[GR_SKY_RESOLUTION].default_value;
  p->size = b[GR_SKY_SIZE].default_value;
  p->seed = (int)b[GR_SKY_SEED].default_value;
}

gr_status gr_cloud_cover_params_validate(const gr_cloud_cover_params *p, char *msg,
                                         size_t msg_len) {
  const char *what = "Invalid cloud cover parameters";
  if (!p)
    return gr_params_missing(what, msg, msg_len);
  const int rows[] = {GR_SKY_COVER,          GR_SKY_SCALE,      GR_SKY_SHARPNESS, GR_SKY_WIND_SPEED,
                      GR_SKY_WIND_DIRECTION, GR_SKY_RESOLUTION, GR_SKY_SIZE,      GR_SKY_SEED};
  const double values[] = {p->cover,          p->scale,      p->sharpness, p->wind_speed,
                           p->wind_direction, p->resolution, p->size,      p->seed};
  return gr_params_check_table(gr_sky_bounds, rows, 8, values, what, gr_sky_hints,
                               GR_PARAM_SAY_IS_WHOLE_FIRST, msg, msg_len);
}

void gr_cloud_cover_grid(const gr_cloud_cover_params *p, gr_grid *out) {
  if (!p || !out)
    return;
  memset(out, 0, sizeof(*out));
  out->nx = out->ny = p->resolution;
  out->dx = out->dy = p->resolution > 0 ? p->size / p->resolution : 0.0;
  out->x0 = out->y0 = -0.5 * p->size + 0.5 * out->dx;
}

/* Fills the octave tables for points x = x0 + i*dx (likewise y) in units of
 * the first octave's wavelength: lattice cell and fraction of the origin
 * split in double, so float keeps its precision far from (0, 0). */
static gr_status gr_cloud_tables(gr_cloud_cover *c, double x0, double y0, double dx, double dy,
                                 int nx, int ny) {
  cl_float table[GR_SKY_OCTAVES * GR_SKY_TABLE_STRIDE];
  cl_int lattice[GR_SKY_OCTAVES * GR_SKY_LATTICE_STRIDE];
  double m = 1.0;
  for (int o = 0; o < GR_SKY_OCTAVES; ++o) {
    double X = x0 * m, Y = y0 * m;
    double ext = fmax(fabs(X), fabs(Y)) + fmax(nx * dx, ny * dy) * m;
    if (!(ext < GR_SKY_LATTICE_LIMIT))
      return gr_set_error(c->ctx, GR_ERR_INVALID_ARGUMENT,
                          "The cloud cover's noise would need lattice coordinates beyond %.0e "
                          "(the image's extent plus the wind's drift, WindSpeed times the time, "
                          "is too many Scales from the origin); raise Scale or use an earlier "
                          "time.",
                          GR_SKY_LATTICE_LIMIT);
    double lx = floor(X), ly = floor(Y);
    table[GR_SKY_TABLE_STRIDE * o + 0] = (cl_float)(X - lx);
    table[GR_SKY_TABLE_STRIDE * o + 1] = (cl_float)(Y - ly);
    table[GR_SKY_TABLE_STRIDE * o + 2] = (cl_float)(dx * m);
    table[GR_SKY_TABLE_STRIDE * o + 3] = (cl_float)(dy * m);
    lattice[GR_SKY_LATTICE_STRIDE * o + 0] = (cl_int)lx;
    lattice[GR_SKY_LATTICE_STRIDE * o + 1] = (cl_int)ly;
    m *= GR_SKY_LACUNARITY;
  }
  gr_status st = gr_buffer_write(c->ctx, c->table, 0, sizeof(table), table);
  if (st == GR_OK)
    st = gr_buffer_write(c->ctx, c->lattice, 0, sizeof(lattice), lattice);
  return st;
}

static gr_status gr_cloud_noise_launch(gr_cloud_cover *c, cl_mem noise, cl_int nx, int row0,
                                       int nrows) {
  cl_kernel k = c->noise_kernel;
  /* The kernel's row bound is the band's end: rounding the launch up never
   * spills into the next band. */
  cl_int ny = row0 + nrows;
  cl_mem table = c->table, lattice = c->lattice;
  /* Apart from the terrain's seed + o, so a sky and a terrain of one Seed differ. */
  cl_uint seed = (cl_uint)c->params.seed * 0x9e3779b1U + 0x5bd1e995U;
  gr_status st = GR_KERNEL_ARG(c->ctx, k, noise);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(c->ctx, k, nx);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(c->ctx, k, ny);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(c->ctx, k, table);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(c->ctx, k, lattice);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(c->ctx, k, seed);
  if (st == GR_OK)
    st = gr_enqueue_2d(c->ctx, k, 0, (size_t)row0, (size_t)nx, (size_t)nrows, NULL);
  return st;
}

static int gr_cmp_float(const void *a, const void *b) {
  float x = *(const float *)a, y = *(const float *)b;
  return (x > y) - (x < y);
}

/* The Seed's noise sample, sorted: GR_SKY_SAMPLE_SIDE^2 points on a grid
 * GR_SKY_SAMPLE_STEP wavelengths apart, away from the origin's lattice. */
static gr_status gr_cloud_measure(gr_cloud_cover *c) {
  const int side = GR_SKY_SAMPLE_SIDE;
  size_t n = (size_t)side * side;
  cl_mem sample = NULL;
  gr_status st = gr_buffer_create(c->ctx, CL_MEM_READ_WRITE, n * sizeof(cl_float), NULL, &sample);
  if (st == GR_OK)
    st = gr_cloud_tables(c, 0.31830988618, 0.57721566490, GR_SKY_SAMPLE_STEP, GR_SKY_SAMPLE_STEP,
                         side, side);
  if (st == GR_OK)
    st = gr_cloud_noise_launch(c, sample, side, 0, side);
  if (st == GR_OK)
    st = gr_buffer_read(c->ctx, sample, 0, n * sizeof(cl_float), c->sorted);
  gr_buffer_release(&sample);
  if (st == GR_OK)
    qsort(c->sorted, n, sizeof(float), gr_cmp_float);
  return st;
}

/* T = the (1 - Cover) quantile of the sample, between 0 (every n above it)
 * and 1 (none): the sorted sample extended by 0 and 1 at its ends and read
 * linearly, so T falls continuously and monotonically as Cover rises. */
static double gr_cloud_quantile(const gr_cloud_cover *c, double cover) {
  const long n = (long)GR_SKY_SAMPLE_SIDE * GR_SKY_SAMPLE_SIDE;
  double pos = (1.0 - cover) * (double)(n + 1);
  long k = (long)floor(pos);
  if (k < 0)
    return 0.0;
  if (k >= n + 1)
    return 1.0;
  double f = pos - (double)k;
  double a = k == 0 ? 0.0 : c->sorted[k - 1];
  double b = k == n ? 1.0 : c->sorted[k];
  return a + f * (b - a);
}

static gr_status gr_cloud_allocate(gr_cloud_cover *c) {
  gr_buffer_release(&c->noise);
  gr_buffer_release(&c->cloud);
  gr_buffer_release(&c->rgb);
  size_t n = (size_t)c->grid.nx * (size_t)c->grid.ny;
  gr_status st = gr_buffer_create(c->ctx, CL_MEM_READ_WRITE, n * sizeof(cl_float), NULL, &c->noise);
  if (st == GR_OK)
    st = gr_buffer_create(c->ctx, CL_MEM_WRITE_ONLY, n * sizeof(cl_float), NULL, &c->cloud);
  if (st == GR_OK)
    st = gr_buffer_create(c->ctx, CL_MEM_WRITE_ONLY, 3 * n, NULL, &c->rgb);
  return st;
}

gr_status gr_cloud_cover_memory(const gr_cloud_cover_params *p, gr_memory_need *out) {
  if (!p || !out)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_cloud_cover_memory needs parameters and a place for the answer.");
  double n = (double)p->resolution * (double)p->resolution;
  double sample = sizeof(cl_float) * (double)GR_SKY_SAMPLE_SIDE * GR_SKY_SAMPLE_SIDE;
  memset(out, 0, sizeof(*out));
  out->points = n;
  out->device = (4.0 + 4.0 + 3.0) * n + sample; /* gr_cloud_allocate, gr_cloud_measure */
  out->largest = 4.0 * n > sample ? 4.0 * n : sample;
  out->host = sample; /* the sorted sample */
  return GR_OK;
}

gr_status gr_cloud_cover_create(gr_context *ctx, const gr_cloud_cover_params *p,
                                gr_cloud_cover **out) {
  char msg[256];
  if (!ctx || !out)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_cloud_cover_create needs a context and a place for the image.");
  *out = NULL;
  if (gr_cloud_cover_params_validate(p, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  gr_grid grid;
  gr_cloud_cover_grid(p, &grid);
  if (gr_grid_validate(&grid, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  gr_memory_need need;
  gr_cloud_cover_memory(p, &need);
  if (gr_memory_check(ctx, &need, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_TOO_LARGE,
                        "The cloud image of %d x %d pixels %s: lower Resolution or use another "
                        "device.",
                        grid.nx, grid.ny, msg);
  gr_cloud_cover *c = calloc(1, sizeof(*c));
  float *sorted = malloc(sizeof(float) * GR_SKY_SAMPLE_SIDE * GR_SKY_SAMPLE_SIDE);
  if (!c || !sorted) {
    free(c);
    free(sorted);
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  c->ctx = gr_context_retain(ctx);
  c->params = *p;
  c->grid = grid;
  c->sorted = sorted;
  cl_program prog = NULL;
  gr_status st = gr_program_get(ctx, "sky", "", &prog);
  if (st == GR_OK)
    st = gr_kernel_create(ctx, prog, "sky_cloud_noise", &c->noise_kernel);
  if (st == GR_OK)
    st = gr_kernel_create(ctx, prog, "sky_cloud_shade", &c->shade_kernel);
  if (st == GR_OK)
    st = gr_buffer_create(ctx, CL_MEM_READ_ONLY,
                          sizeof(cl_float) * GR_SKY_OCTAVES * GR_SKY_TABLE_STRIDE, NULL, &c->table);
  if (st == GR_OK)
    st = gr_buffer_create(ctx, CL_MEM_READ_ONLY,
                          sizeof(cl_int) * GR_SKY_OCTAVES * GR_SKY_LATTICE_STRIDE, NULL,
                          &c->lattice);
  if (st == GR_OK)
    st = gr_cloud_allocate(c);
  if (st == GR_OK)
    st = gr_cloud_measure(c);
  if (st != GR_OK) {
    gr_cloud_cover_destroy(c);
    return st;
  }
  c->threshold = gr_cloud_quantile(c, p->cover);
  *out = c;
  return GR_OK;
}

gr_status gr_cloud_cover_set_params(gr_cloud_cover *c, const gr_cloud_cover_params *p) {
  char msg[256];
  if (!c)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT, "gr_cloud_cover_set_params needs an image.");
  if (gr_cloud_cover_params_validate(p, msg, sizeof(msg)) != GR_OK)
    return gr_error_keep(c->error, sizeof(c->error),
                         gr_set_error(c->ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg));
  gr_cloud_cover_params old = c->params;
  gr_grid old_grid = c->grid;
  c->params = *p;
  gr_cloud_cover_grid(p, &c->grid);
  gr_status st = GR_OK;
  if (p->resolution != old.resolution)
    st = gr_cloud_allocate(c);
  if (st == GR_OK && p->seed != old.seed)
    st = gr_cloud_measure(c);
  if (st != GR_OK) {
    /* Back to the previous image's state, with this failure's sentence. */
    char why[sizeof(c->error)];
    snprintf(why, sizeof(why), "%s", gr_last_error(c->ctx));
    c->params = old;
    c->grid = old_grid;
    gr_cloud_allocate(c);
    gr_cloud_measure(c);
    gr_set_error(c->ctx, st, "%s", why);
  }
  c->threshold = gr_cloud_quantile(c, c->params.cover);
  c->computed_rows = 0;
  return gr_error_keep(c->error, sizeof(c->error), st);
}

double gr_cloud_cover_threshold(const gr_cloud_cover *c) {
  return c ? c->threshold : 0.0;
}

gr_status gr_cloud_cover_compute(gr_cloud_cover *c, double t) {
  if (!c)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT, "gr_cloud_cover_compute needs an image.");
  return gr_cloud_cover_compute_rows(c, t, 0, c->grid.ny);
}

gr_status gr_cloud_cover_compute_rows(gr_cloud_cover *c, double t, int row0, int nrows) {
  if (!c)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_cloud_cover_compute_rows needs an image.");
  if (!isfinite(t))
    return gr_error_keep(c->error, sizeof(c->error),
                         gr_set_error(c->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "The cloud cover's time is %g s but must be finite.", t));
  if (row0 < 0 || nrows < 0 || row0 > c->grid.ny - nrows)
    return gr_error_keep(c->error, sizeof(c->error),
                         gr_set_error(c->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "Rows %d to %d are not inside the image's %d rows.", row0,
                                      row0 + nrows - 1, c->grid.ny));
  if (nrows == 0)
    return GR_OK;
  const gr_cloud_cover_params *p = &c->params;
  double dir = p->wind_direction * GR_SKY_PI / 180.0;
  double u = p->wind_speed * sin(dir), v = p->wind_speed * cos(dir);
  /* The field moves with the wind: the noise at (x, y) and time t is the
   * noise at (x - u t, y - v t) at time 0. */
  double f = 1.0 / p->scale;
  gr_status st = gr_cloud_tables(c, (c->grid.x0 - u * t) * f, (c->grid.y0 - v * t) * f,
                                 c->grid.dx * f, c->grid.dy * f, c->grid.nx, c->grid.ny);
  if (st == GR_OK)
    st = gr_cloud_noise_launch(c, c->noise, c->grid.nx, row0, nrows);
  if (st == GR_OK) {
    cl_kernel k = c->shade_kernel;
    cl_mem noise = c->noise, cloud = c->cloud, rgb = c->rgb;
    cl_int k0 = row0 * c->grid.nx, kend = (row0 + nrows) * c->grid.nx;
    cl_float threshold = (cl_float)c->threshold;
    cl_float log_sharpness = (cl_float)(255.0 * log(p->sharpness));
    st = GR_KERNEL_ARG(c->ctx, k, noise);
    if (st == GR_OK)
      st = GR_KERNEL_ARG(c->ctx, k, cloud);
    if (st == GR_OK)
      st = GR_KERNEL_ARG(c->ctx, k, rgb);
    if (st == GR_OK)
      st = GR_KERNEL_ARG(c->ctx, k, k0);
    if (st == GR_OK)
      st = GR_KERNEL_ARG(c->ctx, k, kend);
    if (st == GR_OK)
      st = GR_KERNEL_ARG(c->ctx, k, threshold);
    if (st == GR_OK)
      st = GR_KERNEL_ARG(c->ctx, k, log_sharpness);
    if (st == GR_OK)
      st = gr_enqueue_1d(c->ctx, k, (size_t)(kend - k0));
  }
  if (st == GR_OK)
    c->computed_rows = row0 == 0 ? nrows : c->computed_rows + nrows;
  return gr_error_keep(c->error, sizeof(c->error), st);
}

gr_status gr_cloud_cover_get(gr_cloud_cover *c, float *cloud, unsigned char *sky_rgb) {
  if (!c)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT, "gr_cloud_cover_get needs an image.");
  if (c->computed_rows < c->grid.ny)
    return gr_error_keep(c->error, sizeof(c->error),
                         gr_set_error(c->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "The cloud cover has not been computed for its current "
                                      "parameters; call gr_cloud_cover_compute first."));
  size_t n = (size_t)c->grid.nx * (size_t)c->grid.ny;
  gr_status st = GR_OK;
  if (cloud)
    st = gr_buffer_read(c->ctx, c->cloud, 0, n * sizeof(float), cloud);
  if (st == GR_OK && sky_rgb)
    st = gr_buffer_read(c->ctx, c->rgb, 0, 3 * n, sky_rgb);
  return gr_error_keep(c->error, sizeof(c->error), st);
}

const char *gr_cloud_cover_last_error(const gr_cloud_cover *c) {
  return c ? c->error : gr_last_error(NULL);
}

void gr_cloud_cover_destroy(gr_cloud_cover *c) {
  if (!c)
    return;
  if (c->noise_kernel)
    clReleaseKernel(c->noise_kernel);
  if (c->shade_kernel)
    clReleaseKernel(c->shade_kernel);
  gr_buffer_release(&c->noise);
  gr_buffer_release(&c->cloud);
  gr_buffer_release(&c->rgb);
  gr_buffer_release(&c->table);
  gr_buffer_release(&c->lattice);
  free(c->sorted);
  gr_context_release(c->ctx);
  free(c);
}
