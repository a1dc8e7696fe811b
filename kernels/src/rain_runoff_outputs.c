/* Rain runoff core, host side: what a simulation gives back
 * (rain_runoff_internal.h): the flood maps, the fields read and derived,
 * samples, and the ledger. */
#include "rain_runoff_internal.h"

/* ------------------------------------------------------------ flood maps */

/* The flood maps' arguments of kernel k: the maps kernel's, and each
 * model's last step kernel's, which folds the state it leaves into them
 * (GR_RAIN_RUNOFF_MAP_ARGS in rain_runoff.cl): the eight arrays, the
 * wetting depth and the debris factor. */
gr_status gr_rain_runoff_map_args(gr_rain_runoff *s, cl_kernel k) {
  const size_t m = sizeof(cl_mem);
  cl_float wd = (cl_float)s->params.wetting_depth, df = (cl_float)s->params.debris_factor;
  const gr_rain_runoff_arg args[] = {
      {"max_depth", m, &s->map[0]},       {"max_speed", m, &s->map[1]},
      {"arrival", m, &s->map[2]},         {"wet_time", m, &s->map[3]},
      {"max_hazard", m, &s->map[4]},      {"wet_time_lo", m, &s->map[5]},
      {"wet_since", m, &s->map[6]},       {"wet_since_lo", m, &s->map[7]},
      {"wetting_depth", sizeof(wd), &wd}, {"debris_factor", sizeof(df), &df},
  };
  return GR_RAIN_RUNOFF_ARGS(s, k, args);
}

/* The flood maps' time argument (map_time) of a fold at the end t1 of a step
 * that began at t0 (t0 = t1: no step): t1 as a float (the arrival time), t0
 * as a double-float pair (where wet spells begin and end). */
cl_float4 gr_rain_runoff_map_time(double t0, double t1) {
  cl_float4 m;
  m.s[0] = (cl_float)t1;
  m.s[1] = (cl_float)t0;
  m.s[2] = (cl_float)(t0 - (double)m.s[1]);
  m.s[3] = 0.0f;
  return m;
}

/* Folds the state now into the flood maps (rain_runoff_maps) at `time`, the
 * state's time (s), adding no time: the cells' wet state before comes from
 * the maps (wet_since), so this also mends them after the depth or the
 * wetting depth changed outside a step. */
gr_status gr_rain_runoff_maps_update(gr_rain_runoff *s, double time) {
  const size_t m = sizeof(cl_mem);
  gr_status st = GR_OK;
  if (!s->maps_bound) {
    cl_int nx = s->nxl, ny = s->nyl, sw = s->params.flow_model == GR_FLOW_SHALLOW_WATER;
    const gr_rain_runoff_arg args[] = {
        {"qu", m, &s->qu},       {"qv", m, &s->qv},       {"nx", sizeof(nx), &nx},
        {"ny", sizeof(ny), &ny}, {"sw", sizeof(sw), &sw},
    };
    st = gr_rain_runoff_map_args(s, s->maps);
    if (st == GR_OK)
      st = GR_RAIN_RUNOFF_ARGS(s, s->maps, args);
    s->maps_bound = st == GR_OK;
  }
  cl_float4 t = gr_rain_runoff_map_time(time, time);
  /* The depth and limiter alternate with the fused local inertial step. */
  const gr_rain_runoff_arg step[] = {
      {"h", m, &s->h},           {"limit", m, &s->k},         {"qx", m, &s->qx[s->cur]},
      {"qy", m, &s->qy[s->cur]}, {"map_time", sizeof(t), &t},
  };
  if (st == GR_OK)
    st = GR_RAIN_RUNOFF_ARGS(s, s->maps, step);
  /* Read-modify-write per cell: the kernel takes (i, j) and leaves the
   * padding of the rounded-up launch alone, so each cell runs once. */
  if (st == GR_OK)
    st = gr_enqueue_2d(s->ctx, s->maps, 0, 0, (size_t)s->nxl, (size_t)s->nyl, NULL);
  return st;
}

/* The maps of the water there now only (create, reset): nothing yet, never
 * wet (arrival -1), dry (wet_since -1), then the present state folded in at
 * the present time. */
gr_status gr_rain_runoff_maps_restart(gr_rain_runoff *s) {
  size_t bytes = gr_rain_runoff_cells(s) * sizeof(cl_float);
  gr_status st = GR_OK;
  for (int a = 0; st == GR_OK && a < GR_RAIN_RUNOFF_MAP_ARRAYS; ++a)
    st = gr_rain_runoff_fill(s, s->map[a], a == 2 || a == 6 ? -1.0f : 0.0f, bytes);
  if (st == GR_OK)
    st = gr_rain_runoff_maps_update(s, s->time);
  return st;
}

/* ---------------------------------------------------------------- reading */

/* Runs the derive kernel (what: 0 surface, 1 velocity, 2 discharge, 3
 * infiltrated) into the scratch buffer. */
static gr_status gr_rain_runoff_derive_run(gr_rain_runoff *s, cl_int what) {
  size_t cells = gr_rain_runoff_cells(s);
  gr_status st = GR_OK;
  if (!s->scratch)
    st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, 3 * cells * sizeof(cl_float), NULL,
                          &s->scratch);
  cl_int nx = s->nxl, ny = s->nyl, sw = s->params.flow_model == GR_FLOW_SHALLOW_WATER;
  const size_t m = sizeof(cl_mem);
  const gr_rain_runoff_arg args[] = {
      {"h", m, &s->h},
      {"b", m, &s->b},
      {"qu", m, &s->qu},
      {"qv", m, &s->qv},
      {"sw", sizeof(sw), &sw},
      {"qx", m, &s->qx[s->cur]},
      {"qy", m, &s->qy[s->cur]},
      {"limit", m, &s->k},
      {"infiltrated", m, &s->inf},
      {"infiltrated_comp", m, &s->inf_c},
      {"out", m, &s->scratch},
      {"nx", sizeof(nx), &nx},
      {"ny", sizeof(ny), &ny},
      {"what", sizeof(what), &what},
  };
  if (st == GR_OK)
    st = GR_RAIN_RUNOFF_ARGS(s, s->derive, args);
  if (st == GR_OK)
    st = gr_enqueue_2d(s->ctx, s->derive, 0, 0, (size_t)nx, (size_t)ny, NULL);
  return st;
}

/* derive_run, then the owned cells' `comps` floats each back. */
static gr_status gr_rain_runoff_derive(gr_rain_runoff *s, cl_int what, size_t comps, float *host) {
  gr_status st = gr_rain_runoff_derive_run(s, what);
  if (st == GR_OK)
    st = gr_rain_runoff_read_own(s, s->scratch, comps, host);
  return st;
}

static gr_status gr_rain_runoff_sample_impl(gr_rain_runoff *s, const int *ij, int n,
                                            float *values) {
  if (n < 0)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The number of points to sample must be 0 or more (got %d).", n);
  for (int k = 0; k < n; ++k)
    if (ij[2 * k] < 0 || ij[2 * k] >= s->grid.nx || ij[2 * k + 1] < 0 ||
        ij[2 * k + 1] >= s->grid.ny)
      return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                          "Sample point %d is the cell (%d, %d), outside the %d x %d grid: give "
                          "cells from (0, 0) to (%d, %d).",
                          k, ij[2 * k], ij[2 * k + 1], s->grid.nx, s->grid.ny, s->grid.nx - 1,
                          s->grid.ny - 1);
  if (n == 0)
    return GR_OK;
  gr_status st = gr_rain_runoff_derive_run(s, 2);
  for (int k = 0; st == GR_OK && k < n; ++k) {
    /* The cell in the local array (past the ring). */
    size_t c = ((size_t)ij[2 * k + 1] + (size_t)s->ring[2]) * (size_t)s->nxl + (size_t)ij[2 * k] +
               (size_t)s->ring[0];
    float h = 0.0f, b = 0.0f, q = 0.0f;
    st = gr_buffer_read(s->ctx, s->h, c * sizeof(float), sizeof(float), &h);
    if (st == GR_OK)
      st = gr_buffer_read(s->ctx, s->b, c * sizeof(float), sizeof(float), &b);
    if (st == GR_OK)
      st = gr_buffer_read(s->ctx, s->scratch, c * sizeof(float), sizeof(float), &q);
    /* The surface as WATER_SURFACE gives it: the float sum b + h. */
    int off = s->has_nodata && s->mask[c];
    values[3 * k] = off ? NAN : h;
    values[3 * k + 1] = off ? NAN : b + h;
    values[3 * k + 2] = off ? NAN : q;
  }
  return st;
}

gr_status gr_rain_runoff_sample(gr_rain_runoff *s, const int *ij, int n, float *values) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_sample needs a simulation, the cells and room for values.");
  if (n > 0 && (!ij || !values))
    return GR_RAIN_RUNOFF_KEEP_ERROR(
        s,
        gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                     "gr_rain_runoff_sample needs a simulation, the cells and room for values."));
  return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_rain_runoff_sample_impl(s, ij, n, values));
}

static gr_status gr_rain_runoff_get_field_raw(gr_rain_runoff *s, gr_field f, float *host);

static gr_status gr_rain_runoff_get_field_impl(gr_rain_runoff *s, gr_field f, float *host) {
  gr_status st = gr_rain_runoff_get_field_raw(s, f, host);
  if (st == GR_OK)
    gr_rain_runoff_blank(s, host, f == GR_FIELD_VELOCITY ? 3 : 1);
  return st;
}

static gr_status gr_rain_runoff_get_field_raw(gr_rain_runoff *s, gr_field f, float *host) {
  size_t cells = gr_rain_runoff_own_cells(s);
  switch (f) {
  case GR_FIELD_WATER_DEPTH:
    return gr_rain_runoff_read_own(s, s->h, 1, host);
  case GR_FIELD_ELEVATION:
    return gr_rain_runoff_read_own(s, s->b, 1, host);
  case GR_FIELD_PERMEABILITY:
  case GR_FIELD_RAIN_RATE: {
    int field = f == GR_FIELD_RAIN_RATE ? s->has_rain : s->has_perm;
    if (field)
      return gr_rain_runoff_read_own(s, f == GR_FIELD_RAIN_RATE ? s->rain : s->perm, 1, host);
    float v = (float)(f == GR_FIELD_RAIN_RATE ? s->params.rain_rate : s->params.permeability);
    for (size_t c = 0; c < cells; ++c)
      host[c] = v;
    return GR_OK;
  }
  case GR_FIELD_WATER_SURFACE:
    return gr_rain_runoff_derive(s, 0, 1, host);
  case GR_FIELD_VELOCITY:
    return gr_rain_runoff_derive(s, 1, 3, host);
  case GR_FIELD_DISCHARGE:
    return gr_rain_runoff_derive(s, 2, 1, host);
  case GR_FIELD_INFILTRATED:
    return gr_rain_runoff_derive(s, 3, 1, host);
  default:
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The rain runoff simulation has no field '%s'; it has elevation, "
                        "water_depth, water_surface, velocity, discharge, infiltrated, "
                        "permeability and rain_rate.",
                        gr_rain_runoff_field_label(f));
  }
}

gr_status gr_rain_runoff_get_field(gr_rain_runoff *s, gr_field f, float *host) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_get_field needs a simulation and room for the field.");
  if (!host)
    return GR_RAIN_RUNOFF_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_get_field needs a simulation and room for the field."));
  return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_rain_runoff_get_field_impl(s, f, host));
}

gr_status gr_rain_runoff_ledger_get(gr_rain_runoff *s, gr_rain_runoff_ledger *out) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_ledger_get needs a simulation and a ledger to fill.");
  if (!out)
    return GR_RAIN_RUNOFF_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_ledger_get needs a simulation and a ledger to fill."));
  gr_fixed sums[GR_RAIN_RUNOFF_SUMS + 1];
  double hmax = 0.0;
  gr_status st = gr_rain_runoff_reduce_fixed(s, sums, &hmax);
  sums[GR_RAIN_RUNOFF_SUMS] = s->initial;
  /* Over every piece of the domain, as integers: the device's sums, the
   * initial water and the rain, exact in any order, so every split gives
   * the whole grid's bits. */
  long long words[2 * (GR_RAIN_RUNOFF_SUMS + 1)];
  gr_wide rain[2] = {s->rain_book[0], s->rain_book[1]};
  for (int q = 0; q <= GR_RAIN_RUNOFF_SUMS; ++q) {
    words[2 * q] = sums[q].coarse;
    words[2 * q + 1] = sums[q].fine;
  }
  if (st == GR_OK && s->allreduce) {
    double packed[GR_FIXED_PACKED(2 * (GR_RAIN_RUNOFF_SUMS + 1), 2)];
    gr_fixed_pack(words, 2 * (GR_RAIN_RUNOFF_SUMS + 1), rain, 2, packed);
    st = gr_rain_runoff_allreduce(s, packed, (int)(sizeof(packed) / sizeof(packed[0])),
                                  GR_REDUCE_SUM);
    gr_fixed_unpack(packed, words, 2 * (GR_RAIN_RUNOFF_SUMS + 1), rain, 2);
  }
  if (st == GR_OK && s->allreduce)
    st = gr_rain_runoff_allreduce(s, &hmax, 1, GR_REDUCE_MAX);
  if (st != GR_OK)
    return GR_RAIN_RUNOFF_KEEP_ERROR(s, st);
  double area = s->grid.dx * s->grid.dy, depth[GR_RAIN_RUNOFF_SUMS + 1];
  for (int q = 0; q <= GR_RAIN_RUNOFF_SUMS; ++q)
    depth[q] = gr_fixed_value((gr_fixed){words[2 * q], words[2 * q + 1]});
  memset(out, 0, sizeof(*out));
  out->time = s->time;
  out->steps = s->steps;
  out->initial_volume = depth[GR_RAIN_RUNOFF_SUMS] * area;
  out->rain_volume = (gr_wide_value(rain[0], GR_FIXED_COARSE_BITS + GR_RAIN_RUNOFF_STEP_BITS) +
                      gr_wide_value(rain[1], GR_FIXED_FINE_BITS + GR_RAIN_RUNOFF_STEP_BITS)) *
                     area;
  out->stored_volume = depth[0] * area;
  out->infiltrated_volume = depth[1] * area;
  out->outflow_volume = depth[2] * area;
  out->inflow_volume = depth[3] * area;
  out->balance_error = out->initial_volume + out->rain_volume + out->inflow_volume -
                       out->infiltrated_volume - out->outflow_volume - out->stored_volume;
  out->max_depth = hmax;
  return GR_OK;
}

/* ------------------------------------------------------------ flood maps */

static const char *const gr_rain_runoff_map_names[GR_RAIN_RUNOFF_MAP_COUNT] = {
    "max_depth", "max_speed", "arrival_time", "wet_duration", "hazard_rating", "hazard_class"};

const char *gr_rain_runoff_map_name(gr_rain_runoff_map map) {
  int m; /* any bit pattern the enum may hold */
  memcpy(&m, &map, sizeof(m));
  return m >= 0 && m < GR_RAIN_RUNOFF_MAP_COUNT ? gr_rain_runoff_map_names[m] : NULL;
}

int gr_rain_runoff_hazard_class(double rating) {
  /* FD2321/TR2 Table 13.1: the upper ends of "low" and "moderate" belong to
   * the class above; 2.0 itself is still "significant". */
  if (rating > 2.0)
    return 3;
  if (rating >= 1.25)
    return 2;
  if (rating >= 0.75)
    return 1;
  return 0;
}

static gr_status gr_rain_runoff_get_map_impl(gr_rain_runoff *s, gr_rain_runoff_map map,
                                             float *host) {
  size_t cells = gr_rain_runoff_own_cells(s);
  const char *name = gr_rain_runoff_map_name(map);
  if (!name)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The rain runoff simulation has no flood map %d; its maps are 0 "
                        "max_depth to %d hazard_class (gr_rain_runoff_map).",
                        (int)map, GR_RAIN_RUNOFF_MAP_COUNT - 1);
  int buf = map == GR_RAIN_RUNOFF_HAZARD_CLASS ? 4 : (int)map;
  gr_status st = gr_rain_runoff_read_own(s, s->map[buf], 1, host);
  if (st != GR_OK)
    return st;
  if (map == GR_RAIN_RUNOFF_WET_DURATION) {
    /* The ended spells' duration (host: its high word; lo: its low word),
     * and where a spell is under way (since >= 0) the time now less its
     * start, in double. */
    float *lo = malloc(3 * cells * sizeof(float));
    if (!lo)
      return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
    float *since = lo + cells, *since_lo = lo + 2 * cells;
    st = gr_rain_runoff_read_own(s, s->map[5], 1, lo);
    if (st == GR_OK)
      st = gr_rain_runoff_read_own(s, s->map[6], 1, since);
    if (st == GR_OK)
      st = gr_rain_runoff_read_own(s, s->map[7], 1, since_lo);
    for (size_t c = 0; st == GR_OK && c < cells; ++c) {
      double now = since[c] >= 0.0f ? s->time - ((double)since[c] + (double)since_lo[c]) : 0.0;
      host[c] = (float)(((double)host[c] + (double)lo[c]) + now);
    }
    free(lo);
  } else if (map == GR_RAIN_RUNOFF_ARRIVAL_TIME) {
    for (size_t c = 0; c < cells; ++c)
      host[c] = host[c] < 0.0f ? NAN : host[c];
  } else if (map == GR_RAIN_RUNOFF_HAZARD_CLASS) {
    for (size_t c = 0; c < cells; ++c)
      host[c] = (float)gr_rain_runoff_hazard_class(host[c]);
  }
  if (st == GR_OK)
    gr_rain_runoff_blank(s, host, 1);
  return st;
}

gr_status gr_rain_runoff_get_map(gr_rain_runoff *s, gr_rain_runoff_map map, float *host) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_get_map needs a simulation and room for the map.");
  if (!host)
    return GR_RAIN_RUNOFF_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_rain_runoff_get_map needs a simulation and room for the map."));
  return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_rain_runoff_get_map_impl(s, map, host));
}
