/* Snow deformation core (seed 000's thesis): host side of
 * snow_deformation.cl. The model, its step order and its book-keeping are
 * documented in graupel/snow_deformation.h; the constants both sides share
 * in snow_deformation_shared.h; the handle and the helpers the host files
 * share in snow_deformation_internal.h. This file: the parameter table,
 * timing, the device arrays' helpers, and the handle's life cycle (memory,
 * create, destroy, parameters, fields, objects, reset). */
#include "snow_deformation_internal.h"
#include "runtime_internal.h"

/* The one place each range is written. Densities: Table 3.1 of the thesis
 * spans 30 (new snow) to 900 (ice) kg/m^3; sand reaches about 2000. */
static const gr_param_bound gr_snow_bounds[GR_SNOW_P_COUNT] = {
    {"InitialSnowDepth", "m", 0.0, 100.0, 0.5, 1.0, 0, 0},
    {"InitialDensity", "kg/m^3", 1.0, 3000.0, 150.0, 1.0, 0, 0},
    {"MinDensity", "kg/m^3", 1.0, 3000.0, 100.0, 1.0, 0, 0},
    {"MaxDensity", "kg/m^3", 1.0, 3000.0, 400.0, 1.0, 0, 0},
    {"CompressionModel", "", 0.0, 1.0, 0.0, 1.0, 0, 1},
    {"MaxSlope", "m/m", 0.0, 100.0, 0.6, 1.0, 1, 0},
    {"DirectionFalloff", "", 1.0, 1000.0, 8.0, 1.0, 0, 0},
    {"MaxRelaxIterations", "", 0.0, 100000.0, 200.0, 1.0, 0, 1},
    {"RelaxTolerance", "m", 0.0, 1.0, 1e-4, 1.0, 1, 0},
    /* The front of a collapsing granular pile H high moves at about
     * sqrt(g H) (Lube et al. 2004, Lajeunesse et al. 2004): 2.2 m/s for the
     * default 0.5 m cover. 0: instant (every step relaxes to the end). */
    {"SlumpSpeed", "m/s", 0.0, 1000.0, 2.0, 1.0, 0, 0},
};

const gr_param_bound *gr_snow_deformation_param_bounds(int *count) {
  if (count)
    *count = GR_SNOW_P_COUNT;
  return gr_snow_bounds;
}

const char *gr_snow_deformation_last_error(const gr_snow_deformation *s) {
  return s ? s->error : "";
}

void gr_snow_deformation_params_init(gr_snow_deformation_params *p) {
  if (!p)
    return;
  memset(p, 0, sizeof(*p));
  const gr_param_bound *t = gr_snow_bounds;
  p->initial_snow_depth = t[GR_SNOW_P_INITIAL_DEPTH].default_value;
  p->initial_density = t[GR_SNOW_P_INITIAL_DENSITY].default_value;
  p->min_density = t[GR_SNOW_P_MIN_DENSITY].default_value;
  p->max_density = t[GR_SNOW_P_MAX_DENSITY].default_value;
  p->compression_model = (int)t[GR_SNOW_P_COMPRESSION].default_value;
  p->max_slope = t[GR_SNOW_P_MAX_SLOPE].default_value;
  p->direction_falloff = t[GR_SNOW_P_FALLOFF].default_value;
  p->max_relax_iterations = (int)t[GR_SNOW_P_ITERATIONS].default_value;
  p->relax_tolerance = t[GR_SNOW_P_TOLERANCE].default_value;
  p->slump_speed = t[GR_SNOW_P_SLUMP].default_value;
}

static double gr_snow_param_value(const gr_snow_deformation_params *p, int row) {
  switch (row) {
  case GR_SNOW_P_INITIAL_DEPTH:
    return p->initial_snow_depth;
  case GR_SNOW_P_INITIAL_DENSITY:
    return p->initial_density;
  case GR_SNOW_P_MIN_DENSITY:
    return p->min_density;
  case GR_SNOW_P_MAX_DENSITY:
    return p->max_density;
  case GR_SNOW_P_COMPRESSION:
    return (double)p->compression_model;
  case GR_SNOW_P_MAX_SLOPE:
    return p->max_slope;
  case GR_SNOW_P_FALLOFF:
    return p->direction_falloff;
  case GR_SNOW_P_ITERATIONS:
    return (double)p->max_relax_iterations;
  case GR_SNOW_P_SLUMP:
    return p->slump_speed;
  default:
    return p->relax_tolerance;
  }
}

gr_status gr_snow_deformation_params_validate(const gr_snow_deformation_params *p, char *msg,
                                              size_t msg_len) {
  const char *what = "Invalid snow deformation parameters";
  if (!p)
    return gr_params_missing(what, msg, msg_len);
  double values[GR_SNOW_P_COUNT];
  for (int row = 0; row < GR_SNOW_P_COUNT; ++row)
    values[row] = gr_snow_param_value(p, row);
  if (gr_params_check_table(gr_snow_bounds, NULL, GR_SNOW_P_COUNT, values, what, NULL,
                            GR_PARAM_SAY_GOT, msg, msg_len) != GR_OK)
    return GR_ERR_INVALID_ARGUMENT;
  if (p->min_density > p->max_density) {
    if (msg && msg_len)
      snprintf(msg, msg_len,
               "Invalid snow deformation parameters: MinDensity (%g kg/m^3) must not exceed "
               "MaxDensity (%g kg/m^3); swap the two ends of DensityRange.",
               p->min_density, p->max_density);
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (p->initial_density < p->min_density || p->initial_density > p->max_density) {
    if (msg && msg_len)
      snprintf(msg, msg_len,
               "Invalid snow deformation parameters: InitialDensity must lie within DensityRange "
               "%g to %g kg/m^3 (got %g kg/m^3).",
               p->min_density, p->max_density, p->initial_density);
    return GR_ERR_INVALID_ARGUMENT;
  }
  return GR_OK;
}

double gr_snow_now_ms(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return 1e3 * (double)ts.tv_sec + 1e-6 * (double)ts.tv_nsec;
}

/* With timing on: waits for the stage just enqueued and charges its time. */
gr_status gr_snow_mark(gr_snow_deformation *s, double *acc) {
  if (!s->timing)
    return GR_OK;
  gr_status st = gr_finish(s->ctx);
  double t = gr_snow_now_ms();
  *acc += t - s->t_mark;
  s->t_mark = t;
  return st;
}

void gr_snow_deformation_set_blocked(gr_snow_deformation *s, int on) {
  if (s)
    s->blocked = on != 0;
}

void gr_snow_deformation_set_group(gr_snow_deformation *s, int on) {
  if (s)
    s->group = on != 0;
}

void gr_snow_deformation_set_timing(gr_snow_deformation *s, int on) {
  if (!s)
    return;
  s->timing = on != 0;
  memset(&s->tm, 0, sizeof(s->tm));
}

gr_status gr_snow_deformation_timing_get(const gr_snow_deformation *s,
                                         gr_snow_deformation_timing *out) {
  if (!s || !out)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_timing_get needs a simulation and a place for the "
                        "times.");
  *out = s->tm;
  return GR_OK;
}

size_t gr_snow_cells(const gr_snow_deformation *s) {
  return (size_t)s->grid.nx * (size_t)s->grid.ny;
}

static gr_status gr_snow_fill(gr_snow_deformation *s, cl_mem buf, float value) {
  return gr_cl_check(s->ctx,
                     clEnqueueFillBuffer(gr_context_queue(s->ctx), buf, &value, sizeof(value), 0,
                                         gr_snow_cells(s) * sizeof(float), 0, NULL, NULL),
                     "Filling a device buffer");
}

static gr_status gr_snow_copy(gr_snow_deformation *s, cl_mem from, cl_mem to) {
  return gr_cl_check(s->ctx,
                     clEnqueueCopyBuffer(gr_context_queue(s->ctx), from, to, 0, 0,
                                         gr_snow_cells(s) * sizeof(float), 0, NULL, NULL),
                     "Copying a device buffer");
}

/* Depths to whole quanta (snow_deformation_shared.h). */
static gr_status gr_snow_quantize(gr_snow_deformation *s, cl_mem depth) {
  cl_int n = (cl_int)gr_snow_cells(s);
  gr_status st = GR_SNOW_ARG(s, s->quantize, "n", n);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, s->quantize, "depth", depth);
  if (st == GR_OK)
    st = gr_enqueue_1d(s->ctx, s->quantize, (size_t)n);
  return st;
}

/* The state (depth and density) of points [x0, x1] x [y0, y1] from the
 * current buffer of the pair to the other one. */
gr_status gr_snow_sync_rect(gr_snow_deformation *s, int x0, int y0, int x1, int y1) {
  if (x0 > x1 || y0 > y1)
    return GR_OK;
  size_t origin[3] = {(size_t)x0 * sizeof(float), (size_t)y0, 0};
  size_t region[3] = {(size_t)(x1 - x0 + 1) * sizeof(float), (size_t)(y1 - y0 + 1), 1};
  size_t pitch = (size_t)s->grid.nx * sizeof(float);
  cl_int err = CL_SUCCESS;
  for (int q = 0; q < 2 && err == CL_SUCCESS; ++q) {
    cl_mem *pair = q ? s->density : s->depth;
    err = clEnqueueCopyBufferRect(gr_context_queue(s->ctx), pair[s->cur], pair[1 - s->cur], origin,
                                  origin, region, pitch, 0, pitch, 0, 0, NULL, NULL);
  }
  return gr_cl_check(s->ctx, err, "Copying a window of the snow state");
}

/* sum S (quanta) and sum S rho (2^-24 kg/m^2) over the piece's own points
 * (every point of a whole grid). */
gr_status gr_snow_ledger_sums(gr_snow_deformation *s, long long *vol, long long *mass) {
  cl_int nx = s->grid.nx, x0 = s->ring[0], y0 = s->ring[2], w = s->own_nx, n = w * s->own_ny;
  const cl_kernel k = s->ledger_reduce;
  gr_status st = GR_SNOW_ARG(s, k, "depth", s->depth[s->cur]);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "density", s->density[s->cur]);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "nx", nx);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "x0", x0);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "y0", y0);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "w", w);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "n", n);
  long long sums[GR_SNOW_LEDGER_SUMS];
  if (st == GR_OK)
    st = gr_reduction_i64_run(s->ctx, &s->red_ledger, k, sums);
  if (st == GR_OK) {
    *vol = sums[0];
    *mass = sums[1];
  }
  return st;
}

static gr_status gr_snow_initial_state(gr_snow_deformation *s) {
  s->cur = 0;
  gr_status st = gr_snow_copy(s, s->depth0, s->depth[0]);
  if (st == GR_OK)
    st = gr_snow_copy(s, s->density0, s->density[0]);
  if (st == GR_OK)
    st = gr_snow_fill(s, s->overlap_sum, 0.0f);
  if (st == GR_OK)
    st = gr_snow_fill(s, s->contact, 0.0f);
  s->time = s->compressed = s->displaced = s->pending = s->pending_mass = 0.0;
  s->steps = 0;
  s->relax_iterations = 0;
  s->relax_full = 1;
  s->rest[0] = s->rest[1] = 0;
  s->rest[2] = s->rest[3] = -1;
  s->sync_full = 1;
  s->reset_full = 1;
  s->aborted = 0;
  memset(s->force, 0, sizeof(s->force));
  memset(s->area, 0, sizeof(s->area));
  gr_snow_deformation_clear_impulses(s);
  if (st == GR_OK)
    st = gr_snow_ledger_sums(s, &s->initial_q, &s->initial_m);
  return st;
}

/* The talus launch's tile: 32 x 32 points on a CPU (its halo, 2 per
 * iteration on each side, then costs about as much again), 16 x 16 on a
 * GPU, smaller where the kernel's work-group or the local memory (8
 * planes of the tile and halo) does not allow it. */
static gr_status gr_snow_block_shape(gr_snow_deformation *s) {
  cl_device_id dev = gr_context_device(s->ctx);
  cl_device_type type = 0;
  cl_ulong local_mem = 0;
  size_t wg = 0;
  cl_int err = clGetDeviceInfo(dev, CL_DEVICE_TYPE, sizeof(type), &type, NULL);
  if (err == CL_SUCCESS)
    err = clGetDeviceInfo(dev, CL_DEVICE_LOCAL_MEM_SIZE, sizeof(local_mem), &local_mem, NULL);
  if (err == CL_SUCCESS)
    err = clGetKernelWorkGroupInfo(s->relax_block, dev, CL_KERNEL_WORK_GROUP_SIZE, sizeof(wg), &wg,
                                   NULL);
  if (err != CL_SUCCESS)
    return gr_cl_check(s->ctx, err, "Querying the device for the talus kernel's work-group");
  size_t t = (type & CL_DEVICE_TYPE_GPU) ? 16 : 64;
  for (; t > 1; t /= 2) {
    size_t side = t + 4 * GR_SNOW_BLOCK_ITERATIONS;
    if (t * t <= wg && 8 * side * side * sizeof(cl_float) <= local_mem)
      break;
  }
  if (t < 4)
    return gr_set_error(s->ctx, GR_ERR_TOO_LARGE,
                        "The OpenCL device offers too little local memory (%llu bytes) or too "
                        "small work-groups (%zu) for the snow talus kernel; pick another device.",
                        (unsigned long long)local_mem, wg);
  s->block[0] = s->block[1] = t;
  s->blocked = (type & CL_DEVICE_TYPE_GPU) != 0;
  /* The tail's work-group: as large as the device allows on a GPU (one
   * group holds one multiprocessor), 256 on a CPU (one core runs it). */
  wg = 0;
  err = clGetKernelWorkGroupInfo(s->relax_group, dev, CL_KERNEL_WORK_GROUP_SIZE, sizeof(wg), &wg,
                                 NULL);
  if (err != CL_SUCCESS)
    return gr_cl_check(s->ctx, err, "Querying the device for the talus kernel's work-group");
  size_t g = (type & CL_DEVICE_TYPE_GPU) ? 1024 : 256;
  s->group_size = g < wg ? g : wg;
  s->group = s->group_size >= 32;
  s->group_area = (type & CL_DEVICE_TYPE_GPU) ? GR_SNOW_GROUP_AREA_GPU : GR_SNOW_GROUP_AREA_CPU;
  return GR_OK;
}

/* Correctly rounded division and square root where the device offers
 * them (OpenCL allows 2.5 ulp otherwise, and NVIDIA's driver takes it):
 * the talus' decisions hinge on the rates' last bits, so with them a GPU
 * ends bit for bit where PoCL does (without, 7e-5 m apart after 40 steps
 * of the devices_agree trail). */
static const char *gr_snow_build_options(gr_context *ctx) {
  cl_device_fp_config fp = 0;
  if (clGetDeviceInfo(gr_context_device(ctx), CL_DEVICE_SINGLE_FP_CONFIG, sizeof(fp), &fp, NULL) ==
          CL_SUCCESS &&
      (fp & CL_FP_CORRECTLY_ROUNDED_DIVIDE_SQRT))
    return "-cl-fp32-correctly-rounded-divide-sqrt";
  return "";
}

/* The planes of a point that gr_snow_deformation_create allocates. */
#define GR_SNOW_PLANES 17

gr_status gr_snow_deformation_memory(const gr_grid *grid, gr_memory_need *out) {
  if (!grid || !out)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_memory needs a grid and a place for the answer.");
  /* A piece's ring (at most grid->ghost points each way). */
  int ring = grid->ghost > 0 ? grid->ghost : 0;
  double n = ((double)grid->nx + 2.0 * ring) * ((double)grid->ny + 2.0 * ring);
  memset(out, 0, sizeof(*out));
  out->points = (double)grid->nx * (double)grid->ny;
  out->device = sizeof(float) * GR_SNOW_PLANES * n;
  out->largest = sizeof(float) * n;
  out->state = sizeof(float) * GR_SNOW_STATE_ARRAYS * n; /* gr_snow_state_bytes */
  return GR_OK;
}

gr_status gr_snow_deformation_create(gr_context *ctx, const gr_grid *grid,
                                     const gr_snow_deformation_params *p,
                                     gr_snow_deformation **out) {
  char msg[320];
  if (!ctx || !out)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_create needs a context and a place for the "
                        "simulation.");
  *out = NULL;
  if (gr_grid_validate(grid, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  if (gr_snow_deformation_params_validate(p, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  int ring[4];
  if (gr_snow_piece_rings(grid, ring, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  double wide = GR_SNOW_DEFORMATION_GHOST; /* the ring, or a wider one asked for */
  for (int q = 0; q < 4; ++q)
    wide = ring[q] > wide ? ring[q] : wide;
  if (((double)grid->nx + 2 * wide) * ((double)grid->ny + 2 * wide) > (double)INT_MAX / 2)
    return gr_set_error(ctx, GR_ERR_TOO_LARGE,
                        "The snow deformation grid of %d x %d points is too large: the kernels "
                        "address at most about 1e9 points; coarsen it.",
                        grid->nx, grid->ny);
  gr_memory_need need;
  gr_snow_deformation_memory(grid, &need);
  if (gr_memory_check(ctx, &need, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_TOO_LARGE,
                        "The snow deformation of a %d x %d grid %s: use a smaller grid or "
                        "another device.",
                        grid->nx, grid->ny, msg);
  gr_snow_deformation *s = calloc(1, sizeof(*s));
  if (!s)
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  s->ctx = gr_context_retain(ctx);
  s->grid = *grid;
  memcpy(s->ring, ring, sizeof(ring));
  s->own_nx = grid->nx;
  s->own_ny = grid->ny;
  s->gnx = grid->global_nx > 0 ? grid->global_nx : grid->nx;
  s->gny = grid->global_ny > 0 ? grid->global_ny : grid->ny;
  s->ox = grid->i0 - ring[0];
  s->oy = grid->j0 - ring[2];
  s->grid.nx = grid->nx + ring[0] + ring[1];
  s->grid.ny = grid->ny + ring[2] + ring[3];
  s->params = *p;
  size_t cells = gr_snow_cells(s), bytes = cells * sizeof(float);
  cl_program prog = NULL;
  gr_status st = gr_program_get(ctx, "snow_deformation", gr_snow_build_options(ctx), &prog);
  struct {
    const char *name;
    cl_kernel *k;
  } ks[] = {{"snow_raster", &s->raster},
            {"snow_raster_clear", &s->raster_clear},
            {"snow_overlap", &s->overlap_k},
            {"snow_contour", &s->contour},
            {"snow_object_reduce", &s->obj_reduce},
            {"snow_apply", &s->apply},
            {"snow_relax_rate", &s->relax_rate},
            {"snow_relax_move", &s->relax_move},
            {"snow_relax_block", &s->relax_block},
            {"snow_relax_group", &s->relax_group},
            {"snow_check_reduce", &s->check_reduce},
            {"snow_ledger_reduce", &s->ledger_reduce},
            {"snow_surface", &s->surface},
            {"snow_reset", &s->reset},
            {"snow_ring_reduce", &s->ring_reduce},
            {"snow_quantize", &s->quantize},
            {"snow_reach_rows", &s->reach_rows},
            {"snow_reach_cols", &s->reach_cols},
            {"snow_reach_seed", &s->reach_seed},
            {"snow_reach_ceiling", &s->reach_ceiling}};
  for (size_t i = 0; st == GR_OK && i < sizeof(ks) / sizeof(ks[0]); ++i)
    st = gr_kernel_create(ctx, prog, ks[i].name, ks[i].k);
  cl_mem *bufs[] = {&s->depth[0],    &s->depth[1], &s->density[0], &s->density[1], &s->ground,
                    &s->depth0,      &s->density0, &s->under,      &s->overlap,    &s->weight,
                    &s->overlap_sum, &s->contact,  &s->under_min,  &s->rate,       &s->rate_in,
                    &s->movable,     &s->scratch};
  _Static_assert(sizeof(bufs) / sizeof(bufs[0]) == GR_SNOW_PLANES,
                 "gr_snow_deformation_memory counts every plane");
  for (size_t i = 0; st == GR_OK && i < sizeof(bufs) / sizeof(bufs[0]); ++i)
    st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, bytes, NULL, bufs[i]);
  if (st == GR_OK)
    st = gr_snow_block_shape(s);
  if (st == GR_OK)
    st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, 6 * sizeof(cl_int), NULL, &s->group_result);
  if (st == GR_OK)
    st = gr_reduction_i64_init(ctx, s->obj_reduce, cells, GR_SNOW_OBJ_SUMS, &s->red_obj);
  if (st == GR_OK)
    for (int q = 0; st == GR_OK && q <= GR_SNOW_CHECK_LAG; ++q)
      st = gr_reduction_init(ctx, s->check_reduce, cells, 0, GR_SNOW_CHECK_MAXES, &s->red_check[q]);
  if (st == GR_OK)
    st = gr_reduction_i64_init(ctx, s->ledger_reduce, cells, GR_SNOW_LEDGER_SUMS, &s->red_ledger);
  if (st == GR_OK)
    st = gr_reduction_i64_init(ctx, s->ring_reduce, cells, 4, &s->red_ring);
  if (st == GR_OK)
    st = gr_snow_fill(s, s->ground, 0.0f);
  if (st == GR_OK)
    st = gr_snow_fill(s, s->depth0, (float)p->initial_snow_depth);
  if (st == GR_OK)
    st = gr_snow_quantize(s, s->depth0);
  if (st == GR_OK)
    st = gr_snow_fill(s, s->density0, (float)p->initial_density);
  if (st == GR_OK)
    st = gr_snow_fill(s, s->overlap, 0.0f);
  if (st == GR_OK)
    st = gr_snow_initial_state(s);
  if (st != GR_OK) {
    gr_snow_deformation_destroy(s);
    return st;
  }
  *out = s;
  return GR_OK;
}

void gr_snow_deformation_destroy(gr_snow_deformation *s) {
  if (!s)
    return;
  cl_kernel ks[] = {s->raster,      s->raster_clear, s->overlap_k,    s->contour,
                    s->obj_reduce,  s->apply,        s->relax_rate,   s->relax_move,
                    s->relax_block, s->relax_group,  s->check_reduce, s->ledger_reduce,
                    s->surface,     s->reset,        s->ring_reduce,  s->quantize,
                    s->reach_rows,  s->reach_cols,   s->reach_seed,   s->reach_ceiling};
  for (size_t i = 0; i < sizeof(ks) / sizeof(ks[0]); ++i)
    if (ks[i])
      clReleaseKernel(ks[i]);
  cl_mem *bufs[] = {&s->depth[0],    &s->depth[1], &s->density[0], &s->density[1],  &s->ground,
                    &s->depth0,      &s->density0, &s->under,      &s->overlap,     &s->weight,
                    &s->overlap_sum, &s->contact,  &s->under_min,  &s->rate,        &s->rate_in,
                    &s->movable,     &s->scratch,  &s->tri,        &s->group_result};
  for (size_t i = 0; i < sizeof(bufs) / sizeof(bufs[0]); ++i)
    gr_buffer_release(bufs[i]);
  gr_reduction_i64_release(&s->red_obj);
  for (int q = 0; q <= GR_SNOW_CHECK_LAG; ++q)
    gr_reduction_release(&s->red_check[q]);
  gr_reduction_i64_release(&s->red_ledger);
  gr_reduction_i64_release(&s->red_ring);
  for (int o = 0; o < GR_SNOW_DEFORMATION_MAX_OBJECTS; ++o)
    gr_mesh_memo_free(&s->memo[o]);
  gr_context_release(s->ctx);
  free(s);
}

gr_status gr_snow_deformation_set_params(gr_snow_deformation *s,
                                         const gr_snow_deformation_params *p) {
  char msg[320];
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_set_params needs a simulation.");
  if (gr_snow_deformation_params_validate(p, msg, sizeof(msg)) != GR_OK)
    return GR_SNOW_KEEP_ERROR(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg));
  s->params = *p;
  s->relax_full = 1; /* a new MaxSlope may make any slope too steep */
  return GR_OK;
}

gr_status gr_snow_deformation_field_validate(const gr_snow_deformation_params *p, gr_field f,
                                             const float *values, size_t n, size_t nx, char *msg,
                                             size_t msg_len) {
  double lo, hi;
  const char *rule;
  char rule_text[200];
  const char *name = gr_field_name(f);
  if (!name)
    name = "(unknown field)";
  switch (f) {
  case GR_FIELD_ELEVATION:
    lo = -GR_SNOW_MAX_ELEVATION;
    hi = GR_SNOW_MAX_ELEVATION;
    rule = "elevations must be finite and within +-1e6 m";
    break;
  case GR_FIELD_SNOW_DEPTH:
    lo = 0.0;
    hi = GR_SNOW_MAX_DEPTH;
    rule = "snow depths must be finite, at least 0 and at most 1e4 m";
    break;
  case GR_FIELD_SNOW_DENSITY:
    if (!p) {
      if (msg && msg_len)
        snprintf(msg, msg_len,
                 "Checking the field 'snow_density' needs the parameters (its DensityRange); "
                 "pass them.");
      return GR_ERR_INVALID_ARGUMENT;
    }
    lo = (double)(float)p->min_density;
    hi = (double)(float)p->max_density;
    snprintf(rule_text, sizeof(rule_text),
             "snow densities must lie within DensityRange, %g to %g kg/m^3", lo, hi);
    rule = rule_text;
    break;
  default:
    if (msg && msg_len)
      snprintf(msg, msg_len,
               "The field '%s' is not an input of the snow deformation simulation; its inputs "
               "are elevation, snow_depth and snow_density.",
               name);
    return GR_ERR_INVALID_ARGUMENT;
  }
  return gr_field_check_range(name, values, n, nx, lo, hi, rule, msg, msg_len);
}

static gr_status gr_snow_set_field_impl(gr_snow_deformation *s, gr_field f, const float *host) {
  size_t cells = gr_snow_cells(s), nx = (size_t)s->grid.nx;
  char msg[512];
  if (gr_snow_deformation_field_validate(&s->params, f, host, cells, nx, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  size_t bytes = cells * sizeof(float);
  s->relax_full = 1; /* new snow or ground may be too steep anywhere */
  s->sync_full = 1;
  if (f == GR_FIELD_ELEVATION)
    return gr_buffer_write(s->ctx, s->ground, 0, bytes, host);
  /* The new snow replaces what is there: the ledger's initial volume and
   * mass move by the change, so the balance still closes. */
  long long v0, m0, v1, m1;
  gr_status st = gr_snow_ledger_sums(s, &v0, &m0);
  cl_mem init = f == GR_FIELD_SNOW_DEPTH ? s->depth0 : s->density0;
  cl_mem now = f == GR_FIELD_SNOW_DEPTH ? s->depth[s->cur] : s->density[s->cur];
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, init, 0, bytes, host);
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, now, 0, bytes, host);
  if (st == GR_OK && f == GR_FIELD_SNOW_DEPTH)
    st = gr_snow_quantize(s, init);
  if (st == GR_OK && f == GR_FIELD_SNOW_DEPTH)
    st = gr_snow_quantize(s, now);
  if (st == GR_OK)
    st = gr_snow_ledger_sums(s, &v1, &m1);
  if (st == GR_OK) {
    s->initial_q += v1 - v0;
    s->initial_m += m1 - m0;
  }
  return st;
}

gr_status gr_snow_deformation_set_field(gr_snow_deformation *s, gr_field f, const float *host) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_set_field needs a simulation.");
  if (!host)
    return GR_SNOW_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_set_field needs the field's values (got NULL)."));
  return GR_SNOW_KEEP_ERROR(s, gr_snow_set_field_impl(s, f, host));
}

/* The points [*lo, *hi] of a box [b0, b1] whose raster test may pass for
 * coordinates in [a, b] at spacing d (the kernel widens each triangle by one
 * spacing; one more here covers the rounding). Empty: *lo > *hi. */
static gr_status gr_snow_set_objects_impl(gr_snow_deformation *s, const gr_mesh *meshes, int n,
                                          const double *velocities) {
  char msg[320];
  if (n < 0 || n > GR_SNOW_DEFORMATION_MAX_OBJECTS || (n > 0 && !meshes))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_set_objects takes 0 to %d objects with their meshes "
                        "(got %d%s).",
                        GR_SNOW_DEFORMATION_MAX_OBJECTS, n,
                        n > 0 && !meshes ? " and no meshes" : "");
  size_t total = 0;
  for (int o = 0; o < n; ++o) {
    if (gr_mesh_check(&s->memo[o], &meshes[o], 1, msg, sizeof(msg)) != GR_OK)
      return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT, "Object %d: %s", o, msg);
    if (velocities)
      for (int a = 0; a < 3; ++a)
        if (!isfinite(velocities[3 * o + a]))
          return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                              "Object %d has a velocity that is not finite (component %d is %g); "
                              "give finite velocities in m/s.",
                              o, a, velocities[3 * o + a]);
    total += (size_t)meshes[o].ntriangles;
  }
  if (total > (size_t)INT_MAX / 9)
    return gr_set_error(s->ctx, GR_ERR_TOO_LARGE,
                        "The objects have %zu triangles, more than the core addresses; simplify "
                        "the meshes.",
                        total);
  int most_vertices = 0;
  for (int o = 0; o < n; ++o)
    most_vertices = meshes[o].nvertices > most_vertices ? meshes[o].nvertices : most_vertices;
  float *tri = total ? malloc(total * 9 * sizeof(float)) : NULL;
  double *world = most_vertices ? malloc((size_t)most_vertices * 3 * sizeof(double)) : NULL;
  if ((total && !tri) || (most_vertices && !world)) {
    free(tri);
    free(world);
    return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  gr_snow_object objs[GR_SNOW_DEFORMATION_MAX_OBJECTS];
  const gr_grid *g = &s->grid;
  size_t at = 0;
  for (int o = 0; o < n; ++o) {
    const gr_mesh *m = &meshes[o];
    const double *T = m->transform;
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    objs[o].first = (int)at;
    objs[o].count = m->ntriangles;
    /* Each vertex once, relative to grid point (0, 0), where float keeps
     * its precision. */
    for (int q = 0; q < m->nvertices; ++q) {
      const float *v = m->vertices + 3 * q;
      double *w = world + 3 * q;
      for (int a = 0; a < 3; ++a)
        w[a] = T[a] * v[0] + T[4 + a] * v[1] + T[8 + a] * v[2] + T[12 + a];
      w[0] -= g->x0;
      w[1] -= g->y0;
    }
    for (int t = 0; t < m->ntriangles; ++t, ++at)
      for (int k = 0; k < 3; ++k) {
        const double *w = world + 3 * m->triangles[3 * t + k];
        for (int a = 0; a < 3; ++a) {
          tri[9 * at + 3 * k + a] = (float)w[a];
          lo[a] = w[a] < lo[a] ? w[a] : lo[a];
          hi[a] = w[a] > hi[a] ? w[a] : hi[a];
        }
      }
    /* The box in the whole domain's points, kept in the local arrays'
     * indices (for a piece it may lie partly or wholly beyond them: every
     * piece steps every object the domain has). */
    double fi0 = ceil(lo[0] / g->dx - 1.0), fi1 = floor(hi[0] / g->dx + 1.0);
    double fj0 = ceil(lo[1] / g->dy - 1.0), fj1 = floor(hi[1] / g->dy + 1.0);
    if (fi1 < 0 || fj1 < 0 || fi0 > s->gnx - 1 || fj0 > s->gny - 1) {
      objs[o].bi0 = objs[o].bj0 = 1;
      objs[o].bi1 = objs[o].bj1 = 0; /* wholly outside: touches nothing */
    } else {
      objs[o].bi0 = (int)fmax(0.0, fi0) - s->ox;
      objs[o].bi1 = (int)fmin(s->gnx - 1.0, fi1) - s->ox;
      objs[o].bj0 = (int)fmax(0.0, fj0) - s->oy;
      objs[o].bj1 = (int)fmin(s->gny - 1.0, fj1) - s->oy;
    }
    for (int a = 0; a < 3; ++a)
      objs[o].v[a] = velocities ? velocities[3 * o + a] : 0.0;
  }
  free(world);
  gr_status st = GR_OK;
  if (total > s->tri_cap) {
    gr_buffer_release(&s->tri);
    s->tri_cap = 0;
    st = gr_buffer_create(s->ctx, CL_MEM_READ_ONLY, total * 9 * sizeof(float), NULL, &s->tri);
    if (st == GR_OK)
      s->tri_cap = total;
  }
  if (st == GR_OK && total)
    st = gr_buffer_write(s->ctx, s->tri, 0, total * 9 * sizeof(float), tri);
  free(tri);
  if (st != GR_OK)
    return st;
  memcpy(s->objects, objs, (size_t)n * sizeof(objs[0]));
  if (n != s->nobjects) {
    memset(s->force, 0, sizeof(s->force));
    memset(s->area, 0, sizeof(s->area));
    gr_snow_deformation_clear_impulses(s);
  }
  s->nobjects = n;
  return GR_OK;
}

gr_status gr_snow_deformation_set_objects(gr_snow_deformation *s, const gr_mesh *meshes, int n,
                                          const double *velocities) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_set_objects needs a simulation.");
  return GR_SNOW_KEEP_ERROR(s, gr_snow_set_objects_impl(s, meshes, n, velocities));
}

gr_status gr_snow_deformation_reset(gr_snow_deformation *s) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_reset needs a simulation.");
  gr_status st = gr_snow_initial_state(s);
  return st == GR_OK ? GR_OK : GR_SNOW_KEEP_ERROR(s, st);
}
