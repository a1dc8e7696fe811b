/* Rain runoff core (seed 004's water simulation): host side of
 * rain_runoff.cl. The model, the step order and the book-keeping are
 * documented in graupel/rain_runoff.h; the kernels' data layout in
 * rain_runoff_li.cl and rain_runoff_sw.cl (the two flow models' parts of
 * rain_runoff.cl); the constants both sides share in rain_runoff_shared.h;
 * the handle and the helpers the host files share in
 * rain_runoff_internal.h. This file: the parameter table and its checks,
 * the field checks, and the handle's life cycle (memory, create, destroy,
 * set_params, reset). */
#include "rain_runoff_internal.h"
#include "runtime_internal.h"

/* The one place each range is written: the validator, the field checks, the
 * filter's clamps, the XML domains and the README follow it. */
const gr_param_bound gr_rain_runoff_bounds[GR_RAIN_RUNOFF_P_COUNT] = {
    {"RainRate", "mm/h", 0.0, 3600.0, 100.0, 1.0 / 3.6e6, 0, 0},
    {"Permeability", "mm/h", 0.0, 36000.0, 0.0, 1.0 / 3.6e6, 0, 0},
    {"ManningN", "s/m^(1/3)", 0.0, 1.0, 0.03, 1.0, 0, 0},
    {"MaxTimeStep", "s", 0.0, 3600.0, 3600.0, 1.0, 1, 0},
    {"CourantNumber", "", 0.0, 1.0, 0.7, 1.0, 1, 0},
    {"BoundaryWest", "", 0.0, 3.0, 0.0, 1.0, 0, 1},
    {"BoundaryEast", "", 0.0, 3.0, 0.0, 1.0, 0, 1},
    {"BoundarySouth", "", 0.0, 3.0, 0.0, 1.0, 0, 1},
    {"BoundaryNorth", "", 0.0, 3.0, 0.0, 1.0, 0, 1},
    {"LevelWest", "m", -1.0e6, 1.0e6, 0.0, 1.0, 0, 0},
    {"LevelEast", "m", -1.0e6, 1.0e6, 0.0, 1.0, 0, 0},
    {"LevelSouth", "m", -1.0e6, 1.0e6, 0.0, 1.0, 0, 0},
    {"LevelNorth", "m", -1.0e6, 1.0e6, 0.0, 1.0, 0, 0},
    {"FlowModel", "", 0.0, 1.0, 0.0, 1.0, 0, 1},
    {"WettingDepth", "m", 0.0, 10.0, 0.01, 1.0, 1, 0},
    {"DebrisFactor", "", 0.0, 1.0, 0.0, 1.0, 0, 0},
    {"NoDataBoundary", "", 0.0, 1.0, 1.0, 1.0, 0, 1},
};

/* A row's range in the core's unit: exactly the products a caller gets from
 * the user's bounds times to_core, so the user's own bounds are accepted. */
static double gr_rain_runoff_core_min(int row) {
  return gr_rain_runoff_bounds[row].min * gr_rain_runoff_bounds[row].to_core;
}
double gr_rain_runoff_core_max(int row) {
  return gr_rain_runoff_bounds[row].max * gr_rain_runoff_bounds[row].to_core;
}

const gr_param_bound *gr_rain_runoff_param_bounds(int *count) {
  if (count)
    *count = GR_RAIN_RUNOFF_P_COUNT;
  return gr_rain_runoff_bounds;
}

const char *gr_rain_runoff_last_error(const gr_rain_runoff *s) {
  return s ? s->error : "";
}

void gr_rain_runoff_params_init(gr_rain_runoff_params *p) {
  if (!p)
    return;
  memset(p, 0, sizeof(*p));
  const gr_param_bound *t = gr_rain_runoff_bounds;
  p->rain_rate =
      t[GR_RAIN_RUNOFF_P_RAIN_RATE].default_value * t[GR_RAIN_RUNOFF_P_RAIN_RATE].to_core;
  p->permeability =
      t[GR_RAIN_RUNOFF_P_PERMEABILITY].default_value * t[GR_RAIN_RUNOFF_P_PERMEABILITY].to_core;
  p->manning_n = t[GR_RAIN_RUNOFF_P_MANNING_N].default_value;
  p->max_dt = t[GR_RAIN_RUNOFF_P_MAX_DT].default_value;
  p->cfl = t[GR_RAIN_RUNOFF_P_CFL].default_value;
  for (int e = 0; e < 4; ++e) {
    p->boundary[e] = (gr_boundary)(int)t[GR_RAIN_RUNOFF_P_BOUNDARY + e].default_value;
    p->boundary_level[e] = t[GR_RAIN_RUNOFF_P_LEVEL + e].default_value;
  }
  p->flow_model = (gr_flow_model)(int)t[GR_RAIN_RUNOFF_P_FLOW_MODEL].default_value;
  p->wetting_depth = t[GR_RAIN_RUNOFF_P_WETTING_DEPTH].default_value;
  p->debris_factor = t[GR_RAIN_RUNOFF_P_DEBRIS_FACTOR].default_value;
  p->no_data = (gr_boundary)(int)t[GR_RAIN_RUNOFF_P_NO_DATA].default_value;
}

/* The core's value of row `row` in p. */
static double gr_rain_runoff_param_value(const gr_rain_runoff_params *p, int row) {
  switch (row) {
  case GR_RAIN_RUNOFF_P_RAIN_RATE:
    return p->rain_rate;
  case GR_RAIN_RUNOFF_P_PERMEABILITY:
    return p->permeability;
  case GR_RAIN_RUNOFF_P_MANNING_N:
    return p->manning_n;
  case GR_RAIN_RUNOFF_P_MAX_DT:
    return p->max_dt;
  case GR_RAIN_RUNOFF_P_CFL:
    return p->cfl;
  case GR_RAIN_RUNOFF_P_WETTING_DEPTH:
    return p->wetting_depth;
  case GR_RAIN_RUNOFF_P_DEBRIS_FACTOR:
    return p->debris_factor;
  case GR_RAIN_RUNOFF_P_NO_DATA: {
    int k; /* any bit pattern the enum may hold */
    memcpy(&k, &p->no_data, sizeof(k));
    return (double)k;
  }
  case GR_RAIN_RUNOFF_P_FLOW_MODEL: {
    int m; /* any bit pattern the enum may hold */
    memcpy(&m, &p->flow_model, sizeof(m));
    return (double)m;
  }
  default:
    if (row >= GR_RAIN_RUNOFF_P_LEVEL)
      return p->boundary_level[row - GR_RAIN_RUNOFF_P_LEVEL];
    else {
      int b; /* any bit pattern the enum may hold */
      memcpy(&b, &p->boundary[row - GR_RAIN_RUNOFF_P_BOUNDARY], sizeof(b));
      return (double)b;
    }
  }
}

gr_status gr_rain_runoff_params_validate(const gr_rain_runoff_params *p, char *msg,
                                         size_t msg_len) {
  const char *what = "Invalid rain runoff parameters";
  if (!p)
    return gr_params_missing(what, msg, msg_len);
  double values[GR_RAIN_RUNOFF_P_COUNT];
  for (int row = 0; row < GR_RAIN_RUNOFF_P_COUNT; ++row)
    values[row] = gr_rain_runoff_param_value(p, row);
  if (gr_params_check_table(gr_rain_runoff_bounds, NULL, GR_RAIN_RUNOFF_P_COUNT, values, what, NULL,
                            GR_PARAM_SAY_GOT, msg, msg_len) != GR_OK)
    return GR_ERR_INVALID_ARGUMENT;
  if (p->flow_model == GR_FLOW_LOCAL_INERTIAL && p->manning_n < GR_RAIN_RUNOFF_LI_MIN_N) {
    if (msg && msg_len)
      snprintf(msg, msg_len,
               "Invalid rain runoff parameters: ManningN must be at least %g s/m^(1/3) for "
               "FlowModel 1 (local inertial) (got %g); raise it, or take FlowModel 0 (shallow "
               "water), which allows 0.",
               GR_RAIN_RUNOFF_LI_MIN_N, p->manning_n);
    return GR_ERR_INVALID_ARGUMENT;
  }
  return GR_OK;
}

const char *gr_rain_runoff_field_label(gr_field f) {
  const char *name = gr_field_name(f);
  return name ? name : "(unknown field)";
}

/* field_validate's checks; with nx > 0 the bad value is named by its cell
 * (i, j), otherwise by its index. strict adds set_field's sanity bounds. */
gr_status gr_rain_runoff_field_check(gr_field f, const float *values, size_t n, size_t nx,
                                     int strict, char *msg, size_t msg_len) {
  const char *rule = NULL;
  char rule_text[160];
  double lo = -HUGE_VAL, hi = HUGE_VAL;
  size_t comps = 1;
  int nan_ok = 0;
  switch (f) {
  case GR_FIELD_ELEVATION:
    /* NaN marks a no-data cell (outside the domain); infinities are refused. */
    nan_ok = 1;
    rule = strict ? "elevations must be within +-1e6 m, or NaN for a no-data cell"
                  : "elevations must be finite, or NaN for a no-data cell";
    if (strict) {
      lo = -GR_RAIN_RUNOFF_MAX_ELEVATION;
      hi = GR_RAIN_RUNOFF_MAX_ELEVATION;
    }
    break;
  case GR_FIELD_WATER_SURFACE:
    rule = strict ? "water surfaces must be finite and within +-1e6 m"
                  : "water surfaces must be finite";
    if (strict) {
      lo = -GR_RAIN_RUNOFF_MAX_ELEVATION;
      hi = GR_RAIN_RUNOFF_MAX_ELEVATION;
    }
    break;
  case GR_FIELD_VELOCITY:
    rule = "velocities must be finite and within +-1000 m/s";
    lo = -1000.0;
    hi = 1000.0;
    comps = 3;
    break;
  case GR_FIELD_WATER_DEPTH:
    rule = strict ? "depths must be finite, at least 0 and at most 1e4 m"
                  : "depths must be finite and at least 0 m";
    lo = 0.0;
    if (strict)
      hi = GR_RAIN_RUNOFF_MAX_DEPTH;
    break;
  case GR_FIELD_PERMEABILITY:
  case GR_FIELD_RAIN_RATE: {
    /* The maps replace the uniform parameters: the same range, in m/s. */
    int row = f == GR_FIELD_RAIN_RATE ? GR_RAIN_RUNOFF_P_RAIN_RATE : GR_RAIN_RUNOFF_P_PERMEABILITY;
    lo = gr_rain_runoff_core_min(row);
    hi = gr_rain_runoff_core_max(row);
    snprintf(rule_text, sizeof(rule_text),
             "%s must lie between %g and %g m/s (%g to %g %s), like %s",
             f == GR_FIELD_RAIN_RATE ? "rain rates" : "permeabilities", lo, hi,
             gr_rain_runoff_bounds[row].min, gr_rain_runoff_bounds[row].max,
             gr_rain_runoff_bounds[row].unit, gr_rain_runoff_bounds[row].property);
    rule = rule_text;
    break;
  }
  default:
    if (msg && msg_len)
      snprintf(msg, msg_len,
               "The field '%s' is not an input of the rain runoff simulation; its inputs are "
               "elevation, water_depth, water_surface, velocity, permeability and rain_rate.",
               gr_rain_runoff_field_label(f));
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (!values) {
    if (msg && msg_len)
      snprintf(msg, msg_len, "No values were given for the field '%s'.",
               gr_rain_runoff_field_label(f));
    return GR_ERR_INVALID_ARGUMENT;
  }
  for (size_t c = 0; c < n; ++c) {
    double v = values[c];
    if ((isfinite(v) && v >= lo && v <= hi) || (nan_ok && isnan(v)))
      continue;
    if (msg && msg_len) {
      if (nx > 0)
        snprintf(msg, msg_len, "The field '%s' has the value %g at cell (%zu, %zu): %s.",
                 gr_rain_runoff_field_label(f), v, c / comps % nx, c / comps / nx, rule);
      else
        snprintf(msg, msg_len,
                 "The field '%s' has the value %g at index %zu (row-major, x fastest): %s.",
                 gr_rain_runoff_field_label(f), v, c, rule);
    }
    return GR_ERR_INVALID_ARGUMENT;
  }
  return GR_OK;
}

gr_status gr_rain_runoff_field_validate(gr_field f, const float *values, size_t n, char *msg,
                                        size_t msg_len) {
  return gr_rain_runoff_field_check(f, values, n, 0, 0, msg, msg_len);
}

/* ------------------------------------------------------------- life cycle */

gr_status gr_rain_runoff_memory(const gr_context *ctx, const gr_grid *grid,
                                const gr_rain_runoff_params *p, int inputs, gr_memory_need *out) {
  if (!grid || !p || !out)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_memory needs a grid, parameters and a place for the "
                        "answer.");
  /* A piece's ring (at most grid->ghost cells each way). */
  int ring = grid->ghost > 0 ? grid->ghost : 0;
  double nx = (double)grid->nx + 2.0 * ring, ny = (double)grid->ny + 2.0 * ring, cells = nx * ny;
  double faces = (nx + 1.0) * ny + nx * (ny + 1.0);
  /* gr_rain_runoff_create's per_cell (21) and flood maps, the derive
   * kernel's scratch (3), the initial water h0 (1). */
  double planes = 21.0 + GR_RAIN_RUNOFF_MAP_ARRAYS + 3.0 + 1.0;
  planes += (inputs & GR_RAIN_RUNOFF_INPUT_RAIN) ? 1.0 : 0.0;
  planes += (inputs & GR_RAIN_RUNOFF_INPUT_PERMEABILITY) ? 1.0 : 0.0;
  planes += (inputs & GR_RAIN_RUNOFF_INPUT_INFLOWS) ? 2.0 : 0.0; /* src, pts */
  planes += (inputs & GR_RAIN_RUNOFF_INPUT_NO_DATA) ? 1.0 : 0.0;
  planes += (inputs & GR_RAIN_RUNOFF_INPUT_MANNING) ? 1.0 : 0.0;
  /* A GPU's local inertial step writes the new depth to a second plane
   * (rain_runoff_limit_update; the handle's merged, h_alt). */
  int gpu = ctx && gr_context_is_gpu(ctx);
  planes += p->flow_model == GR_FLOW_LOCAL_INERTIAL && gpu ? 1.0 : 0.0;
  double face_planes = 2.0; /* qx[2] and qy[2]: two sets of x- and y-faces */
  /* The separate shallow-water launches' x- and y-face arrays
   * (gr_rain_runoff_face_arrays): where the stages are not fused. */
  int separate = p->flow_model == GR_FLOW_SHALLOW_WATER && !gpu;
  face_planes += separate ? 6.0 : 0.0;
  memset(out, 0, sizeof(*out));
  out->points = (double)grid->nx * (double)grid->ny;
  out->device = sizeof(cl_float) * (planes * cells + face_planes * faces);
  out->largest = sizeof(cl_float) * (separate ? 6.0 * (nx + 1.0) * ny : 3.0 * cells);
  out->host = ((inputs & GR_RAIN_RUNOFF_INPUT_NO_DATA) ? 1.0 : 0.0) * cells + 8.0 * cells;
  /* gr_rain_runoff_state_bytes, the header aside */
  out->state = sizeof(float) * (GR_RAIN_RUNOFF_STATE_CELL_ARRAYS * cells + faces);
  return GR_OK;
}

gr_status gr_rain_runoff_create(gr_context *ctx, const gr_grid *grid,
                                const gr_rain_runoff_params *p, gr_rain_runoff **out) {
  char msg[256];
  if (!ctx || !out)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_create needs a context and a place for the simulation.");
  *out = NULL;
  if (gr_grid_validate(grid, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  if (gr_rain_runoff_params_validate(p, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  int ring[4];
  if (gr_rain_runoff_piece(grid, p->flow_model, ring, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);

  size_t nx = (size_t)grid->nx + (size_t)ring[0] + (size_t)ring[1];
  size_t ny = (size_t)grid->ny + (size_t)ring[2] + (size_t)ring[3], cells = nx * ny;
  if (((double)nx + 1.0) * ((double)ny + 1.0) > GR_RAIN_RUNOFF_MAX_FACES)
    return gr_set_error(ctx, GR_ERR_TOO_LARGE,
                        "The rain runoff grid of %zu x %zu points is too large: the kernels "
                        "address at most about 2.1e9 faces; split the domain or coarsen it.",
                        nx, ny);
  gr_memory_need need;
  gr_rain_runoff_memory(ctx, grid, p, 0, &need);
  if (gr_memory_check(ctx, &need, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_TOO_LARGE,
                        "The rain runoff state of a %zu x %zu grid %s: use a smaller grid or "
                        "another device.",
                        nx, ny, msg);
  gr_status st = GR_OK;
  gr_rain_runoff *s = calloc(1, sizeof(*s));
  if (!s)
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  s->ctx = gr_context_retain(ctx);
  s->grid = *grid;
  s->nxl = (int)nx;
  s->nyl = (int)ny;
  memcpy(s->ring, ring, sizeof(ring));
  s->params = *p;
  size_t bytes = cells * sizeof(cl_float);
  /* The kernels: for the inputs in use (none yet), made again when they
   * change (gr_rain_runoff_specialise). */
  s->inputs = -1;
  s->specialise = 1;
  size_t ext_len = 0;
  char *ext = NULL;
  if (clGetDeviceInfo(gr_context_device(ctx), CL_DEVICE_EXTENSIONS, 0, NULL, &ext_len) ==
          CL_SUCCESS &&
      (ext = calloc(ext_len + 1, 1)) != NULL &&
      clGetDeviceInfo(gr_context_device(ctx), CL_DEVICE_EXTENSIONS, ext_len, ext, NULL) ==
          CL_SUCCESS)
    s->nv_registers = strstr(ext, "cl_nv_compiler_options") != NULL;
  free(ext);
  cl_device_type type = 0;
  if (clGetDeviceInfo(gr_context_device(ctx), CL_DEVICE_TYPE, sizeof(type), &type, NULL) ==
      CL_SUCCESS)
    s->gpu = (type & CL_DEVICE_TYPE_GPU) != 0;
  st = gr_rain_runoff_specialise(s);
  if (st == GR_OK)
    st = gr_rain_runoff_sw_shape(s, 0, 0, 1);
  /* The fused local inertial step is not the default (see li_shape). */
  s->fused = 0;
  /* GPUs: the limiter and the update in one launch (rain_runoff_limit_update:
   * the H200's step at 4096^2 in 0.646 ms against 0.680, the limiter's
   * launch and its traffic gone). CPUs keep the two launches, where each
   * cell's limiter is computed once instead of five times (PoCL at 512^2:
   * the same time either way, within this machine's spread). */
  s->merged = s->gpu;
  for (int a = 0; st == GR_OK && a < GR_RAIN_RUNOFF_MAP_ARRAYS; ++a)
    st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, bytes, NULL, &s->map[a]);
  cl_mem *per_cell[] = {&s->h,     &s->h_c, &s->b,    &s->k,  &s->inf, &s->inf_c, &s->out,
                        &s->out_c, &s->in,  &s->in_c, &s->qu, &s->qv,  &s->h1,    &s->qu1,
                        &s->qv1,   &s->dh1, &s->wh,   &s->wu, &s->wv,  &s->u1,    &s->v1};
  for (size_t i = 0; st == GR_OK && i < sizeof(per_cell) / sizeof(per_cell[0]); ++i)
    st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, bytes, NULL, per_cell[i]);
  for (int a = 0; a < 2 && st == GR_OK; ++a) {
    st =
        gr_buffer_create(ctx, CL_MEM_READ_WRITE, (nx + 1) * ny * sizeof(cl_float), NULL, &s->qx[a]);
    if (st == GR_OK)
      st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, nx * (ny + 1) * sizeof(cl_float), NULL,
                            &s->qy[a]);
  }
  /* Bound where an input is absent, and for the face arrays before they
   * exist (gr_rain_runoff_face_arrays, arguments the kernels may write):
   * read-write, though nothing reads or writes it. */
  if (st == GR_OK)
    st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, sizeof(cl_float), NULL, &s->dummy);
  if (st == GR_OK)
    st = gr_rain_runoff_reductions(s);
  /* Dry, flat ground; nothing infiltrated or gone. */
  cl_mem *zeroed[] = {&s->h,  &s->h_c,  &s->b,  &s->inf, &s->inf_c, &s->out, &s->out_c,
                      &s->in, &s->in_c, &s->h1, &s->qu1, &s->qv1,   &s->dh1, &s->dummy};
  for (size_t i = 0; st == GR_OK && i < sizeof(zeroed) / sizeof(zeroed[0]); ++i)
    st =
        gr_rain_runoff_fill(s, *zeroed[i], 0.0f, *zeroed[i] == s->dummy ? sizeof(cl_float) : bytes);
  if (st == GR_OK)
    st = gr_rain_runoff_clear_flow(s);
  if (st == GR_OK)
    st = gr_rain_runoff_maps_restart(s);
  if (st == GR_OK)
    st = gr_finish(ctx);
  if (st != GR_OK) {
    gr_rain_runoff_destroy(s);
    return st;
  }
  *out = s;
  return GR_OK;
}

void gr_rain_runoff_destroy(gr_rain_runoff *s) {
  if (!s)
    return;
  cl_kernel kernels[] = {s->flux,         s->limit,        s->update,      s->reduce,
                         s->derive,       s->sw_prep,      s->sw_faces[0], s->sw_faces[1],
                         s->sw_update[0], s->sw_update[1], s->sw_speed,    s->maps,
                         s->source,       s->flux_edges,   s->sw_edges,    s->li_speed,
                         s->li_step,      s->limit_update};
  for (size_t i = 0; i < sizeof(kernels) / sizeof(kernels[0]); ++i)
    if (kernels[i])
      clReleaseKernel(kernels[i]);
  cl_mem *bufs[] = {&s->h,    &s->h_c,     &s->b,      &s->qx[0], &s->qy[0], &s->qx[1], &s->qy[1],
                    &s->k,    &s->inf,     &s->inf_c,  &s->out,   &s->out_c, &s->h0,    &s->rain,
                    &s->perm, &s->scratch, &s->dummy,  &s->qu,    &s->qv,    &s->h1,    &s->qu1,
                    &s->qv1,  &s->qu0,     &s->qv0,    &s->dh1,   &s->in,    &s->in_c,  &s->pts,
                    &s->src,  &s->n2map,   &s->nodata, &s->wh,    &s->wu,    &s->wv,    &s->u1,
                    &s->v1,   &s->fx,      &s->fy,     &s->h_alt, &s->k_alt};
  for (size_t i = 0; i < sizeof(bufs) / sizeof(bufs[0]); ++i)
    gr_buffer_release(bufs[i]);
  for (int a = 0; a < GR_RAIN_RUNOFF_MAP_ARRAYS; ++a)
    gr_buffer_release(&s->map[a]);
  for (int k = 0; k < 2; ++k) {
    if (s->sw_stage[k])
      clReleaseKernel(s->sw_stage[k]);
    if (s->sw_inner[k])
      clReleaseKernel(s->sw_inner[k]);
    if (s->sw_rim_faces[k])
      clReleaseKernel(s->sw_rim_faces[k]);
  }
  gr_reduction_i64_release(&s->ledger);
  gr_reduction_release(&s->speed);
  gr_reduction_release(&s->film);
  for (int e = 0; e < 4; ++e) {
    free(s->edge_t[e]);
    free(s->edge_q[e]);
  }
  free(s->hy_t);
  free(s->hy_r);
  free(s->mask);
  gr_context_release(s->ctx);
  free(s);
}

gr_status gr_rain_runoff_set_params(gr_rain_runoff *s, const gr_rain_runoff_params *p) {
  char msg[256];
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_set_params needs a simulation.");
  if (gr_rain_runoff_params_validate(p, msg, sizeof(msg)) != GR_OK)
    return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg));
  if (p->flow_model == GR_FLOW_LOCAL_INERTIAL && s->has_n2 && s->n_min < GR_RAIN_RUNOFF_LI_MIN_N)
    return GR_RAIN_RUNOFF_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The Manning map's smallest n is %g s/m^(1/3), below the %g that FlowModel "
                        "1 (local inertial) needs; raise the map's values, or keep FlowModel 0 "
                        "(shallow water).",
                        s->n_min, GR_RAIN_RUNOFF_LI_MIN_N));
  if (p->flow_model != s->params.flow_model) {
    /* The models keep their discharges in different places: the water
     * stays and starts from rest. A piece's ring width is its model's. */
    if (gr_rain_runoff_has_ring(s))
      return GR_RAIN_RUNOFF_KEEP_ERROR(
          s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                          "A rain runoff piece with neighbours cannot change its FlowModel (from "
                          "%d to %d): its ghost ring is the model's; create the pieces anew.",
                          (int)s->params.flow_model, (int)p->flow_model));
    gr_status st = gr_rain_runoff_clear_flow(s);
    if (st != GR_OK)
      return GR_RAIN_RUNOFF_KEEP_ERROR(s, st);
  }
  int rebuild = s->has_nodata && p->no_data != s->params.no_data;
  /* A new wetting depth turns cells wet or dry without a step: the maps
   * take it at once (their wet spells; the step kernels take a cell's wet
   * state before a step from its depth). */
  int rewet = p->wetting_depth != s->params.wetting_depth;
  s->params = *p;
  s->args_set = 0;
  s->maps_bound = 0;
  gr_status st = rewet ? gr_rain_runoff_maps_update(s, s->time) : GR_OK;
  if (st != GR_OK)
    return GR_RAIN_RUNOFF_KEEP_ERROR(s, st);
  if (rebuild) {
    /* The no-data cells turn from walls to outfalls or back: their bed and
     * kind, from the elevation on the device and the mask. */
    size_t cells = gr_rain_runoff_cells(s);
    float *b = malloc(cells * sizeof(float));
    if (!b)
      return GR_RAIN_RUNOFF_KEEP_ERROR(
          s, gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory."));
    st = gr_buffer_read(s->ctx, s->b, 0, cells * sizeof(cl_float), b);
    for (size_t c = 0; c < cells; ++c)
      if (s->mask[c])
        b[c] = NAN;
    if (st == GR_OK)
      st = gr_rain_runoff_set_elevation(s, b);
    free(b);
    return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_rain_runoff_inputs_changed(s, st));
  }
  /* A new FlowModel takes its program. */
  return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_rain_runoff_inputs_changed(s, GR_OK));
}

static gr_status gr_rain_runoff_reset_impl(gr_rain_runoff *s) {
  size_t bytes = gr_rain_runoff_cells(s) * sizeof(cl_float);
  gr_status st;
  if (s->h0)
    st = gr_cl_check(
        s->ctx,
        clEnqueueCopyBuffer(gr_context_queue(s->ctx), s->h0, s->h, 0, 0, bytes, 0, NULL, NULL),
        "Copying the initial water depth");
  else
    st = gr_rain_runoff_fill(s, s->h, 0.0f, bytes);
  cl_mem zeroed[] = {s->h_c, s->inf, s->inf_c, s->out, s->out_c, s->in, s->in_c};
  for (size_t i = 0; st == GR_OK && i < sizeof(zeroed) / sizeof(zeroed[0]); ++i)
    st = gr_rain_runoff_fill(s, zeroed[i], 0.0f, bytes);
  if (st == GR_OK)
    st = gr_rain_runoff_clear_flow(s);
  for (int a = 0; st == GR_OK && s->qu0 && a < 2; ++a)
    st = gr_cl_check(s->ctx,
                     clEnqueueCopyBuffer(gr_context_queue(s->ctx), a ? s->qv0 : s->qu0,
                                         a ? s->qv : s->qu, 0, 0, bytes, 0, NULL, NULL),
                     "Copying the initial discharges");
  if (st != GR_OK)
    return st;
  s->time = 0.0;
  s->steps = 0;
  memset(s->rain_book, 0, sizeof(s->rain_book));
  s->initial = s->initial_sum;
  return gr_rain_runoff_maps_restart(s);
}

gr_status gr_rain_runoff_reset(gr_rain_runoff *s) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT, "gr_rain_runoff_reset needs a simulation.");
  return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_rain_runoff_reset_impl(s));
}
