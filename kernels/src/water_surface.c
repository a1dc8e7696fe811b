/* Water surface core (seed 003's height-field water, seed 004's ripples):
 * host side of water_surface.cl. The model is documented in
 * graupel/water_surface.h; the constants both sides share in
 * water_surface_shared.h. This file: the parameters, the handle, creation,
 * the inputs and the water found from them; stepping and the outputs are in
 * water_surface_step.c, pieces and checkpoints in water_surface_pieces.c
 * (around water_surface_internal.h). */
#include "water_surface_internal.h"

/* set_field's sanity bounds: beyond them float differences overflow. */
#define GR_WS_MAX_ELEVATION 1.0e6
#define GR_WS_MAX_DEPTH 1.0e4

/* The parameter table's rows, in gr_water_surface_param_bounds' order. */
enum {
  GR_WS_P_WAVE_SPEED,
  GR_WS_P_DAMPING,
  GR_WS_P_WET_DEPTH,
  GR_WS_P_USE_LAKE,
  GR_WS_P_LAKE_LEVEL,
  GR_WS_P_DROP_RATE,
  GR_WS_P_DROP_AMPLITUDE,
  GR_WS_P_DROP_RADIUS,
  GR_WS_P_SEED,
  GR_WS_P_CFL,
  GR_WS_P_COUNT
};

/* The one place each range is written. WaveSpeed 1 m/s is sqrt(g d) of 10 cm
 * of water (see the header for why it is fixed); Damping 0.1 /s halves a
 * ripple's energy in 7 s; WetDepth 1 cm, the wetting depth below which
 * runoff films carry no visible waves; the drops: about one per 10 m^2 a
 * second, 5 mm deep and 0.5 m wide, ripples that read at terrain scale.
 * LakeLevel spans the deepest ocean to above any terrain Procedural Terrain
 * makes; the Courant fraction 0.5 keeps the wave speed's dispersion error
 * below 1 % for waves of 8 points per wavelength. */
static const gr_param_bound gr_ws_bounds[GR_WS_P_COUNT] = {
    {"WaveSpeed", "m/s", 0.0, 300.0, 1.0, 1.0, 1, 0},
    {"Damping", "1/s", 0.0, 100.0, 0.1, 1.0, 0, 0},
    {"WetDepth", "m", 0.0, 100.0, 0.01, 1.0, 0, 0},
    {"UseLakeLevel", "", 0.0, 1.0, 0.0, 1.0, 0, 1},
    {"LakeLevel", "m", -1.1e4, 1e5, 0.0, 1.0, 0, 0},
    {"DropRate", "1/(m^2 s)", 0.0, 1000.0, 0.1, 1.0, 0, 0},
    {"DropAmplitude", "m", 0.0, 10.0, 0.005, 1.0, 0, 0},
    {"DropRadius", "m", 0.0, 1000.0, 0.5, 1.0, 1, 0},
    {"Seed", "", 0.0, 2147483647.0, 1.0, 1.0, 0, 1},
    {"CourantNumber", "", 0.0, 1.0, 0.5, 1.0, 1, 0},
};

static const char *const gr_ws_names[GR_WATER_OUTPUT_COUNT] = {
    "wave_height", "normal", "water_surface", "wet", "elevation", "water_depth"};

const char *gr_water_surface_output_name(gr_water_surface_output o) {
  return (int)o >= 0 && o < GR_WATER_OUTPUT_COUNT ? gr_ws_names[o] : NULL;
}

int gr_water_surface_output_components(gr_water_surface_output o) {
  if ((int)o < 0 || o >= GR_WATER_OUTPUT_COUNT)
    return 0;
  return o == GR_WATER_NORMAL ? 3 : 1;
}

const gr_param_bound *gr_water_surface_param_bounds(int *count) {
  if (count)
    *count = GR_WS_P_COUNT;
  return gr_ws_bounds;
}

void gr_water_surface_params_init(gr_water_surface_params *p) {
  if (!p)
    return;
  memset(p, 0, sizeof(*p));
  const gr_param_bound *b = gr_ws_bounds;
  p->wave_speed = b[GR_WS_P_WAVE_SPEED].default_value;
  p->damping = b[GR_WS_P_DAMPING].default_value;
  p->wet_depth = b[GR_WS_P_WET_DEPTH].default_value;
  p->use_lake_level = (int)b[GR_WS_P_USE_LAKE].default_value;
  p->lake_level = b[GR_WS_P_LAKE_LEVEL].default_value;
  p->drop_rate = b[GR_WS_P_DROP_RATE].default_value;
  p->drop_amplitude = b[GR_WS_P_DROP_AMPLITUDE].default_value;
  p->drop_radius = b[GR_WS_P_DROP_RADIUS].default_value;
  p->seed = (int)b[GR_WS_P_SEED].default_value;
  p->cfl = b[GR_WS_P_CFL].default_value;
}

static double gr_ws_param_value(const gr_water_surface_params *p, int row) {
  switch (row) {
  case GR_WS_P_WAVE_SPEED:
    return p->wave_speed;
  case GR_WS_P_DAMPING:
    return p->damping;
  case GR_WS_P_WET_DEPTH:
    return p->wet_depth;
  case GR_WS_P_USE_LAKE:
    return p->use_lake_level;
  case GR_WS_P_LAKE_LEVEL:
    return p->lake_level;
  case GR_WS_P_DROP_RATE:
    return p->drop_rate;
  case GR_WS_P_DROP_AMPLITUDE:
    return p->drop_amplitude;
  case GR_WS_P_DROP_RADIUS:
    return p->drop_radius;
  case GR_WS_P_SEED:
    return p->seed;
  default:
    return p->cfl;
  }
}

gr_status gr_water_surface_params_validate(const gr_water_surface_params *p, char *msg,
                                           size_t msg_len) {
  const char *what = "Invalid water surface parameters";
  if (!p)
    return gr_params_missing(what, msg, msg_len);
  double values[GR_WS_P_COUNT];
  for (int row = 0; row < GR_WS_P_COUNT; ++row)
    values[row] = gr_ws_param_value(p, row);
  return gr_params_check_table(gr_ws_bounds, NULL, GR_WS_P_COUNT, values, what, NULL,
                               GR_PARAM_SAY_GOT, msg, msg_len);
}

/* ------------------------------------------------------------- the handle */

const char *gr_water_surface_last_error(const gr_water_surface *s) {
  return s ? s->error : "";
}

int gr_water_surface_ghost(const gr_water_surface_params *p, double dy) {
  if (!p || !(dy > 0.0) || !(p->drop_radius > 0.0))
    return 0;
  return 1 + gr_ws_reach(p->drop_radius, dy);
}

gr_status gr_ws_args(gr_water_surface *s, cl_kernel k, const gr_ws_arg *args, size_t n) {
  gr_status st = GR_OK;
  for (size_t i = 0; st == GR_OK && i < n; ++i)
    st = gr_kernel_arg(s->ctx, k, args[i].name, args[i].size, args[i].value);
  return st;
}

gr_status gr_ws_fill(gr_water_surface *s, cl_mem buf, float value, size_t bytes) {
  return gr_cl_check(s->ctx,
                     clEnqueueFillBuffer(gr_context_queue(s->ctx), buf, &value, sizeof(value), 0,
                                         bytes, 0, NULL, NULL),
                     "Filling a device buffer");
}

void gr_water_surface_destroy(gr_water_surface *s) {
  if (!s)
    return;
  cl_kernel kernels[] = {s->step, s->reduce, s->derive};
  for (size_t i = 0; i < sizeof(kernels) / sizeof(kernels[0]); ++i)
    if (kernels[i])
      clReleaseKernel(kernels[i]);
  cl_mem *bufs[] = {&s->h[0], &s->h[1], &s->v, &s->wet, &s->base, &s->h0, &s->scratch};
  for (size_t i = 0; i < sizeof(bufs) / sizeof(bufs[0]); ++i)
    gr_buffer_release(bufs[i]);
  gr_reduction_i64_release(&s->ledger);
  free(s->elevation);
  free(s->depth);
  gr_context_release(s->ctx);
  free(s);
}

/* ---------------------------------------------------- creation and inputs */

gr_status gr_water_surface_memory(const gr_grid *grid, gr_memory_need *out) {
  if (!grid || !out)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_water_surface_memory needs a grid and a place for the answer.");
  /* A piece's ring (at most grid->ghost rows each way). */
  double n = (double)grid->nx * ((double)grid->ny + 2.0 * (grid->ghost > 0 ? grid->ghost : 0));
  memset(out, 0, sizeof(*out));
  out->points = (double)grid->nx * (double)grid->ny;
  /* h twice, v, base, h0 and the scratch's 3: 8 floats and a byte a point. */
  out->device = (8.0 * 4.0 + 1.0) * n;
  out->largest = 3.0 * 4.0 * n; /* the scratch */
  out->host = (4.0 + 4.0 + 4.0 + 1.0) * n;
  out->state = 2.0 * sizeof(float) * n; /* gr_ws_state_bytes */
  return GR_OK;
}

gr_status gr_water_surface_create(gr_context *ctx, const gr_grid *grid,
                                  const gr_water_surface_params *p, gr_water_surface **out) {
  char msg[256];
  if (!ctx || !out)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_water_surface_create needs a context and a place for the simulation.");
  *out = NULL;
  if (gr_grid_validate(grid, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  if (gr_water_surface_params_validate(p, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  int ring_s = 0, ring_n = 0;
  if (gr_ws_piece_check(grid, p, &ring_s, &ring_n, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  size_t n = (size_t)grid->nx * ((size_t)grid->ny + (size_t)ring_s + (size_t)ring_n);
  if ((double)n > (double)INT_MAX - 1048576.0)
    return gr_set_error(ctx, GR_ERR_TOO_LARGE,
                        "The water surface grid of %d x %d points is too large: the kernels "
                        "address at most about 2.1e9 points; coarsen it.",
                        grid->nx, grid->ny);
  gr_memory_need need;
  gr_water_surface_memory(grid, &need);
  if (gr_memory_check(ctx, &need, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_TOO_LARGE,
                        "The water surface of a %d x %d grid %s: use a smaller grid or another "
                        "device.",
                        grid->nx, grid->ny, msg);
  gr_water_surface *s = calloc(1, sizeof(*s));
  if (!s)
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  s->ctx = gr_context_retain(ctx);
  s->grid = *grid;
  s->gny = grid->global_ny > 0 ? grid->global_ny : grid->ny;
  s->own_ny = grid->ny;
  s->ring_s = ring_s, s->ring_n = ring_n;
  s->row0 = grid->j0 - ring_s;
  s->grid.ny = grid->ny + ring_s + ring_n;
  s->params = *p;
  s->elevation = calloc(n, sizeof(float));
  if (!s->elevation) {
    gr_water_surface_destroy(s);
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  size_t fb = n * sizeof(cl_float), tile3[3] = {0, 0, 0};
  cl_program prog = NULL;
  gr_status st = gr_program_get(ctx, "water_surface", NULL, &prog);
  if (st == GR_OK)
    st = gr_kernel_create(ctx, prog, "water_surface_step", &s->step);
  if (st == GR_OK)
    st = gr_cl_check(ctx,
                     clGetKernelWorkGroupInfo(s->step, gr_context_device(ctx),
                                              CL_KERNEL_COMPILE_WORK_GROUP_SIZE, 3 * sizeof(size_t),
                                              tile3, NULL),
                     "Asking the water surface step for its work-group");
  s->tile[0] = tile3[0], s->tile[1] = tile3[1];
  if (st == GR_OK)
    st = gr_kernel_create(ctx, prog, "water_surface_reduce", &s->reduce);
  if (st == GR_OK)
    st = gr_kernel_create(ctx, prog, "water_surface_derive", &s->derive);
  cl_mem *floats[] = {&s->h[0], &s->h[1], &s->v, &s->base};
  for (size_t i = 0; st == GR_OK && i < sizeof(floats) / sizeof(floats[0]); ++i)
    st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, fb, NULL, floats[i]);
  if (st == GR_OK)
    st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, n, NULL, &s->wet);
  if (st == GR_OK)
    st = gr_reduction_i64_init_max(ctx, s->reduce, n, GR_WATER_SURFACE_WORDS,
                                   GR_WATER_SURFACE_MAXES, &s->ledger);
  for (size_t i = 0; st == GR_OK && i < sizeof(floats) / sizeof(floats[0]); ++i)
    st = gr_ws_fill(s, *floats[i], 0.0f, fb);
  if (st == GR_OK)
    st = gr_finish(ctx);
  if (st != GR_OK) {
    gr_water_surface_destroy(s);
    return st;
  }
  *out = s;
  return GR_OK;
}

gr_status gr_water_surface_set_params(gr_water_surface *s, const gr_water_surface_params *p) {
  char msg[256];
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_water_surface_set_params needs a simulation.");
  if (gr_water_surface_params_validate(p, msg, sizeof(msg)) != GR_OK)
    return GR_WS_KEEP(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg));
  int need = gr_water_surface_ghost(p, s->grid.dy);
  if (gr_ws_pieced(s) && need > s->grid.ghost)
    return GR_WS_KEEP(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "Invalid water surface parameters: DropRadius %g m needs a "
                                      "ghost ring of %d rows but this piece has %d; keep "
                                      "DropRadius smaller or make the piece again with a wider "
                                      "ring.",
                                      p->drop_radius, need, s->grid.ghost));
  s->params = *p;
  s->water_ready = 0;
  s->initial_known = s->initial_known && s->steps > 0;
  return GR_OK;
}

/* Checks an input's floats: finite and within [lo, hi]; names the point. */
static gr_status gr_ws_check(gr_water_surface *s, const char *what, const float *host, double lo,
                             double hi, const char *rule) {
  const int nx = s->grid.nx;
  size_t n = gr_ws_points(s);
  for (size_t c = 0; c < n; ++c) {
    double v = host[c];
    if (isfinite(v) && v >= lo && v <= hi)
      continue;
    return gr_set_error(
        s->ctx, GR_ERR_INVALID_ARGUMENT, "The water surface's %s has %s at point (%zu, %zu): %s.",
        what, isnan(v) ? "NaN" : (isinf(v) ? "an infinite value" : "a value out of range"),
        c % (size_t)nx, c / (size_t)nx + (size_t)s->row0, rule);
  }
  return GR_OK;
}

static gr_status gr_ws_set_field_impl(gr_water_surface *s, gr_field f, const float *host) {
  size_t n = gr_ws_points(s);
  gr_status st;
  switch (f) {
  case GR_FIELD_ELEVATION:
    st = gr_ws_check(s, "elevation", host, -GR_WS_MAX_ELEVATION, GR_WS_MAX_ELEVATION,
                     "every elevation must be a finite number of metres within +-1e6 m");
    if (st == GR_OK)
      memcpy(s->elevation, host, n * sizeof(float));
    break;
  case GR_FIELD_WATER_DEPTH:
    st = gr_ws_check(s, "water_depth", host, 0.0, GR_WS_MAX_DEPTH,
                     "every depth must be a finite number of metres from 0 to 1e4 m");
    if (st == GR_OK && !s->depth && !(s->depth = malloc(n * sizeof(float))))
      st = gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
    if (st == GR_OK) {
      memcpy(s->depth, host, n * sizeof(float));
      s->has_depth = 1;
    }
    break;
  default:
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The field '%s' is not an input of the water surface; its inputs are "
                        "elevation and water_depth.",
                        gr_field_name(f) ? gr_field_name(f) : "(unknown field)");
  }
  if (st == GR_OK)
    s->water_ready = 0;
  return st;
}

gr_status gr_water_surface_set_field(gr_water_surface *s, gr_field f, const float *host) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_water_surface_set_field needs a simulation and the field's values.");
  if (!host)
    return GR_WS_KEEP(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "gr_water_surface_set_field needs a simulation and the "
                                      "field's values."));
  return GR_WS_KEEP(s, gr_ws_set_field_impl(s, f, host));
}

/* The lake's mode: a lake when asked for, else the depth when given. */
int gr_ws_lake(const gr_water_surface *s) {
  return s->params.use_lake_level != 0;
}

/* Finds the wet points and the still surface from the inputs and the
 * parameters, and uploads them; refuses no water with a sentence. Water
 * with no wet point is not refused: runoff that has not gathered yet is
 * dry, and nothing moves. */
gr_status gr_ws_prepare(gr_water_surface *s) {
  if (s->water_ready)
    return GR_OK;
  const gr_water_surface_params *p = &s->params;
  int lake = gr_ws_lake(s);
  if (!lake && !s->has_depth)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The water surface has no water: give it a water depth (water_depth, "
                        "e.g. Rain Runoff's output) or turn UseLakeLevel on with a LakeLevel "
                        "above the ground.");
  size_t n = gr_ws_points(s);
  unsigned char *wet = malloc(n);
  float *base = malloc(n * sizeof(float));
  if (!wet || !base) {
    free(wet);
    free(base);
    return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  float level = (float)p->lake_level, threshold = (float)p->wet_depth;
  long long count = 0;
  for (size_t c = 0; c < n; ++c) {
    float b = s->elevation[c];
    int w;
    if (lake) {
      w = b < level;
      base[c] = w ? level : b;
    } else {
      float d = s->depth[c];
      w = d > threshold;
      base[c] = b + d;
    }
    wet[c] = (unsigned char)w;
    count += w && c >= gr_ws_own_first(s) && c < gr_ws_own_first(s) + gr_ws_own_points(s);
  }
  gr_status st = GR_OK;
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, s->wet, 0, n, wet);
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, s->base, 0, n * sizeof(float), base);
  free(wet);
  free(base);
  if (st == GR_OK) {
    s->water_ready = 1;
    s->wet_points = count;
  }
  return st;
}

/* The ledger's device sums (wave, energy per area, wet count) and max |h|
 * over the own points. The sums are fixed-point integers (reduce.h), and a
 * piece adds the other pieces' through the allreduce as exact 32-bit parts
 * (gr_fixed_pack): the same bits for the whole grid and any split. */
gr_status gr_ws_reduce(gr_water_surface *s, double sums[3], double *max_wave) {
  const gr_grid *g = &s->grid;
  cl_int n = (cl_int)gr_ws_points(s), nx = g->nx, ny = g->ny;
  cl_int own_y0 = s->ring_s, own_y1 = s->ring_s + s->own_ny;
  cl_float c2 = (cl_float)(s->params.wave_speed * s->params.wave_speed);
  cl_float half_dt_c2 = (cl_float)(0.5 * s->last_dt * s->params.wave_speed * s->params.wave_speed);
  cl_float inv_dx2 = (cl_float)(1.0 / (g->dx * g->dx)), inv_dy2 = (cl_float)(1.0 / (g->dy * g->dy));
  const size_t m = sizeof(cl_mem);
  const gr_ws_arg args[] = {
      {"h", m, &s->h[s->cur]},
      {"v", m, &s->v},
      {"wet", m, &s->wet},
      {"n", sizeof(n), &n},
      {"nx", sizeof(nx), &nx},
      {"ny", sizeof(ny), &ny},
      {"own_y0", sizeof(own_y0), &own_y0},
      {"own_y1", sizeof(own_y1), &own_y1},
      {"c2", sizeof(c2), &c2},
      {"half_dt_c2", sizeof(half_dt_c2), &half_dt_c2},
      {"inv_dx2", sizeof(inv_dx2), &inv_dx2},
      {"inv_dy2", sizeof(inv_dy2), &inv_dy2},
  };
  long long words[GR_WATER_SURFACE_WORDS], maxes[GR_WATER_SURFACE_MAXES];
  gr_status st = GR_WS_ARGS(s, s->reduce, args);
  if (st == GR_OK)
    st = gr_reduction_i64_run_max(s->ctx, &s->ledger, s->reduce, words, maxes);
  if (st != GR_OK)
    return st;
  /* The largest |h|, by its float's bits (never below +0). */
  int32_t bits = (int32_t)maxes[0];
  float largest;
  memcpy(&largest, &bits, sizeof(largest));
  double hmax = largest;
  if (gr_ws_pieced(s) && s->allreduce) {
    double packed[GR_FIXED_PACKED(GR_WATER_SURFACE_WORDS, 0)];
    gr_fixed_pack(words, GR_WATER_SURFACE_WORDS, NULL, 0, packed);
    st = gr_ws_allreduce(s, packed, GR_FIXED_PACKED(GR_WATER_SURFACE_WORDS, 0), GR_REDUCE_SUM);
    if (st == GR_OK)
      st = gr_ws_allreduce(s, &hmax, 1, GR_REDUCE_MAX);
    if (st != GR_OK)
      return st;
    gr_fixed_unpack(packed, words, GR_WATER_SURFACE_WORDS, NULL, 0);
  }
  gr_fixed wave = {words[0], words[1]}, energy = {words[2], words[3]};
  sums[0] = gr_fixed_value(wave);
  sums[1] = gr_fixed_value(energy);
  sums[2] = (double)words[4];
  if (max_wave)
    *max_wave = hmax;
  return GR_OK;
}

/* Records the wave's sum at time 0 when it is not known yet. */
gr_status gr_ws_know_initial(gr_water_surface *s) {
  if (s->initial_known || s->steps > 0)
    return GR_OK;
  double sums[3];
  gr_status st = gr_ws_reduce(s, sums, NULL);
  if (st == GR_OK) {
    s->initial_sum = sums[0];
    s->initial_known = 1;
  }
  return st;
}

static gr_status gr_ws_set_wave_impl(gr_water_surface *s, const float *host) {
  size_t bytes = gr_ws_points(s) * sizeof(float);
  gr_status st = gr_ws_check(s, "wave height", host, -GR_WS_MAX_WAVE, GR_WS_MAX_WAVE,
                             "every wave height must be a finite number of metres within +-1e4 m");
  if (st == GR_OK)
    st = s->h0 ? gr_buffer_write(s->ctx, s->h0, 0, bytes, host)
               : gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, bytes, (void *)host, &s->h0);
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, s->h[s->cur], 0, bytes, host);
  if (st == GR_OK)
    st = gr_ws_fill(s, s->v, 0.0f, bytes);
  if (st == GR_OK)
    s->initial_known = 0;
  return st;
}

gr_status gr_water_surface_set_wave(gr_water_surface *s, const float *host) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_water_surface_set_wave needs a simulation and the wave heights.");
  if (!host)
    return GR_WS_KEEP(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "gr_water_surface_set_wave needs a simulation and the wave "
                                      "heights."));
  return GR_WS_KEEP(s, gr_ws_set_wave_impl(s, host));
}
