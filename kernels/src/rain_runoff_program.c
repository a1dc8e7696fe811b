/* Rain runoff core, host side: the device arrays' helpers (cells, fills,
 * rectangles, the ledger's reduction), the kernels' arguments by name and
 * index, and the program: specialised for the inputs in use and the flow
 * model, and the fused work-groups' tiles (rain_runoff_internal.h). */
#include "rain_runoff_internal.h"

/* ----------------------------------------------------------- device state */

/* Cells of the local arrays (the piece and its ring). */
size_t gr_rain_runoff_cells(const gr_rain_runoff *s) {
  return (size_t)s->nxl * (size_t)s->nyl;
}

/* Cells the piece owns: those of the ledger and of get_field. */
size_t gr_rain_runoff_own_cells(const gr_rain_runoff *s) {
  return (size_t)s->grid.nx * (size_t)s->grid.ny;
}

int gr_rain_runoff_has_ring(const gr_rain_runoff *s) {
  return s->ring[0] || s->ring[1] || s->ring[2] || s->ring[3];
}

/* The sum of a local-array field's floats over the owned cells in fixed
 * point: the same integers as the device's reduction of the same floats,
 * whatever the split. */
gr_fixed gr_rain_runoff_own_sum(const gr_rain_runoff *s, const float *host) {
  gr_fixed sum = {0, 0};
  for (int j = s->ring[2]; j < s->nyl - s->ring[3]; ++j)
    for (int i = s->ring[0]; i < s->nxl - s->ring[1]; ++i) {
      size_t c = (size_t)j * (size_t)s->nxl + (size_t)i;
      if (!s->has_nodata || !s->mask[c]) /* nothing falls on, or stays in, no-data cells */
        gr_fixed_add(&sum, gr_fixed_from_float(host[c]));
    }
  return sum;
}

/* Sets the arguments in `args` of kernel k by name; the first failure names
 * the kernel and the argument. */
gr_status gr_rain_runoff_args(gr_rain_runoff *s, cl_kernel k, const gr_rain_runoff_arg *args,
                              size_t n) {
  gr_status st = GR_OK;
  for (size_t i = 0; st == GR_OK && i < n; ++i)
    st = gr_kernel_arg(s->ctx, k, args[i].name, args[i].size, args[i].value);
  return st;
}

/* The indices of kernel k's arguments called names[0..n) (the programs
 * carry argument names, gr_program_get): the step loops set the arguments
 * that change every step by index, without gr_kernel_arg's look-up (a
 * mutex and a query per argument), which shows on small grids. */
static gr_status gr_rain_runoff_arg_indices(gr_rain_runoff *s, cl_kernel k,
                                            const char *const *names, int n, cl_uint *out) {
  cl_uint nargs = 0;
  cl_int err = clGetKernelInfo(k, CL_KERNEL_NUM_ARGS, sizeof(nargs), &nargs, NULL);
  for (int a = 0; err == CL_SUCCESS && a < n; ++a) {
    out[a] = nargs;
    for (cl_uint i = 0; err == CL_SUCCESS && i < nargs && out[a] == nargs; ++i) {
      char name[64] = "";
      err = clGetKernelArgInfo(k, i, CL_KERNEL_ARG_NAME, sizeof(name), name, NULL);
      if (err == CL_SUCCESS && strcmp(name, names[a]) == 0)
        out[a] = i;
    }
    if (err == CL_SUCCESS && out[a] == nargs)
      return gr_set_error(s->ctx, GR_ERR_OPENCL,
                          "A rain runoff step kernel has no argument '%s': the kernels' source "
                          "and rain_runoff.c disagree; rebuild Graupel.",
                          names[a]);
  }
  return gr_cl_check(s->ctx, err, "Reading the rain runoff step kernels' argument names");
}

/* Sets argument `index` of kernel k (see gr_rain_runoff_arg_indices). */
gr_status gr_rain_runoff_arg_at(gr_rain_runoff *s, cl_kernel k, cl_uint index, size_t size,
                                const void *value) {
  return gr_cl_check(s->ctx, clSetKernelArg(k, index, size, value),
                     "Setting a rain runoff step kernel's argument");
}

/* Looks up the indices of the step kernels' changing arguments. */
static gr_status gr_rain_runoff_step_indices(gr_rain_runoff *s) {
  static const char *const step[] = {"h",      "h_out", "limit", "limit_out", "qx_old",
                                     "qy_old", "qx",    "qy",    "map_time"};
  static const char *const edges[] = {"h", "limit", "qx_old", "qy_old", "qx", "qy"};
  static const char *const update[] = {"qx", "qy", "map_time", "h", "h_out"};
  static const char *const flux[] = {"qx_old", "qy_old", "qx", "qy", "h"};
  gr_status st = gr_rain_runoff_arg_indices(s, s->li_step, step, 9, s->ix_step);
  if (st == GR_OK)
    st = gr_rain_runoff_arg_indices(s, s->flux_edges, edges, 6, s->ix_edges);
  if (st == GR_OK)
    st = gr_rain_runoff_arg_indices(s, s->flux, flux, 5, s->ix_flux);
  if (st == GR_OK)
    st = gr_rain_runoff_arg_indices(s, s->limit, update, 2, s->ix_limit);
  if (st == GR_OK)
    st = gr_rain_runoff_arg_indices(s, s->update, update, 3, s->ix_update);
  if (st == GR_OK)
    st = gr_rain_runoff_arg_indices(s, s->limit_update, update, 5, s->ix_lu);
  static const char *const rain[] = {"rain_uniform"};
  cl_kernel li[6] = {s->flux_edges, s->li_step, s->flux, s->limit, s->update, s->limit_update};
  for (int k = 0; st == GR_OK && k < 6; ++k)
    st = gr_rain_runoff_arg_indices(s, li[k], rain, 1, &s->ix_rain[k]);
  return st;
}

/* The device's largest work-group and its local memory (bytes). */
static cl_int gr_rain_runoff_group_limits(const gr_rain_runoff *s, size_t *most,
                                          cl_ulong *local_mem) {
  cl_device_id dev = gr_context_device(s->ctx);
  cl_int err = clGetDeviceInfo(dev, CL_DEVICE_MAX_WORK_GROUP_SIZE, sizeof(*most), most, NULL);
  if (err == CL_SUCCESS)
    err = clGetDeviceInfo(dev, CL_DEVICE_LOCAL_MEM_SIZE, sizeof(*local_mem), local_mem, NULL);
  return err;
}

/* The fused local inertial step's work-group (rain_runoff_li_step: a tile
 * 3 cells smaller each way, whose faces it computes again for the ring
 * around the tile) and whether it is the default. A GPU: the largest of 32
 * x 16, 16 x 16, 16 x 8 and 8 x 8 that the kernel's registers and the local
 * memory allow (a tile of 29 x 13 computes 1.36 times the faces of its
 * cells, 13 x 13 1.5 times; the redundant reads hit the caches); one launch
 * by default, the step's traffic in one pass. A CPU: 64 x 16 (61 x 13), three launches by default:
 * with PoCL on this project's 2-core machine the one launch took about 1.5 times the CPU time of
 * the three at 256^2 to 1024^2 (its ring's faces again, every cell's limiter five times, and LLVM's
 * code for its two regions), where the caches hide most of what the three launches read again. */
static gr_status gr_rain_runoff_li_shape(gr_rain_runoff *s) {
  cl_ulong local_mem = 0;
  size_t most = 0, wg = 0;
  cl_int err = gr_rain_runoff_group_limits(s, &most, &local_mem);
  if (err == CL_SUCCESS)
    err = clGetKernelWorkGroupInfo(s->li_step, gr_context_device(s->ctx), CL_KERNEL_WORK_GROUP_SIZE,
                                   sizeof(wg), &wg, NULL);
  if (err != CL_SUCCESS)
    return gr_cl_check(s->ctx, err, "Querying the device for the local inertial step's work-group");
  static const size_t gpu_shapes[][2] = {{32, 16}, {16, 16}, {16, 8}, {8, 8}, {8, 8}};
  static const size_t cpu_shapes[][2] = {{64, 16}, {32, 16}, {16, 16}, {16, 8}, {8, 8}};
  const size_t(*shapes)[2] = s->gpu ? gpu_shapes : cpu_shapes;
  int fits = 0;
  for (int k = 0; k < 5 && !fits; ++k) {
    s->li_local[0] = shapes[k][0];
    s->li_local[1] = shapes[k][1];
    size_t items = shapes[k][0] * shapes[k][1];
    fits = items <= wg && 3 * items * sizeof(cl_float) <= local_mem;
  }
  /* Where not even 8 x 8 fits (a tile of 5 x 5), the three launches only. */
  if (!fits)
    s->li_local[0] = s->li_local[1] = 0;
  /* Not the default anywhere (gr_rain_runoff_create): the fused step
   * recomputes the ring's faces and each cell's limiter five times, and
   * measured slower on both kinds of device (the H200 at 4096^2: 1.34 ms a
   * step against 1.14; PoCL here about 1.5x). gr_rain_runoff_set_fused
   * picks it, where the device allows its work-group. */
  s->fused = s->fused && s->li_local[0] > 0;
  return GR_OK;
}

gr_status gr_rain_runoff_fill(gr_rain_runoff *s, cl_mem buf, float value, size_t bytes) {
  return gr_cl_check(s->ctx,
                     clEnqueueFillBuffer(gr_context_queue(s->ctx), buf, &value, sizeof(value), 0,
                                         bytes, 0, NULL, NULL),
                     "Filling a device buffer");
}

/* Discharges none, limiters 1 (nothing was limited). */
gr_status gr_rain_runoff_clear_flow(gr_rain_runoff *s) {
  size_t nx = (size_t)s->nxl, ny = (size_t)s->nyl;
  gr_status st = GR_OK;
  for (int a = 0; a < 2 && st == GR_OK; ++a) {
    st = gr_rain_runoff_fill(s, s->qx[a], 0.0f, (nx + 1) * ny * sizeof(float));
    if (st == GR_OK)
      st = gr_rain_runoff_fill(s, s->qy[a], 0.0f, nx * (ny + 1) * sizeof(float));
  }
  if (st == GR_OK)
    st = gr_rain_runoff_fill(s, s->k, 1.0f, nx * ny * sizeof(float));
  if (st == GR_OK)
    st = gr_rain_runoff_fill(s, s->qu, 0.0f, nx * ny * sizeof(float));
  if (st == GR_OK)
    st = gr_rain_runoff_fill(s, s->qv, 0.0f, nx * ny * sizeof(float));
  return st;
}

/* Copies the floats of cells [x0, x0+w) x [y0, y0+h) of a local array with
 * `comps` floats per cell and rows of `pitch` cells between the device and
 * a packed host block (w * comps floats per row); waits. */
gr_status gr_rain_runoff_rect(gr_rain_runoff *s, cl_mem buf, size_t pitch, size_t comps, size_t x0,
                              size_t y0, size_t w, size_t h, void *host, int write) {
  const size_t f = sizeof(cl_float) * comps;
  size_t origin[3] = {x0 * f, y0, 0}, host_origin[3] = {0, 0, 0}, region[3] = {w * f, h, 1};
  cl_command_queue q = gr_context_queue(s->ctx);
  cl_int err = write ? clEnqueueWriteBufferRect(q, buf, CL_TRUE, origin, host_origin, region,
                                                pitch * f, 0, w * f, 0, host, 0, NULL, NULL)
                     : clEnqueueReadBufferRect(q, buf, CL_TRUE, origin, host_origin, region,
                                               pitch * f, 0, w * f, 0, host, 0, NULL, NULL);
  return gr_cl_check(s->ctx, err,
                     write ? "Writing a halo strip to the device"
                           : "Reading part of a field back from the device");
}

/* Reads the owned cells of a local array (comps floats per cell): the whole
 * array for a grid without a ring. */
gr_status gr_rain_runoff_read_own(gr_rain_runoff *s, cl_mem buf, size_t comps, float *host) {
  if (!gr_rain_runoff_has_ring(s))
    return gr_buffer_read(s->ctx, buf, 0, gr_rain_runoff_cells(s) * comps * sizeof(cl_float), host);
  return gr_rain_runoff_rect(s, buf, (size_t)s->nxl, comps, (size_t)s->ring[0], (size_t)s->ring[2],
                             (size_t)s->grid.nx, (size_t)s->grid.ny, host, 0);
}

/* Sums the stored, infiltrated, outflow and inflow depths over the owned
 * cells in fixed point (m, so times dx dy for m^3; sums NULL: none) and
 * finds the deepest cell. */
gr_status gr_rain_runoff_reduce_fixed(gr_rain_runoff *s, gr_fixed sums[GR_RAIN_RUNOFF_SUMS],
                                      double *max_depth) {
  cl_int n = (cl_int)gr_rain_runoff_cells(s);
  /* The owned cells of the local arrays (masked only where there is a ring). */
  cl_int row = s->nxl, own_x0 = s->ring[0], own_x1 = s->nxl - s->ring[1];
  cl_int own_y0 = s->ring[2], own_y1 = s->nyl - s->ring[3];
  cl_int masked = gr_rain_runoff_has_ring(s), with_sums = sums != NULL;
  const gr_rain_runoff_arg args[] = {
      {"with_sums", sizeof(with_sums), &with_sums},
      {"h", sizeof(cl_mem), &s->h},
      {"h_comp", sizeof(cl_mem), &s->h_c},
      {"infiltrated", sizeof(cl_mem), &s->inf},
      {"infiltrated_comp", sizeof(cl_mem), &s->inf_c},
      {"outflow", sizeof(cl_mem), &s->out},
      {"outflow_comp", sizeof(cl_mem), &s->out_c},
      {"inflow", sizeof(cl_mem), &s->in},
      {"inflow_comp", sizeof(cl_mem), &s->in_c},
      {"n", sizeof(n), &n},
      {"row", sizeof(row), &row},
      {"own_x0", sizeof(own_x0), &own_x0},
      {"own_x1", sizeof(own_x1), &own_x1},
      {"own_y0", sizeof(own_y0), &own_y0},
      {"own_y1", sizeof(own_y1), &own_y1},
      {"masked", sizeof(masked), &masked},
  };
  long long words[2 * GR_RAIN_RUNOFF_SUMS], maxes[GR_RAIN_RUNOFF_MAXES];
  gr_status st = GR_RAIN_RUNOFF_ARGS(s, s->reduce, args);
  if (st == GR_OK)
    st = gr_reduction_i64_run_max(s->ctx, &s->ledger, s->reduce, words, maxes);
  if (st != GR_OK)
    return st;
  for (int q = 0; sums && q < GR_RAIN_RUNOFF_SUMS; ++q) {
    sums[q].coarse = words[2 * q];
    sums[q].fine = words[2 * q + 1];
  }
  if (max_depth) {
    /* The deepest cell's float, by its bits (a depth is never below 0). */
    int32_t bits = (int32_t)maxes[0];
    float deepest;
    memcpy(&deepest, &bits, sizeof(deepest));
    *max_depth = deepest;
  }
  return GR_OK;
}

/* The deepest owned cell only (the stable step): the ledger's reduction
 * reading the depth alone. */
gr_status gr_rain_runoff_deepest(gr_rain_runoff *s, double *max_depth) {
  return gr_rain_runoff_reduce_fixed(s, NULL, max_depth);
}

/* The local memory of a fused shallow-water stage's tile of tx x ty cells
 * (gr_sw_fused): its points with two cells either side (a float4 each),
 * six planes of x-faces and six of y-faces. */
static size_t gr_rain_runoff_sw_tile_bytes(size_t tx, size_t ty) {
  return sizeof(cl_float) * (4 * (tx + 4) * (ty + 4) + 6 * ((tx + 1) * ty + tx * (ty + 1)));
}

/* The default tile of a device whose work-groups take at most `most`
 * work-items and local_mem bytes: 32 x 8, halved until it fits. Measured
 * on the H200 at 4096^2 (ms a step): 32 x 8 1.51, 64 x 4 1.59, 32 x 4 1.63
 * (and before the interior's kernel and the register cap, 16 x 8 2.48,
 * 16 x 16 2.50 against 32 x 8 2.16); with the tile's size built into the
 * kernels, 32 x 8 1.12, 16 x 16 1.76. */
static void gr_rain_runoff_sw_default_tile(size_t most, cl_ulong local_mem, size_t *tx,
                                           size_t *ty) {
  *tx = 32;
  *ty = 8;
  while (*ty > 1 && (*tx * *ty > most || gr_rain_runoff_sw_tile_bytes(*tx, *ty) > local_mem))
    *ty /= 2;
  while (*tx > 1 && (*tx * *ty > most || gr_rain_runoff_sw_tile_bytes(*tx, *ty) > local_mem))
    *tx /= 2;
}

/* The fused shallow-water stages' work-group (rain_runoff_sw_stage1, 2): a
 * tile of tx x ty cells (0 x 0: the device's default), refused where the
 * device's work-groups or local memory are too small for it; with
 * set_default also whether the fused path is the default. A GPU: fused by
 * default (a step moves the state twice instead of storing and reading
 * every face and point, see gr_sw_fused; the H200 at 4096^2: 2.16 ms a step
 * against 2.65). A CPU: not fused by default: with PoCL
 * on this project's 2-core machine a fused step took 4-7x the separate
 * launches' time (512^2: 32-35 ms against 7.7-8.5; 1024^2: 160-250 ms
 * against 36), where the caches hide most of what the separate launches
 * store and read again. */
gr_status gr_rain_runoff_sw_shape(gr_rain_runoff *s, size_t tx, size_t ty, int set_default) {
  cl_device_id dev = gr_context_device(s->ctx);
  cl_ulong local_mem = 0;
  size_t most = 0;
  cl_int err = gr_rain_runoff_group_limits(s, &most, &local_mem);
  /* The smallest work-group any of the four kernels takes. A local
   * inertial program has no stages: the device's largest work-group until
   * the model changes, when the tile is checked again
   * (gr_rain_runoff_specialise). */
  cl_kernel stages[4] = {s->sw_stage[0], s->sw_stage[1], s->sw_inner[0], s->sw_inner[1]};
  for (int k = 0; err == CL_SUCCESS && k < 4; ++k) {
    size_t wg = most;
    if (stages[k])
      err = clGetKernelWorkGroupInfo(stages[k], dev, CL_KERNEL_WORK_GROUP_SIZE, sizeof(wg), &wg,
                                     NULL);
    most = wg < most ? wg : most;
  }
  if (err != CL_SUCCESS)
    return gr_cl_check(s->ctx, err, "Querying the device for the shallow-water stages' work-group");
  if (tx == 0 && ty == 0)
    gr_rain_runoff_sw_default_tile(most, local_mem, &tx, &ty);
  size_t bytes = gr_rain_runoff_sw_tile_bytes(tx, ty);
  if (tx == 0 || ty == 0 || tx * ty > most || bytes > local_mem)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The shallow-water tile of %zu x %zu cells does not fit the device: it "
                        "takes at most %zu work-items and %llu bytes of local memory (the tile "
                        "needs %zu); take a smaller tile, or 0 x 0 for the device's default.",
                        tx, ty, most, (unsigned long long)local_mem, bytes);
  s->sw_local[0] = tx;
  s->sw_local[1] = ty;
  s->sw_tile_bytes = bytes;
  /* The interior's tiles: those whose faces all lie two cells or more
   * inside the local array (i0 >= 2, i0 + tx + 2 <= nx, and so along y);
   * with none, every tile is the rim's (rows 0 .. ntj - 1 below an empty
   * interior). */
  size_t nti = ((size_t)s->nxl + tx - 1) / tx, ntj = ((size_t)s->nyl + ty - 1) / ty;
  size_t ilo = (2 + tx - 1) / tx, ihi = s->nxl >= 2 ? ((size_t)s->nxl - 2) / tx : 0;
  size_t jlo = (2 + ty - 1) / ty, jhi = s->nyl >= 2 ? ((size_t)s->nyl - 2) / ty : 0;
  if (ihi <= ilo || jhi <= jlo) {
    ilo = ihi = 0;
    jlo = jhi = ntj;
  }
  s->sw_tiles[0] = (cl_int)ilo;
  s->sw_tiles[1] = (cl_int)ihi;
  s->sw_tiles[2] = (cl_int)jlo;
  s->sw_tiles[3] = (cl_int)jhi;
  s->sw_rim = nti * ntj - (ihi - ilo) * (jhi - jlo);
  if (set_default)
    s->sw_fused = s->gpu;
  s->args_set = 0;
  return GR_OK;
}

/* The ledger's and the stable steps' reductions, (re)made for their
 * kernels' work-groups. */
gr_status gr_rain_runoff_reductions(gr_rain_runoff *s) {
  size_t cells = (size_t)s->nxl * (size_t)s->nyl;
  gr_reduction_i64_release(&s->ledger);
  gr_reduction_release(&s->speed);
  gr_reduction_release(&s->film);
  gr_status st = gr_reduction_i64_init_max(s->ctx, s->reduce, cells, 2 * GR_RAIN_RUNOFF_SUMS,
                                           GR_RAIN_RUNOFF_MAXES, &s->ledger);
  if (st == GR_OK && s->sw_speed) /* a shallow-water program's */
    st = gr_reduction_init(s->ctx, s->sw_speed, cells, 0, 2, &s->speed);
  if (st == GR_OK)
    st = gr_reduction_init(s->ctx, s->li_speed, cells, 0, 1, &s->film);
  return st;
}

/* The optional inputs in use, GR_RAIN_RUNOFF_IN_* bits. */
static int gr_rain_runoff_inputs_used(const gr_rain_runoff *s) {
  return (s->has_rain ? GR_RAIN_RUNOFF_IN_RAIN : 0) | (s->has_perm ? GR_RAIN_RUNOFF_IN_PERM : 0) |
         (gr_rain_runoff_has_sources(s) ? GR_RAIN_RUNOFF_IN_SRC : 0) |
         (s->has_nodata ? GR_RAIN_RUNOFF_IN_NODATA : 0) | (s->has_n2 ? GR_RAIN_RUNOFF_IN_N2 : 0);
}

/* Takes every kernel from the program built for the inputs in use (every
 * input where specialise is 0) when they are not already from it: the
 * program is found or built (gr_program_get: once per context and
 * options), the kernels made, and only then the old ones released; the
 * argument indices, the fused work-groups, the reductions and the
 * arguments follow. Called at creation, by the setters of inputs
 * (gr_rain_runoff_inputs_changed), and before every batch of steps and
 * every local inertial stable step (a switch of specialise, or a build
 * that failed before). */
gr_status gr_rain_runoff_specialise(gr_rain_runoff *s) {
  /* The inputs' bits, and the shallow-water kernels above them: a local
   * inertial simulation's program leaves those out. */
  int sw = !s->specialise || s->params.flow_model == GR_FLOW_SHALLOW_WATER;
  int inputs = s->specialise ? gr_rain_runoff_inputs_used(s) : GR_RAIN_RUNOFF_IN_ALL;
  int want = inputs | (sw ? GR_RAIN_RUNOFF_IN_ALL + 1 : 0);
  /* A GPU's shallow-water program is built for its tile (GR_SW_TILE_X, Y:
   * the one set, or before one is the device's default): the fused stages
   * then take only that work-group. */
  size_t tile[2] = {0, 0};
  if (s->gpu && sw) {
    tile[0] = s->sw_local[0];
    tile[1] = s->sw_local[1];
    cl_ulong local_mem = 0;
    size_t most = 0;
    if (tile[0] == 0 && gr_rain_runoff_group_limits(s, &most, &local_mem) == CL_SUCCESS)
      gr_rain_runoff_sw_default_tile(most, local_mem, &tile[0], &tile[1]);
  }
  if (want == s->inputs && tile[0] == s->sw_built[0] && tile[1] == s->sw_built[1])
    return GR_OK;
  static const char *const names[] = {
      "rain_runoff_flux",       "rain_runoff_flux_edges", "rain_runoff_limit",
      "rain_runoff_update",     "rain_runoff_li_step",    "rain_runoff_sw_prep",
      "rain_runoff_sw_faces1",  "rain_runoff_sw_faces2",  "rain_runoff_sw_update1",
      "rain_runoff_sw_update2", "rain_runoff_sw_edges",   "rain_runoff_sw_stage1",
      "rain_runoff_sw_stage2",  "rain_runoff_reduce",     "rain_runoff_derive",
      "rain_runoff_sw_speed",   "rain_runoff_li_speed",   "rain_runoff_maps",
      "rain_runoff_source",     "rain_runoff_sw_inner1",  "rain_runoff_sw_inner2",
      "rain_runoff_sw_rim1",    "rain_runoff_sw_rim2",    "rain_runoff_limit_update"};
  enum { GR_RR_KERNELS = sizeof(names) / sizeof(names[0]) };
  /* The shallow-water model's kernels (none in a local inertial program). */
  static const unsigned char sw_only[GR_RR_KERNELS] = {0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1,
                                                       1, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1, 0};
  cl_kernel *slots[GR_RR_KERNELS] = {&s->flux,
                                     &s->flux_edges,
                                     &s->limit,
                                     &s->update,
                                     &s->li_step,
                                     &s->sw_prep,
                                     &s->sw_faces[0],
                                     &s->sw_faces[1],
                                     &s->sw_update[0],
                                     &s->sw_update[1],
                                     &s->sw_edges,
                                     &s->sw_stage[0],
                                     &s->sw_stage[1],
                                     &s->reduce,
                                     &s->derive,
                                     &s->sw_speed,
                                     &s->li_speed,
                                     &s->maps,
                                     &s->source,
                                     &s->sw_inner[0],
                                     &s->sw_inner[1],
                                     &s->sw_rim_faces[0],
                                     &s->sw_rim_faces[1],
                                     &s->limit_update};
  char opt[224] = "";
  int len = 0;
  if (s->specialise)
    len = snprintf(opt, sizeof(opt), "-DGR_RAIN_RUNOFF_INPUTS=%d -DGR_RAIN_RUNOFF_SW=%d ", inputs,
                   sw);
  if (s->gpu)
    len += snprintf(opt + len, sizeof(opt) - (size_t)len, "-DGR_RAIN_RUNOFF_GPU=1 ");
  if (tile[0] > 0)
    len += snprintf(opt + len, sizeof(opt) - (size_t)len, "-DGR_SW_TILE_X=%zu -DGR_SW_TILE_Y=%zu ",
                    tile[0], tile[1]);
  if (s->nv_registers && sw)
    snprintf(opt + len, sizeof(opt) - (size_t)len, "-cl-nv-maxrregcount=%d",
             GR_RAIN_RUNOFF_NV_REGISTERS);
  cl_program prog = NULL;
  gr_status st = gr_program_get(s->ctx, "rain_runoff", opt[0] ? opt : NULL, &prog);
  cl_kernel made[GR_RR_KERNELS] = {NULL};
  for (int k = 0; st == GR_OK && k < GR_RR_KERNELS; ++k)
    if (sw || !sw_only[k])
      st = gr_kernel_create(s->ctx, prog, names[k], &made[k]);
  if (st != GR_OK) {
    for (int k = 0; k < GR_RR_KERNELS; ++k)
      if (made[k])
        clReleaseKernel(made[k]);
    return st;
  }
  int first = s->inputs < 0;
  for (int k = 0; k < GR_RR_KERNELS; ++k) {
    if (*slots[k])
      clReleaseKernel(*slots[k]);
    *slots[k] = made[k];
  }
  /* Until all that follows holds, the next call builds them again. */
  s->inputs = -1;
  s->sw_built[0] = tile[0];
  s->sw_built[1] = tile[1];
  s->args_set = 0;
  s->maps_bound = 0;
  st = gr_rain_runoff_step_indices(s);
  if (st == GR_OK)
    st = gr_rain_runoff_li_shape(s);
  /* The shallow-water tile, checked against the new kernels (at creation
   * the caller picks the default); one that no longer fits becomes it. */
  if (st == GR_OK && !first && gr_rain_runoff_sw_shape(s, s->sw_local[0], s->sw_local[1], 0))
    st = gr_rain_runoff_sw_shape(s, 0, 0, 0);
  /* The reductions' work-groups, from their new kernels (at creation the
   * caller makes them). */
  if (st == GR_OK && !first)
    st = gr_rain_runoff_reductions(s);
  if (st == GR_OK)
    s->inputs = want;
  /* A tile that had to change (it no longer fitted): built for the new one. */
  if (st == GR_OK && !first && tile[0] > 0 &&
      (s->sw_local[0] != tile[0] || s->sw_local[1] != tile[1]))
    st = gr_rain_runoff_specialise(s);
  return st;
}

/* After a setter (its status st) that may have changed the inputs in use:
 * the kernels follow at once. Kernels built for more inputs than are in use
 * are right too; where a build fails (out of memory), the kernels that read
 * inputs (the steps' and the local inertial stable step's) are made again
 * before they next run: gr_rain_runoff_enqueue and
 * gr_rain_runoff_stable_dt_impl call gr_rain_runoff_specialise first. The
 * other kernels read no optional input. */
gr_status gr_rain_runoff_inputs_changed(gr_rain_runoff *s, gr_status st) {
  return st == GR_OK ? gr_rain_runoff_specialise(s) : st;
}

void gr_rain_runoff_set_specialised(gr_rain_runoff *s, int on) {
  if (s)
    s->specialise = on != 0;
}

/* The public bits are the kernels' (rain_runoff_shared.h). */
_Static_assert(GR_RAIN_RUNOFF_INPUT_RAIN == GR_RAIN_RUNOFF_IN_RAIN &&
                   GR_RAIN_RUNOFF_INPUT_PERMEABILITY == GR_RAIN_RUNOFF_IN_PERM &&
                   GR_RAIN_RUNOFF_INPUT_INFLOWS == GR_RAIN_RUNOFF_IN_SRC &&
                   GR_RAIN_RUNOFF_INPUT_NO_DATA == GR_RAIN_RUNOFF_IN_NODATA &&
                   GR_RAIN_RUNOFF_INPUT_MANNING == GR_RAIN_RUNOFF_IN_N2 &&
                   GR_RAIN_RUNOFF_INPUT_ALL == GR_RAIN_RUNOFF_IN_ALL,
               "the optional inputs' bits");

int gr_rain_runoff_specialised_for(const gr_rain_runoff *s) {
  return s && s->inputs >= 0 ? s->inputs & GR_RAIN_RUNOFF_IN_ALL : -1;
}

void gr_rain_runoff_set_sw_fused(gr_rain_runoff *s, int on) {
  if (s)
    s->sw_fused = on != 0;
}

gr_status gr_rain_runoff_set_sw_tile(gr_rain_runoff *s, int tx, int ty) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_set_sw_tile needs a simulation.");
  if (tx < 0 || ty < 0 || (tx == 0) != (ty == 0))
    return GR_RAIN_RUNOFF_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The shallow-water tile of %d x %d cells is not a tile: give two positive "
                        "sizes, or 0 x 0 for the device's default.",
                        tx, ty));
  return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_rain_runoff_sw_shape(s, (size_t)tx, (size_t)ty, 0));
}

void gr_rain_runoff_set_fused(gr_rain_runoff *s, int on) {
  if (!s)
    return;
  s->fused = on != 0 && s->li_local[0] > 0; /* the device allows its work-group */
  s->args_set = 0;
}
