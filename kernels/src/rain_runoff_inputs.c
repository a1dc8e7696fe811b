/* Rain runoff core, host side: the inputs (rain_runoff_internal.h): the
 * fields (elevation and no-data cells, permeability, rain, water, velocity),
 * point and edge inflows, the hyetograph and the Manning map, and the
 * sources and rain they give each step. */
#include "rain_runoff_internal.h"

/* ----------------------------------------------------------------- fields */

/* Uploads into *buf, allocating it on first use. */
static gr_status gr_rain_runoff_upload(gr_rain_runoff *s, cl_mem *buf, const float *host) {
  size_t bytes = gr_rain_runoff_cells(s) * sizeof(cl_float);
  if (!*buf)
    return gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, bytes, host, buf);
  return gr_buffer_write(s->ctx, *buf, 0, bytes, host);
}

/* The lowest ground along each of the domain's edges in the local array
 * `z` (s->edge_bed; 0 on a side with a neighbour). */
static void gr_rain_runoff_edge_beds(gr_rain_runoff *s, const float *z) {
  const int nx = s->nxl, ny = s->nyl;
  for (int e = 0; e < 4; ++e) {
    double low = HUGE_VAL;
    int n = e < 2 ? ny : nx;
    for (int k = 0; !s->ring[e] && k < n; ++k) {
      int i = e == 0 ? 0 : (e == 1 ? nx - 1 : k), j = e < 2 ? k : (e == 2 ? 0 : ny - 1);
      double v = z[(size_t)j * (size_t)nx + (size_t)i];
      low = v < low ? v : low;
    }
    s->edge_bed[e] = s->ring[e] ? 0.0 : low;
  }
}

/* The deepest water a level edge holds over its edge's lowest ground (m; 0
 * without level edges): the stable step counts it as water in the grid. */
double gr_rain_runoff_edge_depth(const gr_rain_runoff *s) {
  double deepest = 0.0;
  for (int e = 0; e < 4; ++e) {
    if (s->ring[e] || s->params.boundary[e] != GR_BOUNDARY_LEVEL)
      continue;
    double d = s->params.boundary_level[e] - s->edge_bed[e];
    deepest = d > deepest ? d : deepest;
  }
  return deepest;
}

static gr_status gr_rain_runoff_rain_sum(gr_rain_runoff *s);

/* The bed the kernels see in a no-data cell: a wall far above any ground
 * and water (elevations lie within +-1e6 m), or an outfall's cliff far
 * below it, over which water pours out (the hydrostatic reconstruction and
 * the local inertial faces then pass what the cell above it sends, and the
 * cell drains every step). Fixed heights: every piece sees the same. */
#define GR_RAIN_RUNOFF_NODATA_WALL 2.0e6f
#define GR_RAIN_RUNOFF_NODATA_CLIFF -2.0e6f

/* Uploads the elevation (NaN: no-data cells, as the params' kind makes
 * them), the no-data map when there are no-data cells, and the owned
 * domain cells' count; the rain field's sum follows the new mask. */
gr_status gr_rain_runoff_set_elevation(gr_rain_runoff *s, const float *host) {
  size_t cells = gr_rain_runoff_cells(s);
  int any = 0;
  for (size_t c = 0; c < cells && !any; ++c)
    any = isnan(host[c]);
  if (!any) {
    free(s->mask);
    s->mask = NULL;
    s->has_nodata = 0;
    s->args_set = 0;
    gr_status st = gr_buffer_write(s->ctx, s->b, 0, cells * sizeof(cl_float), host);
    if (st == GR_OK && s->has_rain)
      st = gr_rain_runoff_rain_sum(s);
    return st;
  }
  unsigned char *mask = malloc(cells);
  float *b = malloc(cells * sizeof(float)), *kind = malloc(cells * sizeof(float));
  if (!mask || !b || !kind) {
    free(mask);
    free(b);
    free(kind);
    return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  int outfall = s->params.no_data == GR_BOUNDARY_OPEN;
  double active = 0.0;
  for (size_t c = 0; c < cells; ++c) {
    mask[c] = isnan(host[c]) ? 1 : 0;
    b[c] = mask[c] ? (outfall ? GR_RAIN_RUNOFF_NODATA_CLIFF : GR_RAIN_RUNOFF_NODATA_WALL) : host[c];
    kind[c] = mask[c] ? (outfall ? 2.0f : 1.0f) : 0.0f;
  }
  for (int j = s->ring[2]; j < s->nyl - s->ring[3]; ++j)
    for (int i = s->ring[0]; i < s->nxl - s->ring[1]; ++i)
      active += !mask[(size_t)j * (size_t)s->nxl + (size_t)i];
  gr_status st = gr_buffer_write(s->ctx, s->b, 0, cells * sizeof(cl_float), b);
  if (st == GR_OK)
    st = gr_rain_runoff_upload(s, &s->nodata, kind);
  free(b);
  free(kind);
  if (st != GR_OK) {
    free(mask);
    return st;
  }
  free(s->mask);
  s->mask = mask;
  s->has_nodata = 1;
  s->active_own = active;
  s->args_set = 0;
  return s->has_rain ? gr_rain_runoff_rain_sum(s) : GR_OK;
}

/* The rain field's sum over the owned domain cells and its largest value,
 * read back from the device (after the no-data cells changed). */
static gr_status gr_rain_runoff_rain_sum(gr_rain_runoff *s) {
  size_t cells = gr_rain_runoff_cells(s);
  float *r = malloc(cells * sizeof(float));
  if (!r)
    return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  gr_status st = gr_buffer_read(s->ctx, s->rain, 0, cells * sizeof(cl_float), r);
  if (st == GR_OK) {
    s->rain_field_sum = gr_rain_runoff_own_sum(s, r);
    s->rain_field_max = 0.0;
    for (size_t c = 0; c < cells; ++c)
      if ((!s->has_nodata || !s->mask[c]) && r[c] > s->rain_field_max)
        s->rain_field_max = r[c];
  }
  free(r);
  return st;
}

/* After a read of the owned cells (comps floats each): NaN in no-data cells. */
void gr_rain_runoff_blank(const gr_rain_runoff *s, float *host, size_t comps) {
  if (!s->has_nodata)
    return;
  size_t k = 0;
  for (int j = s->ring[2]; j < s->nyl - s->ring[3]; ++j)
    for (int i = s->ring[0]; i < s->nxl - s->ring[1]; ++i, ++k)
      if (s->mask[(size_t)j * (size_t)s->nxl + (size_t)i])
        for (size_t q = 0; q < comps; ++q)
          host[k * comps + q] = NAN;
}

/* VELOCITY: the discharges h (u, v) of the water there now; they are also
 * the initial ones that reset returns to. */
static gr_status gr_rain_runoff_set_velocity(gr_rain_runoff *s, const float *host) {
  size_t cells = gr_rain_runoff_cells(s);
  float *q = malloc(3 * cells * sizeof(float));
  if (!q)
    return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  float *qx = q + cells, *qy = q + 2 * cells;
  gr_status st = gr_buffer_read(s->ctx, s->h, 0, cells * sizeof(cl_float), q);
  for (size_t c = 0; st == GR_OK && c < cells; ++c) {
    qx[c] = q[c] * host[3 * c];
    qy[c] = q[c] * host[3 * c + 1];
  }
  if (st == GR_OK)
    st = gr_rain_runoff_upload(s, &s->qu0, qx);
  if (st == GR_OK)
    st = gr_rain_runoff_upload(s, &s->qv0, qy);
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, s->qu, 0, cells * sizeof(cl_float), qx);
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, s->qv, 0, cells * sizeof(cl_float), qy);
  /* The maps see the new speeds from now on. */
  if (st == GR_OK)
    st = gr_rain_runoff_maps_update(s, s->time);
  free(q);
  return st;
}

/* ELEVATION: the bed (gr_rain_runoff_set_elevation), the fastest the bed's
 * slope can speed water up (slope_rate) and the edges' lowest ground. */
static gr_status gr_rain_runoff_set_ground(gr_rain_runoff *s, const float *host) {
  gr_status st = gr_rain_runoff_set_elevation(s, host);
  double worst = 0.0;
  const int nx = s->nxl, ny = s->nyl;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const float *z = host + (size_t)j * nx + i;
      double sx = 0.0, sy = 0.0;
      if (i > 0)
        sx = fabs((double)z[0] - z[-1]);
      if (i < nx - 1)
        sx = fmax(sx, fabs((double)z[1] - z[0]));
      if (j > 0)
        sy = fabs((double)z[0] - z[-nx]);
      if (j < ny - 1)
        sy = fmax(sy, fabs((double)z[nx] - z[0]));
      double rate = sx / (s->grid.dx * s->grid.dx) + sy / (s->grid.dy * s->grid.dy);
      worst = rate > worst ? rate : worst;
    }
  if (st == GR_OK) {
    s->slope_rate = GR_GRAVITY * worst;
    gr_rain_runoff_edge_beds(s, host);
  }
  return st;
}

/* RAIN_RATE: the field, its sum over the owned domain cells and its
 * largest value. */
static gr_status gr_rain_runoff_set_rain_field(gr_rain_runoff *s, const float *host) {
  size_t cells = gr_rain_runoff_cells(s);
  gr_fixed sum = gr_rain_runoff_own_sum(s, host);
  gr_status st = gr_rain_runoff_upload(s, &s->rain, host);
  if (st == GR_OK) {
    s->has_rain = 1;
    s->rain_field_sum = sum;
    s->rain_field_max = 0.0;
    for (size_t c = 0; c < cells; ++c)
      if (!s->has_nodata || !s->mask[c])
        s->rain_field_max = host[c] > s->rain_field_max ? host[c] : s->rain_field_max;
  }
  return st;
}

/* WATER_DEPTH: the new water replaces what is there now: the ledger counts
 * the difference as initial water, so the balance still closes. No-data
 * cells hold none. */
static gr_status gr_rain_runoff_set_water(gr_rain_runoff *s, const float *host) {
  size_t cells = gr_rain_runoff_cells(s);
  float *dry = NULL;
  if (s->has_nodata) {
    dry = malloc(cells * sizeof(float));
    if (!dry)
      return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
    for (size_t c = 0; c < cells; ++c)
      dry[c] = s->mask[c] ? 0.0f : host[c];
    host = dry;
  }
  gr_fixed now[GR_RAIN_RUNOFF_SUMS], sum = gr_rain_runoff_own_sum(s, host);
  gr_status st = gr_rain_runoff_reduce_fixed(s, now, NULL);
  if (st == GR_OK)
    st = gr_rain_runoff_upload(s, &s->h0, host);
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, s->h, 0, cells * sizeof(cl_float), host);
  if (st == GR_OK)
    st = gr_rain_runoff_fill(s, s->h_c, 0.0f, cells * sizeof(cl_float));
  if (st == GR_OK)
    st = gr_rain_runoff_clear_flow(s);
  /* No discharge: the initial velocity, if any, was of other water. */
  gr_buffer_release(&s->qu0);
  gr_buffer_release(&s->qv0);
  if (st == GR_OK) { /* exact: the device's sum of the old water is in the same units */
    s->initial_sum = sum;
    s->initial.coarse += sum.coarse - now[0].coarse;
    s->initial.fine += sum.fine - now[0].fine;
  }
  /* The maps count the new water from the time it is set. */
  if (st == GR_OK)
    st = gr_rain_runoff_maps_update(s, s->time);
  free(dry);
  return st;
}

static gr_status gr_rain_runoff_set_field_impl(gr_rain_runoff *s, gr_field f, const float *host) {
  char msg[320];
  size_t cells = gr_rain_runoff_cells(s);
  size_t values = f == GR_FIELD_VELOCITY ? 3 * cells : cells;
  if (gr_rain_runoff_field_check(f, host, values, (size_t)s->nxl, 1, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  if (f == GR_FIELD_VELOCITY && s->params.flow_model != GR_FLOW_SHALLOW_WATER)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The field 'velocity' is an input of FlowModel 0 (shallow water) only, and "
                        "this simulation runs FlowModel %d (local inertial), which starts from "
                        "rest: leave it out, or take FlowModel 0.",
                        (int)s->params.flow_model);
  if (f == GR_FIELD_WATER_SURFACE) {
    /* The depth under the surface, as WATER_DEPTH sets it. */
    float *d = malloc(cells * sizeof(float));
    if (!d)
      return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
    gr_status st = gr_buffer_read(s->ctx, s->b, 0, cells * sizeof(cl_float), d);
    for (size_t c = 0; st == GR_OK && c < cells; ++c) {
      float depth = host[c] - d[c];
      d[c] = depth > 0.0f ? depth : 0.0f;
    }
    if (st == GR_OK)
      st = gr_rain_runoff_set_field_impl(s, GR_FIELD_WATER_DEPTH, d);
    free(d);
    return st;
  }
  if (f == GR_FIELD_VELOCITY)
    return gr_rain_runoff_set_velocity(s, host);
  gr_status st = GR_OK;
  s->args_set = 0; /* a field allocated now is bound at the next step */
  switch (f) {
  case GR_FIELD_ELEVATION:
    st = gr_rain_runoff_set_ground(s, host);
    break;
  case GR_FIELD_PERMEABILITY:
    st = gr_rain_runoff_upload(s, &s->perm, host);
    if (st == GR_OK)
      s->has_perm = 1;
    break;
  case GR_FIELD_RAIN_RATE:
    st = gr_rain_runoff_set_rain_field(s, host);
    break;
  case GR_FIELD_WATER_DEPTH:
    st = gr_rain_runoff_set_water(s, host);
    break;
  default:
    break; /* refused by gr_rain_runoff_field_check */
  }
  return st;
}

gr_status gr_rain_runoff_set_field(gr_rain_runoff *s, gr_field f, const float *host) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_set_field needs a simulation and the field's values.");
  if (!host)
    return GR_RAIN_RUNOFF_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_set_field needs a simulation and the field's values."));
  return GR_RAIN_RUNOFF_KEEP_ERROR(
      s, gr_rain_runoff_inputs_changed(s, gr_rain_runoff_set_field_impl(s, f, host)));
}

/* ------------------------------------------------------------- inflows */

#define GR_RAIN_RUNOFF_MAX_DISCHARGE 1.0e6
#define GR_RAIN_RUNOFF_MAX_ROWS 1000000

static const char *const gr_rain_runoff_side_names[4] = {"west", "east", "south", "north"};

/* Keeps a copy of a validated table of n rows (times t, values v) in
 * *keep_t, *keep_v, freeing the one before; n = 0 keeps none. */
static gr_status gr_rain_runoff_table_keep(gr_rain_runoff *s, const double *t, const double *v,
                                           int n, double **keep_t, double **keep_v) {
  double *nt = NULL, *nv = NULL;
  if (n > 0) {
    nt = malloc((size_t)n * sizeof(double));
    nv = malloc((size_t)n * sizeof(double));
    if (!nt || !nv) {
      free(nt);
      free(nv);
      return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
    }
    memcpy(nt, t, (size_t)n * sizeof(double));
    memcpy(nv, v, (size_t)n * sizeof(double));
  }
  free(*keep_t);
  free(*keep_v);
  *keep_t = nt;
  *keep_v = nv;
  return GR_OK;
}

/* (Re)allocates the source field the steps read, and fills it for the
 * sources now when no hydrograph rewrites it before every step. */
static gr_status gr_rain_runoff_sources_changed(gr_rain_runoff *s) {
  size_t bytes = gr_rain_runoff_cells(s) * sizeof(cl_float);
  gr_status st = GR_OK;
  if (gr_rain_runoff_has_sources(s) && !s->src)
    st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, bytes, NULL, &s->src);
  if (st == GR_OK && gr_rain_runoff_has_sources(s) && !gr_rain_runoff_has_edge_inflow(s))
    st = gr_rain_runoff_sources_update(s, s->time, s->time);
  s->args_set = 0; /* use_src and the buffer are bound at the next step */
  return st;
}

static gr_status gr_rain_runoff_set_point_inflows_impl(gr_rain_runoff *s, const int *ij,
                                                       const double *q, int n) {
  if (n < 0 || n > GR_RAIN_RUNOFF_MAX_ROWS || (n > 0 && (!ij || !q)))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The point inflows must be 0 to %d cells with a discharge each (got %d%s).",
                        GR_RAIN_RUNOFF_MAX_ROWS, n, n > 0 && (!ij || !q) ? " and no values" : "");
  int gnx = s->grid.global_nx > 0 ? s->grid.global_nx : s->grid.nx;
  int gny = s->grid.global_ny > 0 ? s->grid.global_ny : s->grid.ny;
  for (int k = 0; k < n; ++k) {
    if (!(q[k] >= 0.0 && q[k] <= GR_RAIN_RUNOFF_MAX_DISCHARGE))
      return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                          "Point inflow %d has the discharge %g m^3/s: discharges must lie between "
                          "0 and %g m^3/s; give it a discharge in that range.",
                          k, q[k], GR_RAIN_RUNOFF_MAX_DISCHARGE);
    if (ij[2 * k] < 0 || ij[2 * k] >= gnx || ij[2 * k + 1] < 0 || ij[2 * k + 1] >= gny)
      return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                          "Point inflow %d is the cell (%d, %d), outside the domain of %d x %d "
                          "cells: give cells from (0, 0) to (%d, %d).",
                          k, ij[2 * k], ij[2 * k + 1], gnx, gny, gnx - 1, gny - 1);
  }
  size_t cells = gr_rain_runoff_cells(s);
  gr_status st = GR_OK;
  if (n == 0) {
    s->has_pts = 0;
    s->pts_max = 0.0;
  } else {
    /* Summed in double in the order given, one float per cell: the same
     * floats in every piece that holds the cell (owned or in its ring). */
    double *sum = calloc(cells, sizeof(double));
    float *f = malloc(cells * sizeof(float));
    if (!sum || !f) {
      free(sum);
      free(f);
      return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
    }
    const int x0 = s->grid.i0 - s->ring[0], y0 = s->grid.j0 - s->ring[2];
    for (int k = 0; k < n; ++k) {
      int i = ij[2 * k] - x0, j = ij[2 * k + 1] - y0;
      if (i >= 0 && i < s->nxl && j >= 0 && j < s->nyl)
        sum[(size_t)j * (size_t)s->nxl + (size_t)i] += q[k];
    }
    double area = s->grid.dx * s->grid.dy, top = 0.0;
    for (size_t c = 0; c < cells; ++c) {
      f[c] = (float)(sum[c] / area);
      top = f[c] > top ? f[c] : top;
    }
    st = gr_rain_runoff_upload(s, &s->pts, f);
    free(sum);
    free(f);
    if (st != GR_OK)
      return st;
    s->has_pts = 1;
    s->pts_max = top;
  }
  return gr_rain_runoff_sources_changed(s);
}

gr_status gr_rain_runoff_set_point_inflows(gr_rain_runoff *s, const int *ij,
                                           const double *discharge, int n) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_set_point_inflows needs a simulation.");
  return GR_RAIN_RUNOFF_KEEP_ERROR(
      s,
      gr_rain_runoff_inputs_changed(s, gr_rain_runoff_set_point_inflows_impl(s, ij, discharge, n)));
}

static gr_status gr_rain_runoff_set_edge_inflow_impl(gr_rain_runoff *s, int side, const double *t,
                                                     const double *q, int n) {
  if (side < 0 || side > 3)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The edge of an inflow hydrograph must be 0 west, 1 east, 2 south or 3 "
                        "north (got %d).",
                        side);
  const char *name = gr_rain_runoff_side_names[side];
  if (n < 0 || n > GR_RAIN_RUNOFF_MAX_ROWS || (n > 0 && (!t || !q)))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The %s edge's inflow hydrograph must have 0 to %d rows of time and "
                        "discharge (got %d%s).",
                        name, GR_RAIN_RUNOFF_MAX_ROWS, n,
                        n > 0 && (!t || !q) ? " and no values" : "");
  for (int k = 0; k < n; ++k) {
    if (!(t[k] >= -1e12 && t[k] <= 1e12))
      return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                          "The %s edge's inflow hydrograph has the time %g s in row %d: times must "
                          "be finite numbers of seconds; correct that row.",
                          name, t[k], k);
    if (k > 0 && !(t[k] > t[k - 1]))
      return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                          "The %s edge's inflow hydrograph's times must increase from row to row, "
                          "but row %d has %g s after %g s; sort the rows and drop repeated times.",
                          name, k, t[k], t[k - 1]);
    if (!(q[k] >= 0.0 && q[k] <= GR_RAIN_RUNOFF_MAX_DISCHARGE))
      return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                          "The %s edge's inflow hydrograph has the discharge %g m^3/s in row %d: "
                          "discharges must lie between 0 and %g m^3/s; correct that row.",
                          name, q[k], k, GR_RAIN_RUNOFF_MAX_DISCHARGE);
  }
  gr_status st = gr_rain_runoff_table_keep(s, t, q, n, &s->edge_t[side], &s->edge_q[side]);
  if (st != GR_OK)
    return st;
  s->edge_n[side] = n;
  return gr_rain_runoff_sources_changed(s);
}

gr_status gr_rain_runoff_set_edge_inflow(gr_rain_runoff *s, int side, const double *times,
                                         const double *discharge, int n) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_set_edge_inflow needs a simulation.");
  return GR_RAIN_RUNOFF_KEEP_ERROR(
      s, gr_rain_runoff_inputs_changed(
             s, gr_rain_runoff_set_edge_inflow_impl(s, side, times, discharge, n)));
}

/* ------------------------------------------------ rain and roughness maps */

static gr_status gr_rain_runoff_set_manning_map_impl(gr_rain_runoff *s, const double *n) {
  size_t cells = gr_rain_runoff_cells(s);
  if (!n) {
    s->has_n2 = 0;
    s->args_set = 0;
    return GR_OK;
  }
  const gr_param_bound *row = &gr_rain_runoff_bounds[GR_RAIN_RUNOFF_P_MANNING_N];
  int li = s->params.flow_model == GR_FLOW_LOCAL_INERTIAL;
  double lo = li ? GR_RAIN_RUNOFF_LI_MIN_N : row->min, low = HUGE_VAL;
  for (size_t c = 0; c < cells; ++c) {
    if (!(n[c] >= lo && n[c] <= row->max))
      return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                          "The Manning map has the value %g s/m^(1/3) at cell (%zu, %zu): values "
                          "must lie between %g and %g%s, like ManningN; correct the map.",
                          n[c], c % (size_t)s->nxl, c / (size_t)s->nxl, lo, row->max,
                          li ? " for FlowModel 1 (local inertial)" : "");
    low = n[c] < low ? n[c] : low;
  }
  float *n2 = malloc(cells * sizeof(float));
  if (!n2)
    return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  /* n^2 as the uniform ManningN's: in double, then one float (the same
   * float for the same n, so a map of ManningN everywhere is that run). */
  for (size_t c = 0; c < cells; ++c)
    n2[c] = (float)(n[c] * n[c]);
  gr_status st = gr_rain_runoff_upload(s, &s->n2map, n2);
  free(n2);
  if (st != GR_OK)
    return st;
  s->has_n2 = 1;
  s->n_min = low;
  s->args_set = 0;
  return GR_OK;
}

gr_status gr_rain_runoff_set_manning_map(gr_rain_runoff *s, const double *n) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_set_manning_map needs a simulation.");
  return GR_RAIN_RUNOFF_KEEP_ERROR(
      s, gr_rain_runoff_inputs_changed(s, gr_rain_runoff_set_manning_map_impl(s, n)));
}

static gr_status gr_rain_runoff_set_hyetograph_impl(gr_rain_runoff *s, const double *t,
                                                    const double *r, int n) {
  const gr_param_bound *row = &gr_rain_runoff_bounds[GR_RAIN_RUNOFF_P_RAIN_RATE];
  const double hi = gr_rain_runoff_core_max(GR_RAIN_RUNOFF_P_RAIN_RATE);
  if (n < 0 || n > GR_RAIN_RUNOFF_MAX_ROWS || (n > 0 && (!t || !r)))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The hyetograph must have 0 to %d rows of time and rain rate (got %d%s).",
                        GR_RAIN_RUNOFF_MAX_ROWS, n, n > 0 && (!t || !r) ? " and no values" : "");
  for (int k = 0; k < n; ++k) {
    if (!(t[k] >= -1e12 && t[k] <= 1e12))
      return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                          "The hyetograph has the time %g s in row %d: times must be finite "
                          "numbers of seconds; correct that row.",
                          t[k], k);
    if (k > 0 && !(t[k] > t[k - 1]))
      return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                          "The hyetograph's times must increase from row to row, but row %d has "
                          "%g s after %g s; sort the rows and drop repeated times.",
                          k, t[k], t[k - 1]);
    if (!(r[k] >= 0.0 && r[k] <= hi))
      return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                          "The hyetograph has the rain rate %g %s in row %d: rates must lie "
                          "between %g and %g %s, like RainRate; correct that row.",
                          r[k] / row->to_core, row->unit, k, row->min, row->max, row->unit);
  }
  gr_status st = gr_rain_runoff_table_keep(s, t, r, n, &s->hy_t, &s->hy_r);
  if (st != GR_OK)
    return st;
  s->hy_n = n;
  s->args_set = 0; /* RainRate again at the next bind when it is removed */
  return GR_OK;
}

gr_status gr_rain_runoff_set_hyetograph(gr_rain_runoff *s, const double *times, const double *rates,
                                        int n) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_set_hyetograph needs a simulation.");
  return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_rain_runoff_set_hyetograph_impl(s, times, rates, n));
}

/* ---------------------------------------------------------------- sources */

int gr_rain_runoff_has_edge_inflow(const gr_rain_runoff *s) {
  return s->edge_n[0] || s->edge_n[1] || s->edge_n[2] || s->edge_n[3];
}

int gr_rain_runoff_has_sources(const gr_rain_runoff *s) {
  return s->has_pts || gr_rain_runoff_has_edge_inflow(s);
}

/* The integral over [a, b] of the piecewise-linear function through (t[k],
 * v[k]), k < n, held at v[0] before t[0] and at v[n-1] after t[n-1]. */
static double gr_rain_runoff_table_integral(const double *t, const double *v, int n, double a,
                                            double b) {
  double sum = 0.0;
  if (a < t[0])
    sum += v[0] * ((b < t[0] ? b : t[0]) - a);
  if (b > t[n - 1])
    sum += v[n - 1] * (b - (a > t[n - 1] ? a : t[n - 1]));
  for (int k = 0; k + 1 < n; ++k) {
    double lo = a > t[k] ? a : t[k], hi = b < t[k + 1] ? b : t[k + 1];
    if (hi <= lo)
      continue;
    double slope = (v[k + 1] - v[k]) / (t[k + 1] - t[k]);
    double vlo = v[k] + slope * (lo - t[k]), vhi = v[k] + slope * (hi - t[k]);
    sum += 0.5 * (vlo + vhi) * (hi - lo);
  }
  return sum;
}

/* The cells along each domain edge of the whole domain (a piece's edge is
 * part of it): the hydrograph's discharge is spread over all of them. */
static double gr_rain_runoff_edge_cells(const gr_rain_runoff *s, int side) {
  int gnx = s->grid.global_nx > 0 ? s->grid.global_nx : s->grid.nx;
  int gny = s->grid.global_ny > 0 ? s->grid.global_ny : s->grid.ny;
  return side < 2 ? (double)gny : (double)gnx;
}

/* Writes the sources of the step [t0, t1] into s->src: the point inflows
 * and each edge's mean discharge over the step (the exact integral of its
 * table, over t1 - t0), spread over the edge's cells, as m/s of depth. */
gr_status gr_rain_runoff_sources_update(gr_rain_runoff *s, double t0, double t1) {
  cl_float edge[4];
  for (int e = 0; e < 4; ++e) {
    double rate = 0.0;
    if (s->edge_n[e] && !s->ring[e] && t1 > t0)
      rate = gr_rain_runoff_table_integral(s->edge_t[e], s->edge_q[e], s->edge_n[e], t0, t1) /
             (t1 - t0) / (gr_rain_runoff_edge_cells(s, e) * s->grid.dx * s->grid.dy);
    edge[e] = (cl_float)rate;
  }
  cl_int nx = s->nxl, ny = s->nyl, use_pts = s->has_pts;
  cl_mem pts = s->has_pts ? s->pts : s->dummy;
  const size_t m = sizeof(cl_mem);
  const gr_rain_runoff_arg args[] = {
      {"pts", m, &pts},
      {"use_pts", sizeof(use_pts), &use_pts},
      {"src", m, &s->src},
      {"nx", sizeof(nx), &nx},
      {"ny", sizeof(ny), &ny},
      {"edge_w", sizeof(cl_float), &edge[0]},
      {"edge_e", sizeof(cl_float), &edge[1]},
      {"edge_s", sizeof(cl_float), &edge[2]},
      {"edge_n", sizeof(cl_float), &edge[3]},
  };
  gr_status st = GR_RAIN_RUNOFF_ARGS(s, s->source, args);
  if (st == GR_OK)
    st = gr_enqueue_2d(s->ctx, s->source, 0, 0, (size_t)s->nxl, (size_t)s->nyl, NULL);
  return st;
}

/* The largest source rate the sources may reach (m/s of depth): the point
 * inflows' and every edge's largest discharge over its cells. */
double gr_rain_runoff_source_max(const gr_rain_runoff *s) {
  double edge = 0.0;
  for (int e = 0; e < 4; ++e) {
    if (!s->edge_n[e] || s->ring[e])
      continue;
    double q = 0.0;
    for (int k = 0; k < s->edge_n[e]; ++k)
      q = s->edge_q[e][k] > q ? s->edge_q[e][k] : q;
    q /= gr_rain_runoff_edge_cells(s, e) * s->grid.dx * s->grid.dy;
    edge += q; /* a corner cell gets two edges' */
  }
  return (s->has_pts ? s->pts_max : 0.0) + edge;
}

/* The ledger's rain for `done` steps of the float dtf: the owned cells'
 * rates (the rain field's, RainRate's, or with a hyetograph the sum of the
 * rates the steps took) in fixed point, times the steps in units of
 * 2^-GR_RAIN_RUNOFF_STEP_BITS s, as exact integer products. dtf >= 2^-9 s
 * is exact in those units (smaller steps round to them); every piece books
 * the same step integers, so the pieces' rain adds up to the whole grid's,
 * bit for bit. Bounds: rates up to RainRate's 3600 mm/h (coarse words up to
 * 2^14 a cell), steps up to MaxTimeStep's 3600 s (2^44 units) and simulated
 * time below 2^31 s keep rain_book[0] below 2^109 and rain_book[1] below 2^125 on a
 * 65536^2 grid. */
void gr_rain_runoff_rain_book(gr_rain_runoff *s, const gr_fixed *hyetograph, cl_float dtf,
                              int done) {
  long long step = llrint(ldexp((double)dtf, GR_RAIN_RUNOFF_STEP_BITS));
  /* The owned cells of the domain: no rain falls on no-data cells. */
  long long active =
      s->has_nodata ? (long long)s->active_own : (long long)gr_rain_runoff_own_cells(s);
  gr_fixed rate;
  long long times;
  if (s->has_rain) {
    rate = s->rain_field_sum;
    times = 1;
  } else if (s->hy_n) { /* each step its own rate, as the device took it */
    rate = *hyetograph;
    times = active;
    done = 1;
  } else {
    rate = gr_fixed_from_float((cl_float)s->params.rain_rate);
    times = active;
  }
  gr_wide coarse = gr_wide_scale(gr_wide_mul(rate.coarse, times), step * done);
  gr_wide fine = gr_wide_scale(gr_wide_mul(rate.fine, times), step * done);
  gr_wide_add(&s->rain_book[0], coarse);
  gr_wide_add(&s->rain_book[1], fine);
}

/* The hyetograph's rain for the step [t0, t1]: the table's exact mean over
 * it, as the float the kernels take in place of RainRate (a rain_rate field
 * still wins); *sum adds that float (in fixed point) for the ledger. */
gr_status gr_rain_runoff_hyetograph_step(gr_rain_runoff *s, double t0, double t1, gr_fixed *sum) {
  cl_float rf =
      (cl_float)(gr_rain_runoff_table_integral(s->hy_t, s->hy_r, s->hy_n, t0, t1) / (t1 - t0));
  int sw = s->params.flow_model == GR_FLOW_SHALLOW_WATER;
  cl_kernel li[6] = {s->flux_edges, s->li_step, s->flux, s->limit, s->update, s->limit_update};
  cl_kernel swk[5] = {s->sw_prep, s->sw_faces[0], s->sw_update[0], s->sw_faces[1], s->sw_update[1]};
  gr_status st = GR_OK;
  for (int k = 0; st == GR_OK && k < (sw ? 5 : (s->fused ? 2 : 6)); ++k)
    st = sw ? gr_kernel_arg(s->ctx, swk[k], "rain_uniform", sizeof(rf), &rf)
            : gr_rain_runoff_arg_at(s, li[k], s->ix_rain[k], sizeof(rf), &rf);
  for (int k = 0; st == GR_OK && sw && k < 4; ++k)
    st = gr_kernel_arg(s->ctx, k < 2 ? s->sw_stage[k] : s->sw_inner[k - 2], "rain_uniform",
                       sizeof(rf), &rf);
  if (st == GR_OK)
    gr_fixed_add(sum, gr_fixed_from_float(rf));
  return st;
}

/* The largest uniform rain rate (m/s): the hyetograph's, or RainRate. */
double gr_rain_runoff_rain_max(const gr_rain_runoff *s) {
  double top = s->hy_n ? 0.0 : s->params.rain_rate;
  for (int k = 0; k < s->hy_n; ++k)
    top = s->hy_r[k] > top ? s->hy_r[k] : top;
  return top;
}

/* The smallest Manning n the friction takes: the map's, or ManningN. */
double gr_rain_runoff_min_n(const gr_rain_runoff *s) {
  return s->has_n2 ? s->n_min : s->params.manning_n;
}
