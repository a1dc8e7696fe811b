/* Rain runoff core (seed 004's water simulation): host side of
 * rain_runoff.cl. The model, the step order and the book-keeping are
 * documented in graupel/rain_runoff.h; the kernels' data layout in
 * rain_runoff.cl. */
#include "graupel/rain_runoff.h"
#include "graupel/cl_runtime.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Floats per work-group in the reduction's output (see rain_runoff_reduce). */
#define GR_RAIN_RUNOFF_SLOTS 7
/* Work-groups of the reduction: enough to fill a GPU, few enough that the
 * host's final sum is instant. */
#define GR_RAIN_RUNOFF_REDUCE_GROUPS 256
#define GR_RAIN_RUNOFF_REDUCE_LOCAL 64
/* Kernels index cells and faces with int: (nx+1)*(ny+1), with room to
 * spare, must stay below INT_MAX. */
#define GR_RAIN_RUNOFF_MAX_FACES ((double)INT_MAX - 1048576.0)
/* Physical sanity bounds set_field adds to field_validate's (finite, and in
 * the parameters' ranges): beyond them float differences overflow. */
#define GR_RAIN_RUNOFF_MAX_ELEVATION 1.0e6
#define GR_RAIN_RUNOFF_MAX_DEPTH 1.0e4
#define GR_RAIN_RUNOFF_MAX_DT 3600.0
#define GR_RAIN_RUNOFF_MIN_DT 1.0e-30
/* The weight of a face's own previous discharge against its neighbours'
 * (de Almeida et al. 2012; 1 is Bates et al. 2010 unchanged). */
#define GR_RAIN_RUNOFF_THETA 0.8
/* advance re-reads the stable step after 4 to 64 steps. */
#define GR_RAIN_RUNOFF_CHUNK_MIN 4
#define GR_RAIN_RUNOFF_CHUNK_MAX 64

struct gr_rain_runoff {
  gr_context *ctx;
  gr_grid grid;
  gr_rain_runoff_params params;
  cl_kernel flux, limit, update, reduce, derive;
  cl_mem h, h_c, b, k, inf, inf_c, out, out_c, partial;
  cl_mem qx[2], qy[2]; /* discharges; [cur] is the latest, the other the next */
  int cur;
  cl_mem h0;      /* initial depth, once WATER_DEPTH was set */
  cl_mem rain;    /* rain-rate field, once set */
  cl_mem perm;    /* permeability field, once set */
  cl_mem scratch; /* derived fields on read (3 floats per cell), on first use */
  cl_mem dummy;   /* bound in place of a field that was not set */
  int has_rain, has_perm;
  double rain_field_sum; /* sum of the rain-rate field's floats, m/s */
  double initial_sum;    /* sum of the initial depth's floats, m */
  double initial_volume, rain_volume, time;
  long long steps;
  size_t reduce_local, reduce_groups;
  float *partial_host;
};

void gr_rain_runoff_params_init(gr_rain_runoff_params *p) {
  if (!p)
    return;
  memset(p, 0, sizeof(*p));
  p->rain_rate = 10.0 / 3.6e6; /* 10 mm/h */
  p->permeability = 0.0;
  p->manning_n = 0.03;
  p->cfl = 0.7;
  p->max_dt = 1.0;
  p->boundary = GR_BOUNDARY_OPEN;
}

static int gr_in_range(double v, double lo, double hi) {
  return v >= lo && v <= hi; /* false for NaN */
}

gr_status gr_rain_runoff_params_validate(const gr_rain_runoff_params *p, char *msg,
                                         size_t msg_len) {
  const char *why = NULL;
  if (!p)
    why = "no parameters were given";
  else if (!gr_in_range(p->rain_rate, 0.0, 1e-3))
    why = "RainRate must lie between 0 and 0.001 m/s (3600 mm/h)";
  else if (!gr_in_range(p->permeability, 0.0, 1e-2))
    why = "Permeability must lie between 0 and 0.01 m/s (36000 mm/h)";
  else if (!gr_in_range(p->manning_n, 0.005, 1.0))
    why = "ManningN must lie between 0.005 and 1 s/m^(1/3)";
  else if (!(p->cfl > 0.0) || p->cfl > 1.0)
    why = "CourantNumber (cfl) must be above 0 and at most 1";
  else if (!(p->max_dt > 0.0) || p->max_dt > GR_RAIN_RUNOFF_MAX_DT)
    why = "MaxTimeStep must be above 0 and at most 3600 s";
  else if (p->boundary != GR_BOUNDARY_OPEN && p->boundary != GR_BOUNDARY_CLOSED)
    why = "Boundary must be 0 (open) or 1 (closed)";
  if (!why)
    return GR_OK;
  if (msg && msg_len)
    snprintf(msg, msg_len, "Invalid rain runoff parameters: %s.", why);
  return GR_ERR_INVALID_ARGUMENT;
}

static const char *gr_rain_runoff_field_label(gr_field f) {
  const char *name = gr_field_name(f);
  return name ? name : "(unknown field)";
}

/* field_validate's checks; with nx > 0 the bad value is named by its cell
 * (i, j), otherwise by its index. strict adds set_field's sanity bounds. */
static gr_status gr_rain_runoff_field_check(gr_field f, const float *values, size_t n, size_t nx,
                                            int strict, char *msg, size_t msg_len) {
  const char *rule = NULL;
  double lo = -HUGE_VAL, hi = HUGE_VAL;
  switch (f) {
  case GR_FIELD_ELEVATION:
    rule = strict ? "elevations must be finite and within +-1e6 m" : "elevations must be finite";
    if (strict) {
      lo = -GR_RAIN_RUNOFF_MAX_ELEVATION;
      hi = GR_RAIN_RUNOFF_MAX_ELEVATION;
    }
    break;
  case GR_FIELD_WATER_DEPTH:
    rule = strict ? "depths must be finite, at least 0 and at most 1e4 m"
                  : "depths must be finite and at least 0 m";
    lo = 0.0;
    if (strict)
      hi = GR_RAIN_RUNOFF_MAX_DEPTH;
    break;
  case GR_FIELD_PERMEABILITY:
    rule = "permeabilities must lie between 0 and 0.01 m/s, like Permeability";
    lo = 0.0;
    hi = 1e-2;
    break;
  case GR_FIELD_RAIN_RATE:
    rule = "rain rates must lie between 0 and 0.001 m/s, like RainRate";
    lo = 0.0;
    hi = 1e-3;
    break;
  default:
    if (msg && msg_len)
      snprintf(msg, msg_len,
               "The field '%s' is not an input of the rain runoff simulation; its inputs are "
               "elevation, water_depth, permeability and rain_rate.",
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
    if (isfinite(v) && v >= lo && v <= hi)
      continue;
    if (msg && msg_len) {
      if (nx > 0)
        snprintf(msg, msg_len, "The field '%s' has the value %g at cell (%zu, %zu): %s.",
                 gr_rain_runoff_field_label(f), v, c % nx, c / nx, rule);
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

/* ----------------------------------------------------------- device state */

static size_t gr_rain_runoff_cells(const gr_rain_runoff *s) {
  return (size_t)s->grid.nx * (size_t)s->grid.ny;
}

static gr_status gr_rain_runoff_fill(gr_rain_runoff *s, cl_mem buf, float value, size_t bytes) {
  return gr_cl_check(s->ctx,
                     clEnqueueFillBuffer(gr_context_queue(s->ctx), buf, &value, sizeof(value), 0,
                                         bytes, 0, NULL, NULL),
                     "Filling a device buffer");
}

/* Discharges none, limiters 1 (nothing was limited). */
static gr_status gr_rain_runoff_clear_flow(gr_rain_runoff *s) {
  size_t nx = (size_t)s->grid.nx, ny = (size_t)s->grid.ny;
  gr_status st = GR_OK;
  for (int a = 0; a < 2 && st == GR_OK; ++a) {
    st = gr_rain_runoff_fill(s, s->qx[a], 0.0f, (nx + 1) * ny * sizeof(float));
    if (st == GR_OK)
      st = gr_rain_runoff_fill(s, s->qy[a], 0.0f, nx * (ny + 1) * sizeof(float));
  }
  if (st == GR_OK)
    st = gr_rain_runoff_fill(s, s->k, 1.0f, nx * ny * sizeof(float));
  return st;
}

/* Sums the stored, infiltrated and outflow depths over the cells (m, so
 * times dx dy for m^3) and finds the deepest cell. */
static gr_status gr_rain_runoff_reduce(gr_rain_runoff *s, double sums[3], double *max_depth) {
  cl_int n = (cl_int)gr_rain_runoff_cells(s);
  const size_t m = sizeof(cl_mem);
  gr_status st = gr_kernel_args(s->ctx, s->reduce, m, &s->h, m, &s->h_c, m, &s->inf, m, &s->inf_c,
                                m, &s->out, m, &s->out_c, m, &s->partial,
                                s->reduce_local * GR_RAIN_RUNOFF_SLOTS * sizeof(cl_float), NULL,
                                sizeof(cl_int), &n, (size_t)0);
  if (st != GR_OK)
    return st;
  size_t global = s->reduce_groups * s->reduce_local;
  st = gr_cl_check(s->ctx,
                   clEnqueueNDRangeKernel(gr_context_queue(s->ctx), s->reduce, 1, NULL, &global,
                                          &s->reduce_local, 0, NULL, NULL),
                   "Enqueueing the rain runoff reduction");
  if (st == GR_OK)
    st =
        gr_buffer_read(s->ctx, s->partial, 0,
                       s->reduce_groups * GR_RAIN_RUNOFF_SLOTS * sizeof(cl_float), s->partial_host);
  if (st != GR_OK)
    return st;
  double acc[3] = {0.0, 0.0, 0.0}, hmax = 0.0;
  for (size_t grp = 0; grp < s->reduce_groups; ++grp) {
    const float *p = s->partial_host + GR_RAIN_RUNOFF_SLOTS * grp;
    for (int q = 0; q < 3; ++q)
      acc[q] += (double)p[2 * q] + (double)p[2 * q + 1];
    hmax = p[6] > hmax ? p[6] : hmax;
  }
  for (int q = 0; q < 3; ++q)
    sums[q] = acc[q];
  if (max_depth)
    *max_depth = hmax;
  return GR_OK;
}

/* ------------------------------------------------------------- life cycle */

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

  size_t nx = (size_t)grid->nx, ny = (size_t)grid->ny, cells = nx * ny;
  if (((double)nx + 1.0) * ((double)ny + 1.0) > GR_RAIN_RUNOFF_MAX_FACES)
    return gr_set_error(ctx, GR_ERR_TOO_LARGE,
                        "The rain runoff grid of %zu x %zu points is too large: the kernels "
                        "address at most about 2.1e9 faces; split the domain or coarsen it.",
                        nx, ny);
  /* The state that is always there: depth, elevation, limiter, infiltrated
   * and outflow with their compensations (8 per cell) and two sets of face
   * arrays. Refuse before allocating when the device cannot hold it. */
  gr_device_info info;
  gr_status st = gr_context_device_info(ctx, &info);
  if (st != GR_OK)
    return st;
  double need = 4.0 * (8.0 * (double)cells + 2.0 * ((double)(nx + 1) * ny + (double)nx * (ny + 1)));
  if (need > (double)info.global_mem_bytes)
    return gr_set_error(ctx, GR_ERR_TOO_LARGE,
                        "The rain runoff state of a %zu x %zu grid needs %.1f MiB but the device "
                        "'%s' has %.1f MiB: use a smaller grid or another device.",
                        nx, ny, need / 1048576.0, info.name,
                        (double)info.global_mem_bytes / 1048576.0);

  gr_rain_runoff *s = calloc(1, sizeof(*s));
  if (!s)
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  s->ctx = gr_context_retain(ctx);
  s->grid = *grid;
  s->params = *p;
  cl_program prog = NULL;
  size_t bytes = cells * sizeof(cl_float);
  st = gr_program_get(ctx, "rain_runoff", NULL, &prog);
  if (st == GR_OK)
    st = gr_kernel_create(ctx, prog, "rain_runoff_flux", &s->flux);
  if (st == GR_OK)
    st = gr_kernel_create(ctx, prog, "rain_runoff_limit", &s->limit);
  if (st == GR_OK)
    st = gr_kernel_create(ctx, prog, "rain_runoff_update", &s->update);
  if (st == GR_OK)
    st = gr_kernel_create(ctx, prog, "rain_runoff_reduce", &s->reduce);
  if (st == GR_OK)
    st = gr_kernel_create(ctx, prog, "rain_runoff_derive", &s->derive);
  cl_mem *per_cell[] = {&s->h, &s->h_c, &s->b, &s->k, &s->inf, &s->inf_c, &s->out, &s->out_c};
  for (size_t i = 0; st == GR_OK && i < sizeof(per_cell) / sizeof(per_cell[0]); ++i)
    st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, bytes, NULL, per_cell[i]);
  for (int a = 0; a < 2 && st == GR_OK; ++a) {
    st =
        gr_buffer_create(ctx, CL_MEM_READ_WRITE, (nx + 1) * ny * sizeof(cl_float), NULL, &s->qx[a]);
    if (st == GR_OK)
      st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, nx * (ny + 1) * sizeof(cl_float), NULL,
                            &s->qy[a]);
  }
  if (st == GR_OK)
    st = gr_buffer_create(ctx, CL_MEM_READ_ONLY, sizeof(cl_float), NULL, &s->dummy);
  if (st == GR_OK) {
    /* The reduction's work-group: a power of two the kernel allows. */
    size_t kmax = 0;
    cl_int err = clGetKernelWorkGroupInfo(s->reduce, gr_context_device(ctx),
                                          CL_KERNEL_WORK_GROUP_SIZE, sizeof(kmax), &kmax, NULL);
    st = gr_cl_check(ctx, err, "Querying the reduction's work-group size");
    s->reduce_local = 1;
    while (s->reduce_local * 2 <= GR_RAIN_RUNOFF_REDUCE_LOCAL && s->reduce_local * 2 <= kmax)
      s->reduce_local *= 2;
    s->reduce_groups = (cells + s->reduce_local - 1) / s->reduce_local;
    if (s->reduce_groups > GR_RAIN_RUNOFF_REDUCE_GROUPS)
      s->reduce_groups = GR_RAIN_RUNOFF_REDUCE_GROUPS;
  }
  if (st == GR_OK)
    st = gr_buffer_create(ctx, CL_MEM_WRITE_ONLY,
                          s->reduce_groups * GR_RAIN_RUNOFF_SLOTS * sizeof(cl_float), NULL,
                          &s->partial);
  if (st == GR_OK) {
    s->partial_host = malloc(s->reduce_groups * GR_RAIN_RUNOFF_SLOTS * sizeof(float));
    if (!s->partial_host)
      st = gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  /* Dry, flat ground; nothing infiltrated or gone. */
  cl_mem *zeroed[] = {&s->h, &s->h_c, &s->b, &s->inf, &s->inf_c, &s->out, &s->out_c, &s->dummy};
  for (size_t i = 0; st == GR_OK && i < sizeof(zeroed) / sizeof(zeroed[0]); ++i)
    st =
        gr_rain_runoff_fill(s, *zeroed[i], 0.0f, *zeroed[i] == s->dummy ? sizeof(cl_float) : bytes);
  if (st == GR_OK)
    st = gr_rain_runoff_clear_flow(s);
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
  cl_kernel kernels[] = {s->flux, s->limit, s->update, s->reduce, s->derive};
  for (size_t i = 0; i < sizeof(kernels) / sizeof(kernels[0]); ++i)
    if (kernels[i])
      clReleaseKernel(kernels[i]);
  cl_mem *bufs[] = {&s->h,       &s->h_c, &s->b,    &s->qx[0], &s->qy[0],   &s->qx[1],
                    &s->qy[1],   &s->k,   &s->inf,  &s->inf_c, &s->out,     &s->out_c,
                    &s->partial, &s->h0,  &s->rain, &s->perm,  &s->scratch, &s->dummy};
  for (size_t i = 0; i < sizeof(bufs) / sizeof(bufs[0]); ++i)
    gr_buffer_release(bufs[i]);
  free(s->partial_host);
  gr_context_release(s->ctx);
  free(s);
}

gr_status gr_rain_runoff_set_params(gr_rain_runoff *s, const gr_rain_runoff_params *p) {
  char msg[256];
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_set_params needs a simulation.");
  if (gr_rain_runoff_params_validate(p, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  s->params = *p;
  return GR_OK;
}

/* Uploads into *buf, allocating it on first use. */
static gr_status gr_rain_runoff_upload(gr_rain_runoff *s, cl_mem *buf, const float *host) {
  size_t bytes = gr_rain_runoff_cells(s) * sizeof(cl_float);
  if (!*buf)
    return gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, bytes, host, buf);
  return gr_buffer_write(s->ctx, *buf, 0, bytes, host);
}

gr_status gr_rain_runoff_set_field(gr_rain_runoff *s, gr_field f, const float *host) {
  char msg[320];
  if (!s || !host)
    return gr_set_error(s ? s->ctx : NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_set_field needs a simulation and the field's values.");
  size_t cells = gr_rain_runoff_cells(s);
  if (gr_rain_runoff_field_check(f, host, cells, (size_t)s->grid.nx, 1, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  gr_status st = GR_OK;
  switch (f) {
  case GR_FIELD_ELEVATION:
    st = gr_buffer_write(s->ctx, s->b, 0, cells * sizeof(cl_float), host);
    break;
  case GR_FIELD_PERMEABILITY:
    st = gr_rain_runoff_upload(s, &s->perm, host);
    if (st == GR_OK)
      s->has_perm = 1;
    break;
  case GR_FIELD_RAIN_RATE: {
    double sum = 0.0;
    for (size_t c = 0; c < cells; ++c)
      sum += host[c];
    st = gr_rain_runoff_upload(s, &s->rain, host);
    if (st == GR_OK) {
      s->has_rain = 1;
      s->rain_field_sum = sum;
    }
    break;
  }
  case GR_FIELD_WATER_DEPTH: {
    /* The new water replaces what is there now: the ledger counts the
     * difference as initial water, so the balance still closes. */
    double now[3], sum = 0.0;
    for (size_t c = 0; c < cells; ++c)
      sum += host[c];
    st = gr_rain_runoff_reduce(s, now, NULL);
    if (st == GR_OK)
      st = gr_rain_runoff_upload(s, &s->h0, host);
    if (st == GR_OK)
      st = gr_buffer_write(s->ctx, s->h, 0, cells * sizeof(cl_float), host);
    if (st == GR_OK)
      st = gr_rain_runoff_fill(s, s->h_c, 0.0f, cells * sizeof(cl_float));
    if (st == GR_OK)
      st = gr_rain_runoff_clear_flow(s);
    if (st == GR_OK) {
      s->initial_sum = sum;
      s->initial_volume += (sum - now[0]) * s->grid.dx * s->grid.dy;
    }
    break;
  }
  default:
    break; /* refused by gr_rain_runoff_field_check */
  }
  return st;
}

/* --------------------------------------------------------------- stepping */

gr_status gr_rain_runoff_step(gr_rain_runoff *s, double dt, int nsteps) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT, "gr_rain_runoff_step needs a simulation.");
  if (!(dt >= GR_RAIN_RUNOFF_MIN_DT && dt <= GR_RAIN_RUNOFF_MAX_DT))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The time step dt must lie between 1e-30 and 3600 s (got %g s).", dt);
  if (nsteps < 0)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The number of steps must be 0 or more (got %d).", nsteps);
  if (nsteps == 0)
    return GR_OK;
  const gr_rain_runoff_params *p = &s->params;
  const gr_grid *gd = &s->grid;
  cl_int nx = gd->nx, ny = gd->ny;
  cl_float dtf = (cl_float)dt;
  cl_float inv_dx = (cl_float)(1.0 / gd->dx), inv_dy = (cl_float)(1.0 / gd->dy);
  cl_float g = (cl_float)GR_GRAVITY;
  cl_float n2 = (cl_float)(p->manning_n * p->manning_n);
  cl_int use_rain = s->has_rain, use_perm = s->has_perm;
  cl_float rain_u = (cl_float)p->rain_rate, perm_u = (cl_float)p->permeability;
  cl_int closed = p->boundary == GR_BOUNDARY_CLOSED;
  cl_mem rain = s->has_rain ? s->rain : s->dummy, perm = s->has_perm ? s->perm : s->dummy;
  cl_float theta = (cl_float)GR_RAIN_RUNOFF_THETA;
  const size_t m = sizeof(cl_mem), fl = sizeof(cl_float), in = sizeof(cl_int);
  /* Every argument but the alternating face arrays (set per step below). */
  gr_status st =
      gr_kernel_args(s->ctx, s->flux, m, &s->h, m, &s->b, m, &rain, m, &perm, m, &s->qx[0], m,
                     &s->qy[0], m, &s->qx[1], m, &s->qy[1], m, &s->k, in, &nx, in, &ny, fl, &dtf,
                     fl, &inv_dx, fl, &inv_dy, fl, &g, fl, &n2, fl, &theta, in, &use_rain, fl,
                     &rain_u, in, &use_perm, fl, &perm_u, in, &closed, (size_t)0);
  if (st == GR_OK)
    st = gr_kernel_args(s->ctx, s->limit, m, &s->h, m, &rain, m, &perm, m, &s->qx[0], m, &s->qy[0],
                        m, &s->k, in, &nx, in, &ny, fl, &dtf, fl, &inv_dx, fl, &inv_dy, in,
                        &use_rain, fl, &rain_u, in, &use_perm, fl, &perm_u, (size_t)0);
  if (st == GR_OK)
    st = gr_kernel_args(s->ctx, s->update, m, &s->h, m, &s->h_c, m, &rain, m, &perm, m, &s->qx[0],
                        m, &s->qy[0], m, &s->k, m, &s->inf, m, &s->inf_c, m, &s->out, m, &s->out_c,
                        in, &nx, in, &ny, fl, &dtf, fl, &inv_dx, fl, &inv_dy, in, &use_rain, fl,
                        &rain_u, in, &use_perm, fl, &perm_u, (size_t)0);
  int done = 0;
  while (st == GR_OK && done < nsteps) {
    int old = s->cur, now = 1 - s->cur;
    cl_int err = clSetKernelArg(s->flux, 4, m, &s->qx[old]);
    err |= clSetKernelArg(s->flux, 5, m, &s->qy[old]);
    err |= clSetKernelArg(s->flux, 6, m, &s->qx[now]);
    err |= clSetKernelArg(s->flux, 7, m, &s->qy[now]);
    err |= clSetKernelArg(s->limit, 3, m, &s->qx[now]);
    err |= clSetKernelArg(s->limit, 4, m, &s->qy[now]);
    err |= clSetKernelArg(s->update, 4, m, &s->qx[now]);
    err |= clSetKernelArg(s->update, 5, m, &s->qy[now]);
    st = gr_cl_check(s->ctx, err, "Setting the rain runoff face arrays");
    if (st == GR_OK)
      st = gr_enqueue_2d(s->ctx, s->flux, 0, 0, (size_t)nx + 1, (size_t)ny + 1, NULL);
    if (st == GR_OK)
      s->cur = now; /* the flux kernel is enqueued: the new faces are current */
    if (st == GR_OK)
      st = gr_enqueue_2d(s->ctx, s->limit, 0, 0, (size_t)nx, (size_t)ny, NULL);
    if (st == GR_OK)
      st = gr_enqueue_2d(s->ctx, s->update, 0, 0, (size_t)nx, (size_t)ny, NULL);
    if (st == GR_OK)
      ++done;
  }
  /* The ledger counts the steps whose launches were all enqueued, with the
   * rain the device added: the float dt it was given. */
  double rain_sum = s->has_rain ? s->rain_field_sum
                                : (double)gr_rain_runoff_cells(s) * (double)(cl_float)p->rain_rate;
  s->rain_volume += rain_sum * gd->dx * gd->dy * (double)dtf * (double)done;
  s->time += dt * (double)done;
  s->steps += done;
  return st;
}

gr_status gr_rain_runoff_stable_dt(gr_rain_runoff *s, double *dt) {
  if (!s || !dt)
    return gr_set_error(s ? s->ctx : NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_stable_dt needs a simulation and a place for dt.");
  double sums[3], hmax = 0.0;
  gr_status st = gr_rain_runoff_reduce(s, sums, &hmax);
  if (st != GR_OK)
    return st;
  /* The scheme's stability limit in 2-D for gravity waves, c = sqrt(g h)
   * at the deepest cell: a checkerboard mode of the staggered grid, damped
   * by the smoothing to 2 theta - 1 per step, grows unless
   *   c dt sqrt(1/dx^2 + 1/dy^2) <= sqrt(theta).
   * (Bates et al. 2010's cfl dx / sqrt(g h) is the 1-D limit; in 2-D it
   * allows steps sqrt(2 / theta) times too long.) cfl is the fraction of the
   * limit taken. The flow speed |u| is left out on purpose: the local
   * inertial equations have no advection term, and q / h of a cell that a
   * step has just drained would shrink the step for nothing. */
  double c = sqrt(GR_GRAVITY * hmax);
  double inv = sqrt(1.0 / (s->grid.dx * s->grid.dx) + 1.0 / (s->grid.dy * s->grid.dy));
  double stable =
      c > 0.0 ? s->params.cfl * sqrt(GR_RAIN_RUNOFF_THETA) / (c * inv) : s->params.max_dt;
  *dt = stable < s->params.max_dt ? stable : s->params.max_dt;
  return GR_OK;
}

gr_status gr_rain_runoff_advance(gr_rain_runoff *s, double duration, int *steps_taken) {
  if (steps_taken)
    *steps_taken = 0;
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_advance needs a simulation.");
  if (!(duration >= 0.0 && duration < HUGE_VAL))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The duration to advance must be a finite number of seconds, 0 or more "
                        "(got %g).",
                        duration);
  /* The stable step is read back again after a few steps, not once: rain
   * filling a dry bowl deepens it, and a step that was stable at the start
   * of a long advance is not by its end. The stretch between reads starts
   * at GR_RAIN_RUNOFF_CHUNK_MIN steps and doubles (to GR_RAIN_RUNOFF_CHUNK_MAX) while the
   * stable step holds; the last stretch is split into equal steps that end
   * exactly at the duration. All of it depends on the state only, so the
   * same state and duration give the same steps. */
  double left = duration, last_dt = 0.0;
  long long taken = 0;
  int chunk = GR_RAIN_RUNOFF_CHUNK_MIN;
  gr_status st = GR_OK;
  while (st == GR_OK && left > 0.0) {
    double dt = 0.0;
    st = gr_rain_runoff_stable_dt(s, &dt);
    if (st != GR_OK)
      break;
    if (last_dt > 0.0)
      chunk = dt >= 0.95 * last_dt
                  ? (chunk * 2 < GR_RAIN_RUNOFF_CHUNK_MAX ? chunk * 2 : GR_RAIN_RUNOFF_CHUNK_MAX)
                  : GR_RAIN_RUNOFF_CHUNK_MIN;
    last_dt = dt;
    double n = ceil(left / dt);
    if (n < 1.0)
      n = 1.0;
    if ((double)taken + n > (double)INT_MAX) {
      st = gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "Advancing by %g s takes more than %d steps (the stable step is %g s "
                        "with %g s left): advance in parts.",
                        duration, INT_MAX, dt, left);
      break;
    }
    if (n <= chunk) {
      st = gr_rain_runoff_step(s, left / n, (int)n);
      if (st == GR_OK)
        taken += (long long)n;
      break;
    }
    st = gr_rain_runoff_step(s, dt, chunk);
    if (st == GR_OK) {
      taken += chunk;
      left -= chunk * dt;
    }
  }
  if (steps_taken)
    *steps_taken = (int)taken;
  return st;
}

/* ---------------------------------------------------------------- reading */

/* Runs the derive kernel (what: 0 surface, 1 velocity, 2 discharge, 3
 * infiltrated) into the scratch buffer and reads `floats` values back. */
static gr_status gr_rain_runoff_derive(gr_rain_runoff *s, cl_int what, size_t floats, float *host) {
  size_t cells = gr_rain_runoff_cells(s);
  gr_status st = GR_OK;
  if (!s->scratch)
    st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, 3 * cells * sizeof(cl_float), NULL,
                          &s->scratch);
  cl_int nx = s->grid.nx, ny = s->grid.ny;
  const size_t m = sizeof(cl_mem), in = sizeof(cl_int);
  if (st == GR_OK)
    st = gr_kernel_args(s->ctx, s->derive, m, &s->h, m, &s->b, m, &s->qx[s->cur], m, &s->qy[s->cur],
                        m, &s->k, m, &s->inf, m, &s->inf_c, m, &s->scratch, in, &nx, in, &ny, in,
                        &what, (size_t)0);
  if (st == GR_OK)
    st = gr_enqueue_2d(s->ctx, s->derive, 0, 0, (size_t)nx, (size_t)ny, NULL);
  if (st == GR_OK)
    st = gr_buffer_read(s->ctx, s->scratch, 0, floats * sizeof(cl_float), host);
  return st;
}

gr_status gr_rain_runoff_get_field(gr_rain_runoff *s, gr_field f, float *host) {
  if (!s || !host)
    return gr_set_error(s ? s->ctx : NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_get_field needs a simulation and room for the field.");
  size_t cells = gr_rain_runoff_cells(s), bytes = cells * sizeof(cl_float);
  switch (f) {
  case GR_FIELD_WATER_DEPTH:
    return gr_buffer_read(s->ctx, s->h, 0, bytes, host);
  case GR_FIELD_ELEVATION:
    return gr_buffer_read(s->ctx, s->b, 0, bytes, host);
  case GR_FIELD_PERMEABILITY:
  case GR_FIELD_RAIN_RATE: {
    int field = f == GR_FIELD_RAIN_RATE ? s->has_rain : s->has_perm;
    if (field)
      return gr_buffer_read(s->ctx, f == GR_FIELD_RAIN_RATE ? s->rain : s->perm, 0, bytes, host);
    float v = (float)(f == GR_FIELD_RAIN_RATE ? s->params.rain_rate : s->params.permeability);
    for (size_t c = 0; c < cells; ++c)
      host[c] = v;
    return GR_OK;
  }
  case GR_FIELD_WATER_SURFACE:
    return gr_rain_runoff_derive(s, 0, cells, host);
  case GR_FIELD_VELOCITY:
    return gr_rain_runoff_derive(s, 1, 3 * cells, host);
  case GR_FIELD_DISCHARGE:
    return gr_rain_runoff_derive(s, 2, cells, host);
  case GR_FIELD_INFILTRATED:
    return gr_rain_runoff_derive(s, 3, cells, host);
  default:
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The rain runoff simulation has no field '%s'; it has elevation, "
                        "water_depth, water_surface, velocity, discharge, infiltrated, "
                        "permeability and rain_rate.",
                        gr_rain_runoff_field_label(f));
  }
}

gr_status gr_rain_runoff_ledger_get(gr_rain_runoff *s, gr_rain_runoff_ledger *out) {
  if (!s || !out)
    return gr_set_error(s ? s->ctx : NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_ledger_get needs a simulation and a ledger to fill.");
  double sums[3], hmax = 0.0;
  gr_status st = gr_rain_runoff_reduce(s, sums, &hmax);
  if (st != GR_OK)
    return st;
  double area = s->grid.dx * s->grid.dy;
  memset(out, 0, sizeof(*out));
  out->time = s->time;
  out->steps = s->steps;
  out->initial_volume = s->initial_volume;
  out->rain_volume = s->rain_volume;
  out->stored_volume = sums[0] * area;
  out->infiltrated_volume = sums[1] * area;
  out->outflow_volume = sums[2] * area;
  out->balance_error = out->initial_volume + out->rain_volume - out->infiltrated_volume -
                       out->outflow_volume - out->stored_volume;
  out->max_depth = hmax;
  return GR_OK;
}

gr_status gr_rain_runoff_reset(gr_rain_runoff *s) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT, "gr_rain_runoff_reset needs a simulation.");
  size_t bytes = gr_rain_runoff_cells(s) * sizeof(cl_float);
  gr_status st;
  if (s->h0)
    st = gr_cl_check(
        s->ctx,
        clEnqueueCopyBuffer(gr_context_queue(s->ctx), s->h0, s->h, 0, 0, bytes, 0, NULL, NULL),
        "Copying the initial water depth");
  else
    st = gr_rain_runoff_fill(s, s->h, 0.0f, bytes);
  cl_mem zeroed[] = {s->h_c, s->inf, s->inf_c, s->out, s->out_c};
  for (size_t i = 0; st == GR_OK && i < sizeof(zeroed) / sizeof(zeroed[0]); ++i)
    st = gr_rain_runoff_fill(s, zeroed[i], 0.0f, bytes);
  if (st == GR_OK)
    st = gr_rain_runoff_clear_flow(s);
  if (st != GR_OK)
    return st;
  s->time = 0.0;
  s->steps = 0;
  s->rain_volume = 0.0;
  s->initial_volume = s->initial_sum * s->grid.dx * s->grid.dy;
  return GR_OK;
}
