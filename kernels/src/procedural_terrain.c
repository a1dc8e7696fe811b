/* Procedural terrain core (seed 001): host side of procedural_terrain.cl. */
#include "graupel/procedural_terrain.h"
#include "graupel/cl_runtime.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Lattice coordinates must stay well inside int range in every octave. */
#define GR_LATTICE_LIMIT 1.0e9

struct gr_procedural_terrain {
  gr_context *ctx;
  gr_grid grid;
  gr_procedural_terrain_params params;
  cl_kernel kernel;
  cl_mem elevation;
  cl_mem table;   /* float4 per octave: origin fraction and step, x and y */
  cl_mem amp;     /* float per octave */
  cl_mem lattice; /* int2 per octave: origin lattice cell */
};

void gr_procedural_terrain_params_init(gr_procedural_terrain_params *p) {
  if (!p)
    return;
  memset(p, 0, sizeof(*p));
  p->seed = 0;
  p->type = GR_NOISE_RIDGED;
  p->octaves = 6;
  p->frequency = 4.0;
  p->lacunarity = 2.0;
  p->persistence = 0.5;
  p->offset = 1.0;
  p->gain = 2.0;
  p->h = 1.0;
  p->invert = 1;
  p->height_scale = 120.0;
}

static int gr_in_range(double v, double lo, double hi) {
  return v >= lo && v <= hi; /* false for NaN */
}

gr_status gr_procedural_terrain_params_validate(const gr_procedural_terrain_params *p, char *msg,
                                                size_t msg_len) {
  const char *why = NULL;
  if (!p)
    why = "no parameters were given";
  else if (p->type != GR_NOISE_RIDGED && p->type != GR_NOISE_FBM && p->type != GR_NOISE_BILLOW)
    why = "NoiseType must be 0 (ridged multifractal), 1 (fBm) or 2 (billow)";
  else if (p->octaves < GR_PROCEDURAL_TERRAIN_OCTAVES_MIN ||
           p->octaves > GR_PROCEDURAL_TERRAIN_OCTAVES_MAX)
    why = "Octaves must lie between 1 and 16";
  else if (!(p->frequency > 0.0) || p->frequency > 1e4)
    why = "Frequency must be above 0 and at most 10000 cycles per km";
  else if (!gr_in_range(p->lacunarity, 1.0, 8.0))
    why = "Lacunarity must lie between 1 and 8";
  else if (!gr_in_range(p->persistence, 0.0, 1.0))
    why = "Persistence must lie between 0 and 1";
  else if (!gr_in_range(p->offset, 0.0, 4.0))
    why = "Offset must lie between 0 and 4";
  else if (!gr_in_range(p->gain, 0.0, 16.0))
    why = "Gain must lie between 0 and 16";
  else if (!gr_in_range(p->h, 0.0, 4.0))
    why = "H (the spectral exponent) must lie between 0 and 4";
  else if (!gr_in_range(p->height_scale, 0.0, 1e5))
    why = "HeightScale must lie between 0 and 100000 m";
  else if (p->type == GR_NOISE_RIDGED && p->offset == 0.0)
    why = "Offset must be above 0 for ridged noise (all octaves would vanish)";
  if (!why)
    return GR_OK;
  if (msg && msg_len)
    snprintf(msg, msg_len, "Invalid terrain noise parameters: %s.", why);
  return GR_ERR_INVALID_ARGUMENT;
}

/* Fills the per-octave tables in double, so every device gets the same
 * float inputs. Fails when a lattice coordinate would leave int range. */
static gr_status gr_procedural_terrain_upload(gr_procedural_terrain *t) {
  const gr_procedural_terrain_params *p = &t->params;
  const gr_grid *g = &t->grid;
  cl_float4 table[GR_PROCEDURAL_TERRAIN_OCTAVES_MAX];
  cl_float amp[GR_PROCEDURAL_TERRAIN_OCTAVES_MAX];
  cl_int2 lattice[GR_PROCEDURAL_TERRAIN_OCTAVES_MAX];
  memset(table, 0, sizeof(table));
  memset(amp, 0, sizeof(amp));
  memset(lattice, 0, sizeof(lattice));
  double f = p->frequency / 1000.0; /* cycles per metre */
  double ridged_step = pow(p->lacunarity, -p->h);
  double m = 1.0, a = 1.0;
  for (int o = 0; o < p->octaves; ++o) {
    double X = g->x0 * f * m, Y = g->y0 * f * m;
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
    table[o].s[0] = (cl_float)(X - lx);
    table[o].s[1] = (cl_float)(Y - ly);
    table[o].s[2] = (cl_float)(g->dx * f * m);
    table[o].s[3] = (cl_float)(g->dy * f * m);
    lattice[o].s[0] = (cl_int)lx;
    lattice[o].s[1] = (cl_int)ly;
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

  gr_procedural_terrain *t = calloc(1, sizeof(*t));
  if (!t)
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  t->ctx = gr_context_retain(ctx);
  t->grid = *grid;
  t->params = *p;
  cl_program prog = NULL;
  size_t bytes = (size_t)grid->nx * (size_t)grid->ny * sizeof(cl_float);
  char options[96];
  snprintf(options, sizeof(options), "-DGR_TERRAIN_OCTAVES=%d -DGR_TERRAIN_KIND=%d", p->octaves,
           (int)p->type);
  gr_status st = gr_program_get(ctx, "procedural_terrain", options, &prog);
  if (st == GR_OK)
    st = gr_kernel_create(ctx, prog, "procedural_terrain_generate", &t->kernel);
  if (st == GR_OK)
    st = gr_buffer_create(ctx, CL_MEM_WRITE_ONLY, bytes, NULL, &t->elevation);
  if (st == GR_OK)
    st = gr_buffer_create(ctx, CL_MEM_READ_ONLY,
                          GR_PROCEDURAL_TERRAIN_OCTAVES_MAX * sizeof(cl_float4), NULL, &t->table);
  if (st == GR_OK)
    st = gr_buffer_create(ctx, CL_MEM_READ_ONLY,
                          GR_PROCEDURAL_TERRAIN_OCTAVES_MAX * sizeof(cl_float), NULL, &t->amp);
  if (st == GR_OK)
    st = gr_buffer_create(ctx, CL_MEM_READ_ONLY,
                          GR_PROCEDURAL_TERRAIN_OCTAVES_MAX * sizeof(cl_int2), NULL, &t->lattice);
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
    return gr_set_error(t->ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  gr_procedural_terrain_params old = t->params;
  t->params = *p;
  gr_status st = gr_procedural_terrain_upload(t);
  if (st != GR_OK) {
    t->params = old; /* keep the generator usable with its previous state */
    gr_procedural_terrain_upload(t);
  }
  return st;
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
    return gr_set_error(t->ctx, GR_ERR_INVALID_ARGUMENT,
                        "Rows %d to %d are not inside the grid's %d rows.", row0, row0 + nrows - 1,
                        t->grid.ny);
  if (nrows == 0)
    return GR_OK;
  const gr_procedural_terrain_params *p = &t->params;
  /* The kernel's row bound is the band's end, so rounding the launch up to
   * the work-group size never spills into the next band. */
  cl_int nx = t->grid.nx, ny = row0 + nrows, i0 = t->grid.i0, j0 = t->grid.j0;
  cl_uint seed = (cl_uint)p->seed;
  cl_int kind = (cl_int)p->type, octaves = p->octaves, invert = p->invert != 0;
  cl_float offset = (cl_float)p->offset, gain = (cl_float)p->gain;
  cl_float hs = (cl_float)p->height_scale;
  gr_status st = gr_kernel_args(
      t->ctx, t->kernel, sizeof(cl_mem), &t->elevation, sizeof(cl_int), &nx, sizeof(cl_int), &ny,
      sizeof(cl_int), &i0, sizeof(cl_int), &j0, sizeof(cl_mem), &t->table, sizeof(cl_mem), &t->amp,
      sizeof(cl_mem), &t->lattice, sizeof(cl_uint), &seed, sizeof(cl_int), &kind, sizeof(cl_int),
      &octaves, sizeof(cl_float), &offset, sizeof(cl_float), &gain, sizeof(cl_int), &invert,
      sizeof(cl_float), &hs, (size_t)0);
  if (st != GR_OK)
    return st;
  return gr_enqueue_2d(t->ctx, t->kernel, 0, (size_t)row0, (size_t)nx, (size_t)nrows, NULL);
}

gr_status gr_procedural_terrain_get_field(gr_procedural_terrain *t, gr_field f, float *host) {
  if (!t || !host)
    return gr_set_error(t ? t->ctx : NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_procedural_terrain_get_field needs a generator and "
                        "room for the field.");
  if (f != GR_FIELD_ELEVATION)
    return gr_set_error(t->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The terrain generator has no field '%s'; it makes "
                        "'elevation' only.",
                        gr_field_name(f) ? gr_field_name(f) : "(unknown)");
  size_t bytes = (size_t)t->grid.nx * (size_t)t->grid.ny * sizeof(float);
  return gr_buffer_read(t->ctx, t->elevation, 0, bytes, host);
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
