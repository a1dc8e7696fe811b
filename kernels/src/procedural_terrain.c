/* Procedural terrain core (seed 001): host side of procedural_terrain.cl. */
#include "graupel/procedural_terrain.h"
#include "graupel/cl_runtime.h"
#include "procedural_terrain_shared.h"
#include "runtime_internal.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Lattice coordinates must stay well inside int range in every octave. */
#define GR_LATTICE_LIMIT 1.0e9

_Static_assert(GR_NOISE_RIDGED == GR_PT_KIND_RIDGED && GR_NOISE_FBM == GR_PT_KIND_FBM &&
                   GR_NOISE_BILLOW == GR_PT_KIND_BILLOW,
               "gr_noise_type and the kernel's noise kinds must agree");

struct gr_procedural_terrain {
  gr_context *ctx;
  gr_grid grid;
  gr_procedural_terrain_params params;
  cl_kernel kernel;
  cl_mem elevation;
  cl_mem table;   /* GR_PT_TABLE_STRIDE floats per octave: origin fraction and step, x and y */
  cl_mem amp;     /* float per octave */
  cl_mem lattice; /* GR_PT_LATTICE_STRIDE ints per octave: origin lattice cell */
  char error[1024];
};

/* The rows of the parameter table, in the order of the filter's properties. */
enum {
  GR_PT_SEED,
  GR_PT_NOISE_TYPE,
  GR_PT_OCTAVES,
  GR_PT_FREQUENCY,
  GR_PT_LACUNARITY,
  GR_PT_PERSISTENCE,
  GR_PT_OFFSET,
  GR_PT_GAIN,
  GR_PT_SPECTRAL_EXPONENT,
  GR_PT_INVERT,
  GR_PT_HEIGHT_SCALE,
  GR_PT_ROWS
};

/* The one place the ranges are written. Offset is (0, 4] for every noise
 * type: ridged noise is all zero at offset 0 (every octave's weight is
 * offset^2), and a range that depended on NoiseType could not be one XML
 * domain or one clamp. Octaves stops at 16: at Lacunarity 2 that spans
 * 2^15 from the first octave to the last, which takes a grid-wide first
 * octave down to the 2-cell Nyquist wavelength on the largest grid the core
 * allows (4e9 points, about 63000 per side); more octaves could only alias. */
static const gr_param_bound gr_pt_bounds[GR_PT_ROWS] = {
    {"Seed", "", (double)INT_MIN, (double)INT_MAX, 0.0, 1.0, 0, 1},
    {"NoiseType", "", GR_NOISE_RIDGED, GR_NOISE_BILLOW, GR_NOISE_RIDGED, 1.0, 0, 1},
    {"Octaves", "", GR_PROCEDURAL_TERRAIN_OCTAVES_MIN, GR_PROCEDURAL_TERRAIN_OCTAVES_MAX, 6.0, 1.0,
     0, 1},
    {"Frequency", "cycles/km", 0.0, 1e4, 4.0, 1.0, 1, 0},
    {"Lacunarity", "", 1.0, 8.0, 2.0, 1.0, 0, 0},
    {"Persistence", "", 0.0, 1.0, 0.5, 1.0, 0, 0},
    {"Offset", "", 0.0, 4.0, 1.0, 1.0, 1, 0},
    {"Gain", "", 0.0, 16.0, 2.0, 1.0, 0, 0},
    {"SpectralExponent", "", 0.0, 4.0, 1.0, 1.0, 0, 0},
    {"Invert", "", 0.0, 1.0, 1.0, 1.0, 0, 1},
    {"HeightScale", "m", 0.0, 1e5, 120.0, 1.0, 0, 0},
};

/* What a row means, where its name alone does not say it. */
static const char *const gr_pt_hints[GR_PT_ROWS] = {
    [GR_PT_NOISE_TYPE] = " (0 ridged multifractal, 1 fBm, 2 billow)",
    [GR_PT_SPECTRAL_EXPONENT] = " (the ridged spectral exponent H)",
    [GR_PT_INVERT] = " (0 or 1)",
};

const gr_param_bound *gr_procedural_terrain_param_bounds(int *count) {
  if (count)
    *count = GR_PT_ROWS;
  return gr_pt_bounds;
}

/* The parameter of a row, in the user's unit (the table's to_core is 1 for
 * every row: the core takes the filter's values as they are). */
static double gr_pt_get(const gr_procedural_terrain_params *p, int row) {
  switch (row) {
  case GR_PT_SEED:
    return p->seed;
  case GR_PT_NOISE_TYPE: {
    int type; /* any bit pattern a caller stored, read as the int it is */
    memcpy(&type, &p->type, sizeof(type));
    return type;
  }
  case GR_PT_OCTAVES:
    return p->octaves;
  case GR_PT_FREQUENCY:
    return p->frequency;
  case GR_PT_LACUNARITY:
    return p->lacunarity;
  case GR_PT_PERSISTENCE:
    return p->persistence;
  case GR_PT_OFFSET:
    return p->offset;
  case GR_PT_GAIN:
    return p->gain;
  case GR_PT_SPECTRAL_EXPONENT:
    return p->h;
  case GR_PT_INVERT:
    return p->invert;
  default:
    return p->height_scale;
  }
}

void gr_procedural_terrain_params_init(gr_procedural_terrain_params *p) {
  if (!p)
    return;
  memset(p, 0, sizeof(*p));
  const gr_param_bound *b = gr_pt_bounds;
  p->seed = (int)b[GR_PT_SEED].default_value;
  p->type = (gr_noise_type)(int)b[GR_PT_NOISE_TYPE].default_value;
  p->octaves = (int)b[GR_PT_OCTAVES].default_value;
  p->frequency = b[GR_PT_FREQUENCY].default_value;
  p->lacunarity = b[GR_PT_LACUNARITY].default_value;
  p->persistence = b[GR_PT_PERSISTENCE].default_value;
  p->offset = b[GR_PT_OFFSET].default_value;
  p->gain = b[GR_PT_GAIN].default_value;
  p->h = b[GR_PT_SPECTRAL_EXPONENT].default_value;
  p->invert = (int)b[GR_PT_INVERT].default_value;
  p->height_scale = b[GR_PT_HEIGHT_SCALE].default_value;
}

gr_status gr_procedural_terrain_params_validate(const gr_procedural_terrain_params *p, char *msg,
                                                size_t msg_len) {
  const char *what = "Invalid terrain noise parameters";
  if (!p)
    return gr_params_missing(what, msg, msg_len);
  double values[GR_PT_ROWS];
  for (int row = 0; row < GR_PT_ROWS; ++row)
    values[row] = gr_pt_get(p, row);
  return gr_params_check_table(gr_pt_bounds, NULL, GR_PT_ROWS, values, what, gr_pt_hints,
                               GR_PARAM_SAY_IS_RANGE, msg, msg_len);
}

/* Fills the per-octave tables in double, so every device gets the same
 * float inputs. Fails when a lattice coordinate would leave int range. */
static gr_status gr_procedural_terrain_upload(gr_procedural_terrain *t) {
  const gr_procedural_terrain_params *p = &t->params;
  const gr_grid *g = &t->grid;
  cl_float table[GR_PROCEDURAL_TERRAIN_OCTAVES_MAX * GR_PT_TABLE_STRIDE];
  cl_float amp[GR_PROCEDURAL_TERRAIN_OCTAVES_MAX];
  cl_int lattice[GR_PROCEDURAL_TERRAIN_OCTAVES_MAX * GR_PT_LATTICE_STRIDE];
  memset(table, 0, sizeof(table));
  memset(amp, 0, sizeof(amp));
  memset(lattice, 0, sizeof(lattice));
  double f = p->frequency / 1000.0; /* cycles per metre */
  double ridged_step = pow(p->lacunarity, -p->h);
  double m = 1.0, a = 1.0;
  for (int o = 0; o < p->octaves; ++o) {
    /* The octave's shift (procedural_terrain_shared.h): no lattice line
     * shared by every octave on the world axes. */
    double sx = 0.25 + GR_PT_SHIFT_STEP_X * o, sy = 0.25 + GR_PT_SHIFT_STEP_Y * o;
    double X = g->x0 * f * m + (sx - floor(sx)), Y = g->y0 * f * m + (sy - floor(sy));
    double ext_x = fabs(X) + ((double)g->i0 + g->nx) * g->dx * f * m;
    double ext_y = fabs(Y) + ((double)g->j0 + g->ny) * g->dy * f * m;
    if (ext_x > GR_LATTICE_LIMIT || ext_y > GR_LATTICE_LIMIT)
      return gr_set_error(t->ctx, GR_ERR_INVALID_ARGUMENT,
                          "Invalid terrain noise parameters: octave %d would need lattice "
                          "coordinates beyond %.0e (origin or extent times Frequency times "
                          "Lacunarity^%d is too large); lower Frequency, Octaves or move "
                          "the Origin closer to 0.",
                          o + 1, GR_LATTICE_LIMIT, o);
    double lx = floor(X), ly = floor(Y);
    cl_float *row = table + GR_PT_TABLE_STRIDE * o;
    cl_int *cell = lattice + GR_PT_LATTICE_STRIDE * o;
    row[0] = (cl_float)(X - lx);
    row[1] = (cl_float)(Y - ly);
    row[2] = (cl_float)(g->dx * f * m);
    row[3] = (cl_float)(g->dy * f * m);
    cell[0] = (cl_int)lx;
    cell[1] = (cl_int)ly;
    amp[o] = (cl_float)a;
    a *= p->type == GR_NOISE_RIDGED ? ridged_step : p->persistence;
    m *= p->lacunarity;
  }
  gr_status st = gr_buffer_write(t->ctx, t->table, 0, sizeof(table), table);
  if (st == GR_OK)
    st = gr_buffer_write(t->ctx, t->amp, 0, sizeof(amp), amp);
  if (st == GR_OK)
    st = gr_buffer_write(t->ctx, t->lattice, 0, sizeof(lattice), lattice);
  return st;
}

/* The kernel variant for p's octave count and noise type. */
static gr_status gr_pt_kernel(gr_context *ctx, const gr_procedural_terrain_params *p,
                              cl_kernel *out) {
  cl_program prog = NULL;
  char options[96];
  snprintf(options, sizeof(options), "-DGR_TERRAIN_OCTAVES=%d -DGR_TERRAIN_KIND=%d", p->octaves,
           (int)p->type);
  gr_status st = gr_program_get(ctx, "procedural_terrain", options, &prog);
  if (st == GR_OK)
    st = gr_kernel_create(ctx, prog, "procedural_terrain_generate", out);
  return st;
}

/* The octave tables' bytes (three small read-only buffers). */
#define GR_PT_TABLE_BYTES                                                                          \
  (GR_PROCEDURAL_TERRAIN_OCTAVES_MAX *                                                             \
   (sizeof(cl_float) * (GR_PT_TABLE_STRIDE + 1) + sizeof(cl_int) * GR_PT_LATTICE_STRIDE))

gr_status gr_procedural_terrain_memory(const gr_grid *grid, gr_memory_need *out) {
  if (!grid || !out)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_procedural_terrain_memory needs a grid and a place for the answer.");
  double points = (double)grid->nx * (double)grid->ny;
  memset(out, 0, sizeof(*out));
  out->points = points;
  out->largest = sizeof(cl_float) * points;
  out->device = out->largest + (double)GR_PT_TABLE_BYTES;
  return GR_OK;
}

gr_status gr_procedural_terrain_create(gr_context *ctx, const gr_grid *grid,
                                       const gr_procedural_terrain_params *p,
                                       gr_procedural_terrain **out) {
  char msg[256];
  if (!ctx || !out)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_procedural_terrain_create needs a context and a place "
                        "for the generator.");
  *out = NULL;
  if (gr_grid_validate(grid, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  if (gr_procedural_terrain_params_validate(p, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  gr_memory_need need;
  gr_procedural_terrain_memory(grid, &need);
  if (gr_memory_check(ctx, &need, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_TOO_LARGE,
                        "The procedural terrain of a %d x %d grid %s: use a smaller grid or "
                        "another device.",
                        grid->nx, grid->ny, msg);

  gr_procedural_terrain *t = calloc(1, sizeof(*t));
  if (!t)
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  t->ctx = gr_context_retain(ctx);
  t->grid = *grid;
  t->params = *p;
  size_t bytes = (size_t)grid->nx * (size_t)grid->ny * sizeof(cl_float);
  gr_status st = gr_pt_kernel(ctx, p, &t->kernel);
  if (st == GR_OK)
    st = gr_buffer_create(ctx, CL_MEM_WRITE_ONLY, bytes, NULL, &t->elevation);
  if (st == GR_OK)
    st = gr_buffer_create(ctx, CL_MEM_READ_ONLY,
                          sizeof(cl_float) * GR_PROCEDURAL_TERRAIN_OCTAVES_MAX * GR_PT_TABLE_STRIDE,
                          NULL, &t->table);
  if (st == GR_OK)
    st = gr_buffer_create(ctx, CL_MEM_READ_ONLY,
                          GR_PROCEDURAL_TERRAIN_OCTAVES_MAX * sizeof(cl_float), NULL, &t->amp);
  if (st == GR_OK)
    st = gr_buffer_create(ctx, CL_MEM_READ_ONLY,
                          sizeof(cl_int) * GR_PROCEDURAL_TERRAIN_OCTAVES_MAX * GR_PT_LATTICE_STRIDE,
                          NULL, &t->lattice);
  if (st == GR_OK)
    st = gr_procedural_terrain_upload(t);
  if (st != GR_OK) {
    gr_procedural_terrain_destroy(t);
    return st;
  }
  *out = t;
  return GR_OK;
}

gr_status gr_procedural_terrain_set_params(gr_procedural_terrain *t,
                                           const gr_procedural_terrain_params *p) {
  char msg[256];
  if (!t)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_procedural_terrain_set_params needs a generator.");
  if (gr_procedural_terrain_params_validate(p, msg, sizeof(msg)) != GR_OK)
    return gr_error_keep(t->error, sizeof(t->error),
                         gr_set_error(t->ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg));
  /* Octaves and NoiseType are compiled into the kernel: a change needs the
   * other variant, which replaces the kernel only once everything worked. */
  cl_kernel k = NULL;
  gr_status st = GR_OK;
  if (p->octaves != t->params.octaves || p->type != t->params.type)
    st = gr_pt_kernel(t->ctx, p, &k);
  if (st != GR_OK)
    return gr_error_keep(t->error, sizeof(t->error), st);
  gr_procedural_terrain_params old = t->params;
  t->params = *p;
  st = gr_procedural_terrain_upload(t);
  if (st != GR_OK) {
    char why[sizeof(t->error)];
    snprintf(why, sizeof(why), "%s", gr_last_error(t->ctx));
    t->params = old; /* keep the generator usable with its previous state */
    gr_procedural_terrain_upload(t);
    gr_set_error(t->ctx, st, "%s", why);
    if (k)
      clReleaseKernel(k);
  } else if (k) {
    clReleaseKernel(t->kernel);
    t->kernel = k;
  }
  return gr_error_keep(t->error, sizeof(t->error), st);
}

gr_status gr_procedural_terrain_compute(gr_procedural_terrain *t) {
  if (!t)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_procedural_terrain_compute needs a generator.");
  return gr_procedural_terrain_compute_rows(t, 0, t->grid.ny);
}

gr_status gr_procedural_terrain_compute_rows(gr_procedural_terrain *t, int row0, int nrows) {
  if (!t)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_procedural_terrain_compute_rows needs a generator.");
  if (row0 < 0 || nrows < 0 || row0 > t->grid.ny - nrows)
    return gr_error_keep(t->error, sizeof(t->error),
                         gr_set_error(t->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "Rows %d to %d are not inside the grid's %d rows.", row0,
                                      row0 + nrows - 1, t->grid.ny));
  if (nrows == 0)
    return GR_OK;
  const gr_procedural_terrain_params *p = &t->params;
  /* The kernel's row bound is the band's end, so rounding the launch up to
   * the work-group size never spills into the next band. */
  cl_int nx = t->grid.nx, ny = row0 + nrows, i0 = t->grid.i0, j0 = t->grid.j0;
  cl_uint seed = (cl_uint)p->seed;
  cl_int kind = (cl_int)p->type, octaves = p->octaves, invert = p->invert != 0;
  cl_float offset = (cl_float)p->offset, gain = (cl_float)p->gain;
  cl_float height_scale = (cl_float)p->height_scale;
  cl_mem elevation = t->elevation, table = t->table, amp = t->amp, lattice = t->lattice;
  cl_kernel k = t->kernel;
  gr_context *ctx = t->ctx;
  gr_status st = GR_KERNEL_ARG(ctx, k, elevation);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, nx);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, ny);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, i0);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, j0);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, table);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, amp);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, lattice);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, seed);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, kind);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, octaves);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, offset);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, gain);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, invert);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, height_scale);
  if (st == GR_OK)
    st = gr_enqueue_2d(ctx, k, 0, (size_t)row0, (size_t)nx, (size_t)nrows, NULL);
  return gr_error_keep(t->error, sizeof(t->error), st);
}

gr_status gr_procedural_terrain_get_field(gr_procedural_terrain *t, gr_field f, float *host) {
  if (!t || !host) {
    gr_status st = gr_set_error(t ? t->ctx : NULL, GR_ERR_INVALID_ARGUMENT,
                                "gr_procedural_terrain_get_field needs a generator and "
                                "room for the field.");
    return t ? gr_error_keep(t->error, sizeof(t->error), st) : st;
  }
  if (f != GR_FIELD_ELEVATION)
    return gr_error_keep(t->error, sizeof(t->error),
                         gr_set_error(t->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "The terrain generator has no field '%s'; it makes "
                                      "'elevation' only.",
                                      gr_field_name(f) ? gr_field_name(f) : "(unknown)"));
  size_t bytes = (size_t)t->grid.nx * (size_t)t->grid.ny * sizeof(float);
  return gr_error_keep(t->error, sizeof(t->error),
                       gr_buffer_read(t->ctx, t->elevation, 0, bytes, host));
}

const char *gr_procedural_terrain_last_error(const gr_procedural_terrain *t) {
  return t ? t->error : gr_last_error(NULL);
}

void gr_procedural_terrain_destroy(gr_procedural_terrain *t) {
  if (!t)
    return;
  if (t->kernel)
    clReleaseKernel(t->kernel);
  gr_buffer_release(&t->elevation);
  gr_buffer_release(&t->table);
  gr_buffer_release(&t->amp);
  gr_buffer_release(&t->lattice);
  gr_context_release(t->ctx);
  free(t);
}

gr_status gr_procedural_terrain_generate(gr_context *ctx, const gr_grid *grid,
                                         const gr_procedural_terrain_params *p, float *host) {
  gr_procedural_terrain *t = NULL;
  if (!host)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_procedural_terrain_generate needs room for the field.");
  gr_status st = gr_procedural_terrain_create(ctx, grid, p, &t);
  if (st == GR_OK)
    st = gr_procedural_terrain_compute(t);
  if (st == GR_OK)
    st = gr_procedural_terrain_get_field(t, GR_FIELD_ELEVATION, host);
  gr_procedural_terrain_destroy(t);
  return st;
}
