/* Terrain analysis core (seed 001): host side of terrain_analysis.cl. */
#include "graupel/terrain_analysis.h"
#include "graupel/cl_runtime.h"
#include "terrain_analysis_shared.h"
#include "runtime_internal.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

_Static_assert(GR_COVER_GROUND == GR_TA_CLASS_GROUND && GR_COVER_SNOW == GR_TA_CLASS_SNOW &&
                   GR_COVER_ROCK == GR_TA_CLASS_ROCK && GR_COVER_ICE == GR_TA_CLASS_ICE,
               "gr_cover_class and the kernel's classes must agree");

#define GR_TA_PI 3.14159265358979323846

struct gr_terrain_analysis {
  gr_context *ctx;
  gr_grid grid;
  gr_terrain_analysis_params params;
  cl_kernel derive, shadow_kernel;
  cl_mem heights, normal, slope, aspect, hillshade, snow_cover, cover_class, shadow;
  int has_heights;
  double h_max;
  /* Which outputs hold the latest heights' results. shadow_rows counts the
   * rows computed since set_heights (or new sun parameters), so a band-wise
   * shadow counts as made once all its rows are. */
  int derived;
  int shadow_rows;
  unsigned char *shadow_done; /* per row: 1 once computed */
  char error[1024];
};

/* The rows of the parameter table, in the order of the filters' properties. */
enum {
  GR_TA_SUN_AZIMUTH,
  GR_TA_SUN_ELEVATION,
  GR_TA_SNOW_EXPONENT,
  GR_TA_COVER_MODE,
  GR_TA_SNOW_COVER_LIMIT,
  GR_TA_ROCK_SLOPE,
  GR_TA_WATER_LEVEL,
  GR_TA_MODEL_SHADOWS,
  GR_TA_PENUMBRA_WIDTH,
  GR_TA_ROWS
};

/* The one place the ranges are written. The defaults: ESRI's Hillshade sun
 * (azimuth 315, elevation 45); SnowExponent 4 puts the smooth cover at 0.5
 * near 33 degrees, where dry snow starts to slide; RockSlope 45 degrees,
 * above which snow does not stay (seed 001 leaves both open, notes C).
 * WaterLevel's range spans the deepest ocean to above the highest terrain a
 * Procedural Terrain can make. SunElevation excludes 0: a sun on the horizon
 * puts every point of flat ground on the shadow's edge. */
static const gr_param_bound gr_ta_bounds[GR_TA_ROWS] = {
    {"SunAzimuth", "deg", 0.0, 360.0, 315.0, 1.0, 0, 0},
    {"SunElevation", "deg", 0.0, 90.0, 45.0, 1.0, 1, 0},
    {"SnowExponent", "", 0.0, 64.0, 4.0, 1.0, 1, 0},
    {"CoverMode", "", GR_TA_COVER_SMOOTH, GR_TA_COVER_THRESHOLD, GR_TA_COVER_SMOOTH, 1.0, 0, 1},
    {"SnowCoverLimit", "", 0.0, 1.0, 0.5, 1.0, 0, 0},
    {"RockSlope", "deg", 0.0, 90.0, 45.0, 1.0, 0, 0},
    {"WaterLevel", "m", -1.1e4, 1e5, 0.0, 1.0, 0, 0},
    {"ModelShadows", "", 0.0, 1.0, 0.0, 1.0, 0, 1},
    {"PenumbraWidth", "deg", 0.0, 20.0, 0.0, 1.0, 0, 0},
};

static const char *const gr_ta_hints[GR_TA_ROWS] = {
    [GR_TA_COVER_MODE] = " (0 smooth, 1 threshold)",
    [GR_TA_MODEL_SHADOWS] = " (0 or 1)",
};

static const char *const gr_ta_names[GR_TERRAIN_OUTPUT_COUNT] = {
    "normal", "slope", "aspect", "hillshade", "snow_cover", "cover_class", "shadow"};

const char *gr_terrain_output_name(gr_terrain_output o) {
  return (int)o >= 0 && o < GR_TERRAIN_OUTPUT_COUNT ? gr_ta_names[o] : NULL;
}

const gr_param_bound *gr_terrain_analysis_param_bounds(int *count) {
  if (count)
    *count = GR_TA_ROWS;
  return gr_ta_bounds;
}

static double gr_ta_get(const gr_terrain_analysis_params *p, int row) {
  switch (row) {
  case GR_TA_SUN_AZIMUTH:
    return p->sun_azimuth;
  case GR_TA_SUN_ELEVATION:
    return p->sun_elevation;
  case GR_TA_SNOW_EXPONENT:
    return p->snow_exponent;
  case GR_TA_COVER_MODE:
    return p->cover_mode;
  case GR_TA_SNOW_COVER_LIMIT:
    return p->snow_cover_limit;
  case GR_TA_ROCK_SLOPE:
    return p->rock_slope;
  case GR_TA_WATER_LEVEL:
    return p->water_level;
  case GR_TA_MODEL_SHADOWS:
    return p->model_shadows;
  default:
    return p->penumbra_width;
  }
}

void gr_terrain_analysis_params_init(gr_terrain_analysis_params *p) {
  if (!p)
    return;
  memset(p, 0, sizeof(*p));
  const gr_param_bound *b = gr_ta_bounds;
  p->sun_azimuth = b[GR_TA_SUN_AZIMUTH].default_value;
  p->sun_elevation = b[GR_TA_SUN_ELEVATION].default_value;
  p->snow_exponent = b[GR_TA_SNOW_EXPONENT].default_value;
  p->cover_mode = (int)b[GR_TA_COVER_MODE].default_value;
  p->snow_cover_limit = b[GR_TA_SNOW_COVER_LIMIT].default_value;
  p->rock_slope = b[GR_TA_ROCK_SLOPE].default_value;
  p->water_level = b[GR_TA_WATER_LEVEL].default_value;
  p->model_shadows = (int)b[GR_TA_MODEL_SHADOWS].default_value;
  p->penumbra_width = b[GR_TA_PENUMBRA_WIDTH].default_value;
}

gr_status gr_terrain_analysis_params_validate(const gr_terrain_analysis_params *p, char *msg,
                                              size_t msg_len) {
  const char *what = "Invalid terrain analysis parameters";
  if (!p)
    return gr_params_missing(what, msg, msg_len);
  double values[GR_TA_ROWS];
  for (int row = 0; row < GR_TA_ROWS; ++row)
    values[row] = gr_ta_get(p, row);
  return gr_params_check_table(gr_ta_bounds, NULL, GR_TA_ROWS, values, what, gr_ta_hints,
                               GR_PARAM_SAY_IS_OPEN_FIRST, msg, msg_len);
}

void gr_terrain_analysis_destroy(gr_terrain_analysis *t) {
  if (!t)
    return;
  if (t->derive)
    clReleaseKernel(t->derive);
  if (t->shadow_kernel)
    clReleaseKernel(t->shadow_kernel);
  cl_mem *bufs[] = {&t->heights,   &t->normal,     &t->slope,       &t->aspect,
                    &t->hillshade, &t->snow_cover, &t->cover_class, &t->shadow};
  for (size_t b = 0; b < sizeof(bufs) / sizeof(bufs[0]); ++b)
    gr_buffer_release(bufs[b]);
  free(t->shadow_done);
  gr_context_release(t->ctx);
  free(t);
}

/* Drops every output: new heights, or new sun parameters for the shadow. */
static void gr_ta_forget(gr_terrain_analysis *t, int shadow_only) {
  if (!shadow_only)
    t->derived = 0;
  t->shadow_rows = 0;
  memset(t->shadow_done, 0, (size_t)t->grid.ny);
}

gr_status gr_terrain_analysis_memory(const gr_grid *grid, gr_memory_need *out) {
  if (!grid || !out)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_terrain_analysis_memory needs a grid and a place for the answer.");
  double n = (double)grid->nx * (double)grid->ny;
  memset(out, 0, sizeof(*out));
  out->points = n;
  out->device = (4.0 * (1 + 3 + 5) + 1.0) * n; /* the buffers gr_terrain_analysis_create makes */
  out->largest = 3.0 * 4.0 * n;                /* the normal */
  out->host = (double)grid->ny;                /* shadow_done */
  return GR_OK;
}

gr_status gr_terrain_analysis_create(gr_context *ctx, const gr_grid *grid,
                                     const gr_terrain_analysis_params *p,
                                     gr_terrain_analysis **out) {
  char msg[256];
  if (!ctx || !out)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_terrain_analysis_create needs a context and a place for the "
                        "analysis.");
  *out = NULL;
  if (gr_grid_validate(grid, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  if ((grid->global_nx && grid->global_nx != grid->nx) ||
      (grid->global_ny && grid->global_ny != grid->ny) || grid->ghost)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "Terrain analysis needs the whole grid (shadow rays cross all of it); "
                        "it was given a piece of %d x %d points of a %d x %d domain with a ring "
                        "of %d: compute it on one rank.",
                        grid->nx, grid->ny, grid->global_nx, grid->global_ny, grid->ghost);
  if (gr_terrain_analysis_params_validate(p, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  gr_memory_need need;
  gr_terrain_analysis_memory(grid, &need);
  if (gr_memory_check(ctx, &need, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_TOO_LARGE,
                        "The terrain analysis of a %d x %d grid %s: use a smaller grid or "
                        "another device.",
                        grid->nx, grid->ny, msg);

  gr_terrain_analysis *t = calloc(1, sizeof(*t));
  if (!t)
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  t->ctx = gr_context_retain(ctx);
  t->grid = *grid;
  t->params = *p;
  t->shadow_done = calloc((size_t)grid->ny, 1);
  if (!t->shadow_done) {
    gr_terrain_analysis_destroy(t);
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  size_t n = (size_t)grid->nx * (size_t)grid->ny, fb = n * sizeof(cl_float);
  cl_program prog = NULL;
  gr_status st = gr_program_get(ctx, "terrain_analysis", "", &prog);
  if (st == GR_OK)
    st = gr_kernel_create(ctx, prog, "terrain_analysis_derive", &t->derive);
  if (st == GR_OK)
    st = gr_kernel_create(ctx, prog, "terrain_analysis_shadow", &t->shadow_kernel);
  if (st == GR_OK)
    st = gr_buffer_create(ctx, CL_MEM_READ_ONLY, fb, NULL, &t->heights);
  if (st == GR_OK)
    st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, 3 * fb, NULL, &t->normal);
  cl_mem *floats[] = {&t->slope, &t->aspect, &t->hillshade, &t->snow_cover, &t->shadow};
  for (size_t b = 0; st == GR_OK && b < sizeof(floats) / sizeof(floats[0]); ++b)
    st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, fb, NULL, floats[b]);
  if (st == GR_OK)
    st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, n, NULL, &t->cover_class);
  if (st != GR_OK) {
    gr_terrain_analysis_destroy(t);
    return st;
  }
  *out = t;
  return GR_OK;
}

gr_status gr_terrain_analysis_set_params(gr_terrain_analysis *t,
                                         const gr_terrain_analysis_params *p) {
  char msg[256];
  if (!t)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_terrain_analysis_set_params needs an analysis.");
  if (gr_terrain_analysis_params_validate(p, msg, sizeof(msg)) != GR_OK)
    return gr_error_keep(t->error, sizeof(t->error),
                         gr_set_error(t->ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg));
  if (p->sun_azimuth != t->params.sun_azimuth || p->sun_elevation != t->params.sun_elevation ||
      p->penumbra_width != t->params.penumbra_width)
    gr_ta_forget(t, 1);
  t->params = *p;
  t->derived = 0;
  return GR_OK;
}

gr_status gr_terrain_analysis_set_heights(gr_terrain_analysis *t, const float *host) {
  if (!t || !host) {
    gr_status st = gr_set_error(t ? t->ctx : NULL, GR_ERR_INVALID_ARGUMENT,
                                "gr_terrain_analysis_set_heights needs an analysis and heights.");
    return t ? gr_error_keep(t->error, sizeof(t->error), st) : st;
  }
  const int nx = t->grid.nx, ny = t->grid.ny;
  double h_max = -DBL_MAX;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      float h = host[(size_t)j * (size_t)nx + (size_t)i];
      if (!isfinite(h))
        return gr_error_keep(t->error, sizeof(t->error),
                             gr_set_error(t->ctx, GR_ERR_INVALID_ARGUMENT,
                                          "The terrain's heights hold %s at point (%d, %d); "
                                          "every height must be a finite number of metres.",
                                          isnan(h) ? "NaN" : "an infinite value", i, j));
      h_max = h > h_max ? h : h_max;
    }
  gr_ta_forget(t, 0);
  t->has_heights = 0;
  gr_status st =
      gr_buffer_write(t->ctx, t->heights, 0, (size_t)nx * (size_t)ny * sizeof(float), host);
  if (st == GR_OK) {
    t->has_heights = 1;
    t->h_max = h_max;
  }
  return gr_error_keep(t->error, sizeof(t->error), st);
}

static gr_status gr_ta_need_heights(gr_terrain_analysis *t, const char *what) {
  if (t->has_heights)
    return GR_OK;
  return gr_error_keep(t->error, sizeof(t->error),
                       gr_set_error(t->ctx, GR_ERR_INVALID_ARGUMENT,
                                    "Terrain analysis cannot compute the %s before it is given "
                                    "heights (gr_terrain_analysis_set_heights).",
                                    what));
}

gr_status gr_terrain_analysis_compute_shadow_rows(gr_terrain_analysis *t, int row0, int nrows) {
  if (!t)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_terrain_analysis_compute_shadow_rows needs an analysis.");
  if (row0 < 0 || nrows < 0 || row0 > t->grid.ny - nrows)
    return gr_error_keep(t->error, sizeof(t->error),
                         gr_set_error(t->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "Rows %d to %d are not inside the grid's %d rows.", row0,
                                      row0 + nrows - 1, t->grid.ny));
  gr_status st = gr_ta_need_heights(t, "shadow");
  if (st != GR_OK || nrows == 0)
    return st;
  const gr_terrain_analysis_params *p = &t->params;
  const gr_grid *g = &t->grid;
  /* The sun's direction in index units, scaled so that the faster axis
   * advances by exactly one point per step; components below 1e-12 are the
   * rounding of sin/cos at multiples of 90 degrees and are made 0, so that
   * rays along an axis stay on grid points. */
  double az = p->sun_azimuth * (GR_TA_PI / 180.0);
  double ex = sin(az), ey = cos(az);
  ex = fabs(ex) < 1e-12 ? 0.0 : ex;
  ey = fabs(ey) < 1e-12 ? 0.0 : ey;
  double m = fmax(fabs(ex) / g->dx, fabs(ey) / g->dy);
  double e = p->sun_elevation, w = p->penumbra_width;
  double lit_deg = e - 0.5 * w, dark_deg = e + 0.5 * w;
  cl_int nx = g->nx, ny = g->ny, rows_end = row0 + nrows;
  cl_float step_i = (cl_float)(ex / g->dx / m), step_j = (cl_float)(ey / g->dy / m);
  cl_float step_len = (cl_float)(1.0 / m);
  cl_float tan_lit = (cl_float)tan(lit_deg * (GR_TA_PI / 180.0));
  cl_float tan_dark = dark_deg >= 90.0 ? FLT_MAX : (cl_float)tan(dark_deg * (GR_TA_PI / 180.0));
  cl_float sun_elevation = (cl_float)e, penumbra = (cl_float)w, h_max = (cl_float)t->h_max;
  cl_mem heights = t->heights, shadow = t->shadow;
  cl_kernel k = t->shadow_kernel;
  gr_context *ctx = t->ctx;
  st = GR_KERNEL_ARG(ctx, k, heights);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, nx);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, ny);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, rows_end);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, step_i);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, step_j);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, step_len);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, tan_lit);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, tan_dark);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, sun_elevation);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, penumbra);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, h_max);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, shadow);
  if (st == GR_OK)
    st = gr_enqueue_2d(ctx, k, 0, (size_t)row0, (size_t)nx, (size_t)nrows, NULL);
  if (st == GR_OK)
    for (int r = row0; r < row0 + nrows; ++r)
      if (!t->shadow_done[r]) {
        t->shadow_done[r] = 1;
        ++t->shadow_rows;
      }
  return gr_error_keep(t->error, sizeof(t->error), st);
}

gr_status gr_terrain_analysis_compute_shadow(gr_terrain_analysis *t) {
  if (!t)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_terrain_analysis_compute_shadow needs an analysis.");
  return gr_terrain_analysis_compute_shadow_rows(t, 0, t->grid.ny);
}

gr_status gr_terrain_analysis_compute(gr_terrain_analysis *t) {
  if (!t)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_terrain_analysis_compute needs an analysis.");
  gr_status st = gr_ta_need_heights(t, "slopes");
  if (st != GR_OK)
    return st;
  const gr_terrain_analysis_params *p = &t->params;
  cl_int use_shadow = p->model_shadows != 0;
  if (use_shadow && t->shadow_rows < t->grid.ny)
    st = gr_terrain_analysis_compute_shadow(t);
  if (st != GR_OK)
    return st;
  const gr_grid *g = &t->grid;
  double az = p->sun_azimuth * (GR_TA_PI / 180.0), el = p->sun_elevation * (GR_TA_PI / 180.0);
  cl_int nx = g->nx, ny = g->ny, cover_mode = p->cover_mode;
  cl_float inv_dx = (cl_float)(1.0 / g->dx), inv_dy = (cl_float)(1.0 / g->dy);
  cl_float sun_x = (cl_float)(sin(az) * cos(el)), sun_y = (cl_float)(cos(az) * cos(el));
  cl_float sun_z = (cl_float)sin(el);
  cl_float snow_exponent = (cl_float)p->snow_exponent;
  cl_float snow_cover_limit = (cl_float)p->snow_cover_limit;
  cl_float rock_slope = (cl_float)p->rock_slope, water_level = (cl_float)p->water_level;
  cl_mem heights = t->heights, shadow = t->shadow, normal = t->normal, slope = t->slope;
  cl_mem aspect = t->aspect, hillshade = t->hillshade, snow_cover = t->snow_cover;
  cl_mem cover_class = t->cover_class;
  cl_kernel k = t->derive;
  gr_context *ctx = t->ctx;
  st = GR_KERNEL_ARG(ctx, k, heights);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, nx);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, ny);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, inv_dx);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, inv_dy);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, sun_x);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, sun_y);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, sun_z);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, snow_exponent);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, cover_mode);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, snow_cover_limit);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, rock_slope);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, water_level);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, use_shadow);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, shadow);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, normal);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, slope);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, aspect);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, hillshade);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, snow_cover);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, cover_class);
  if (st == GR_OK)
    st = gr_enqueue_2d(ctx, k, 0, 0, (size_t)nx, (size_t)ny, NULL);
  if (st == GR_OK)
    t->derived = 1;
  return gr_error_keep(t->error, sizeof(t->error), st);
}

/* The buffer of output o, or NULL with a sentence when it was not made. */
static cl_mem gr_ta_output_buffer(gr_terrain_analysis *t, gr_terrain_output o) {
  const char *name = gr_terrain_output_name(o);
  if (!name) {
    gr_error_keep(t->error, sizeof(t->error),
                  gr_set_error(t->ctx, GR_ERR_INVALID_ARGUMENT,
                               "Terrain analysis has no output number %d.", (int)o));
    return NULL;
  }
  int made = o == GR_TERRAIN_SHADOW ? t->shadow_rows == t->grid.ny : t->derived;
  if (!made) {
    gr_error_keep(t->error, sizeof(t->error),
                  gr_set_error(t->ctx, GR_ERR_INVALID_ARGUMENT,
                               "Terrain analysis has not computed '%s' for the current heights "
                               "and parameters; call %s first.",
                               name,
                               o == GR_TERRAIN_SHADOW ? "gr_terrain_analysis_compute_shadow"
                                                      : "gr_terrain_analysis_compute"));
    return NULL;
  }
  switch (o) {
  case GR_TERRAIN_NORMAL:
    return t->normal;
  case GR_TERRAIN_SLOPE:
    return t->slope;
  case GR_TERRAIN_ASPECT:
    return t->aspect;
  case GR_TERRAIN_HILLSHADE:
    return t->hillshade;
  case GR_TERRAIN_SNOW_COVER:
    return t->snow_cover;
  case GR_TERRAIN_COVER_CLASS:
    return t->cover_class;
  default:
    return t->shadow;
  }
}

gr_status gr_terrain_analysis_get_output(gr_terrain_analysis *t, gr_terrain_output o, float *host) {
  if (!t || !host) {
    gr_status st = gr_set_error(t ? t->ctx : NULL, GR_ERR_INVALID_ARGUMENT,
                                "gr_terrain_analysis_get_output needs an analysis and room for "
                                "the output.");
    return t ? gr_error_keep(t->error, sizeof(t->error), st) : st;
  }
  if (o == GR_TERRAIN_COVER_CLASS)
    return gr_error_keep(t->error, sizeof(t->error),
                         gr_set_error(t->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "cover_class is bytes: read it with "
                                      "gr_terrain_analysis_get_cover_class."));
  cl_mem buf = gr_ta_output_buffer(t, o);
  if (!buf)
    return GR_ERR_INVALID_ARGUMENT;
  size_t n = (size_t)t->grid.nx * (size_t)t->grid.ny * (o == GR_TERRAIN_NORMAL ? 3 : 1);
  return gr_error_keep(t->error, sizeof(t->error),
                       gr_buffer_read(t->ctx, buf, 0, n * sizeof(float), host));
}

gr_status gr_terrain_analysis_get_cover_class(gr_terrain_analysis *t, unsigned char *host) {
  if (!t || !host) {
    gr_status st = gr_set_error(t ? t->ctx : NULL, GR_ERR_INVALID_ARGUMENT,
                                "gr_terrain_analysis_get_cover_class needs an analysis and room "
                                "for the classes.");
    return t ? gr_error_keep(t->error, sizeof(t->error), st) : st;
  }
  cl_mem buf = gr_ta_output_buffer(t, GR_TERRAIN_COVER_CLASS);
  if (!buf)
    return GR_ERR_INVALID_ARGUMENT;
  return gr_error_keep(
      t->error, sizeof(t->error),
      gr_buffer_read(t->ctx, buf, 0, (size_t)t->grid.nx * (size_t)t->grid.ny, host));
}

const char *gr_terrain_analysis_last_error(const gr_terrain_analysis *t) {
  return t ? t->error : gr_last_error(NULL);
}
