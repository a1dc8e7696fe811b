/* Rain runoff core, host side: the step (rain_runoff_internal.h): the
 * step kernels' arguments, the launches of both flow models' steps, and
 * gr_rain_runoff_step. */
#include "rain_runoff_internal.h"

/* --------------------------------------------------------------- stepping */

/* The values the step kernels take besides the state's arrays, from the
 * parameters and the inputs now (gr_rain_runoff_bind). */
typedef struct gr_rain_runoff_binding {
  cl_int nx, ny;
  cl_float dt, inv_dx, inv_dy, g, n2;
  cl_int use_rain, use_perm;
  cl_float rain_uniform, perm_uniform;
  /* The domain's edges' kinds and levels; a side with a neighbour is open
   * (its ring is refreshed from the neighbour after every step). */
  cl_int bnd[4];
  cl_float lvl[4];
  /* The optional inputs, or the one-float dummy where one is absent. */
  cl_mem rain, perm, src, n2map, nodata;
  cl_int use_src, use_n2, use_nodata;
} gr_rain_runoff_binding;

static void gr_rain_runoff_binding_init(const gr_rain_runoff *s, cl_float dt,
                                        gr_rain_runoff_binding *v) {
  const gr_rain_runoff_params *p = &s->params;
  const gr_grid *gd = &s->grid;
  v->nx = s->nxl;
  v->ny = s->nyl;
  v->dt = dt;
  v->inv_dx = (cl_float)(1.0 / gd->dx);
  v->inv_dy = (cl_float)(1.0 / gd->dy);
  v->g = (cl_float)GR_GRAVITY;
  v->n2 = (cl_float)(p->manning_n * p->manning_n);
  v->use_rain = s->has_rain;
  v->use_perm = s->has_perm;
  v->rain_uniform = (cl_float)p->rain_rate;
  v->perm_uniform = (cl_float)p->permeability;
  for (int e = 0; e < 4; ++e) {
    int kind; /* any bit pattern the enum may hold: validated as a whole number 0-3 */
    memcpy(&kind, &p->boundary[e], sizeof(kind));
    v->bnd[e] = s->ring[e] ? GR_RAIN_RUNOFF_B_OPEN : kind;
    v->lvl[e] = (cl_float)p->boundary_level[e];
  }
  v->rain = s->has_rain ? s->rain : s->dummy;
  v->perm = s->has_perm ? s->perm : s->dummy;
  v->use_src = gr_rain_runoff_has_sources(s);
  v->src = v->use_src ? s->src : s->dummy;
  v->use_n2 = s->has_n2;
  v->n2map = v->use_n2 ? s->n2map : s->dummy;
  v->use_nodata = s->has_nodata;
  v->nodata = v->use_nodata ? s->nodata : s->dummy;
}

/* The arguments every step kernel of either model takes: the grid, the
 * step, and the rain, infiltration, sources and no-data cells. */
static gr_status gr_rain_runoff_bind_inputs(gr_rain_runoff *s, cl_kernel k,
                                            const gr_rain_runoff_binding *v) {
  const size_t m = sizeof(cl_mem);
  const gr_rain_runoff_arg inputs[] = {
      {"rain", m, &v->rain},
      {"perm", m, &v->perm},
      {"src", m, &v->src},
      {"use_src", sizeof(v->use_src), &v->use_src},
      {"nodata", m, &v->nodata},
      {"use_nodata", sizeof(v->use_nodata), &v->use_nodata},
      {"nx", sizeof(v->nx), &v->nx},
      {"ny", sizeof(v->ny), &v->ny},
      {"dt", sizeof(v->dt), &v->dt},
      {"inv_dx", sizeof(v->inv_dx), &v->inv_dx},
      {"inv_dy", sizeof(v->inv_dy), &v->inv_dy},
      {"use_rain", sizeof(v->use_rain), &v->use_rain},
      {"rain_uniform", sizeof(v->rain_uniform), &v->rain_uniform},
      {"use_perm", sizeof(v->use_perm), &v->use_perm},
      {"perm_uniform", sizeof(v->perm_uniform), &v->perm_uniform},
  };
  return GR_RAIN_RUNOFF_ARGS(s, k, inputs);
}

/* The friction's arguments (the bed, gravity, the roughness) of the
 * kernels that compute faces. */
static gr_status gr_rain_runoff_bind_friction(gr_rain_runoff *s, cl_kernel k,
                                              const gr_rain_runoff_binding *v) {
  const size_t m = sizeof(cl_mem);
  const gr_rain_runoff_arg friction[] = {
      {"b", m, &s->b},
      {"g", sizeof(v->g), &v->g},
      {"n2", sizeof(v->n2), &v->n2},
      {"n2map", m, &v->n2map},
      {"use_n2", sizeof(v->use_n2), &v->use_n2},
  };
  return GR_RAIN_RUNOFF_ARGS(s, k, friction);
}

/* The domain's edges' kinds and levels, for the kernels that apply them. */
static gr_status gr_rain_runoff_bind_edges(gr_rain_runoff *s, cl_kernel k,
                                           const gr_rain_runoff_binding *v) {
  const gr_rain_runoff_arg edges[] = {
      {"bnd_w", sizeof(cl_int), &v->bnd[0]},   {"bnd_e", sizeof(cl_int), &v->bnd[1]},
      {"bnd_s", sizeof(cl_int), &v->bnd[2]},   {"bnd_n", sizeof(cl_int), &v->bnd[3]},
      {"lvl_w", sizeof(cl_float), &v->lvl[0]}, {"lvl_e", sizeof(cl_float), &v->lvl[1]},
      {"lvl_s", sizeof(cl_float), &v->lvl[2]}, {"lvl_n", sizeof(cl_float), &v->lvl[3]},
  };
  return GR_RAIN_RUNOFF_ARGS(s, k, edges);
}

/* The Kahan sums the kernels that change the depth book into: the depth's
 * compensation, the infiltration, the outflow and the inflow. */
static gr_status gr_rain_runoff_bind_books(gr_rain_runoff *s, cl_kernel k) {
  const size_t m = sizeof(cl_mem);
  const gr_rain_runoff_arg books[] = {
      {"h_comp", m, &s->h_c},
      {"infiltrated", m, &s->inf},
      {"infiltrated_comp", m, &s->inf_c},
      {"outflow", m, &s->out},
      {"outflow_comp", m, &s->out_c},
      {"inflow", m, &s->in},
      {"inflow_comp", m, &s->in_c},
  };
  return GR_RAIN_RUNOFF_ARGS(s, k, books);
}

/* The flood maps' arguments of kernel k, the last kernel of a step, which
 * folds its state into them (map_time is set before every launch). */
static gr_status gr_rain_runoff_bind_maps(gr_rain_runoff *s, cl_kernel k) {
  cl_float4 t0 = gr_rain_runoff_map_time(0.0, 0.0);
  gr_status st = gr_rain_runoff_map_args(s, k);
  if (st == GR_OK)
    st = gr_kernel_arg(s->ctx, k, "map_time", sizeof(t0), &t0);
  return st;
}

/* The shallow-water kernels' arguments: the separate launches' and the
 * fused stages' (which also take the interior's tiles and their tile's
 * local memory). */
static gr_status gr_rain_runoff_bind_sw(gr_rain_runoff *s, const gr_rain_runoff_binding *v) {
  const size_t m = sizeof(cl_mem);
  /* The face arrays, or the one-float dummy until a step takes the
   * separate launches (gr_rain_runoff_face_arrays). */
  cl_mem fx = s->fx ? s->fx : s->dummy, fy = s->fy ? s->fy : s->dummy;
  const gr_rain_runoff_arg sw[] = {
      {"h", m, &s->h},     {"qu", m, &s->qu},   {"qv", m, &s->qv}, {"h1", m, &s->h1},
      {"wh", m, &s->wh},   {"wu", m, &s->wu},   {"wv", m, &s->wv}, {"u1", m, &s->u1},
      {"v1", m, &s->v1},   {"fx", m, &fx},      {"fy", m, &fy},    {"dh1", m, &s->dh1},
      {"qu1", m, &s->qu1}, {"qv1", m, &s->qv1},
  };
  /* The separate launches, then the fused stages, which take the same
   * arguments. */
  cl_kernel swk[12] = {s->sw_prep,      s->sw_faces[0], s->sw_update[0],    s->sw_faces[1],
                       s->sw_update[1], s->sw_edges,    s->sw_stage[0],     s->sw_stage[1],
                       s->sw_inner[0],  s->sw_inner[1], s->sw_rim_faces[0], s->sw_rim_faces[1]};
  gr_status st = GR_OK;
  for (int k = 0; st == GR_OK && k < 12; ++k) {
    st = GR_RAIN_RUNOFF_ARGS(s, swk[k], sw);
    if (st == GR_OK)
      st = gr_rain_runoff_bind_inputs(s, swk[k], v);
    if (st == GR_OK)
      st = gr_rain_runoff_bind_friction(s, swk[k], v);
    if (st == GR_OK)
      st = gr_rain_runoff_bind_edges(s, swk[k], v);
    if (st == GR_OK)
      st = gr_rain_runoff_bind_books(s, swk[k]);
    if (st == GR_OK)
      st = gr_rain_runoff_bind_maps(s, swk[k]);
  }
  /* The fused stages' interior tiles and their tile's local memory. */
  for (int k = 6; st == GR_OK && k < 10; ++k)
    st = gr_kernel_arg(s->ctx, swk[k], "tiles", sizeof(s->sw_tiles), s->sw_tiles);
  for (int k = 6; st == GR_OK && k < 10; ++k)
    st = gr_kernel_arg(s->ctx, swk[k], "tile", s->sw_tile_bytes, NULL);
  return st;
}

/* The local inertial kernels' arguments: the three launches' and the fused
 * step's. */
static gr_status gr_rain_runoff_bind_li(gr_rain_runoff *s, const gr_rain_runoff_binding *v) {
  const size_t m = sizeof(cl_mem);
  /* The depth and limiter the three step kernels share (each takes those
   * it has). */
  const gr_rain_runoff_arg state[] = {{"h", m, &s->h}, {"limit", m, &s->k}};
  cl_kernel kernels[] = {s->flux, s->flux_edges, s->limit, s->update, s->li_step, s->limit_update};
  gr_status st = GR_OK;
  for (int i = 0; st == GR_OK && i < 6; ++i)
    st = GR_RAIN_RUNOFF_ARGS(s, kernels[i], state);
  for (int i = 0; st == GR_OK && i < 6; ++i)
    st = gr_rain_runoff_bind_inputs(s, kernels[i], v);
  if (st == GR_OK)
    st = gr_rain_runoff_bind_friction(s, s->flux, v);
  if (st == GR_OK)
    st = gr_rain_runoff_bind_friction(s, s->flux_edges, v);
  if (st == GR_OK)
    st = gr_rain_runoff_bind_friction(s, s->li_step, v);
  cl_float theta = (cl_float)GR_RAIN_RUNOFF_THETA;
  if (st == GR_OK)
    st = gr_kernel_arg(s->ctx, s->flux, "theta", sizeof(theta), &theta);
  if (st == GR_OK)
    st = gr_kernel_arg(s->ctx, s->li_step, "theta", sizeof(theta), &theta);
  if (st == GR_OK)
    st = gr_rain_runoff_bind_edges(s, s->flux_edges, v);
  if (st == GR_OK)
    st = gr_rain_runoff_bind_books(s, s->update);
  if (st == GR_OK)
    st = gr_rain_runoff_bind_maps(s, s->update);
  if (st == GR_OK)
    st = gr_rain_runoff_bind_books(s, s->limit_update);
  if (st == GR_OK)
    st = gr_rain_runoff_bind_maps(s, s->limit_update);
  if (st == GR_OK)
    st = gr_rain_runoff_bind_books(s, s->li_step);
  if (st == GR_OK)
    st = gr_rain_runoff_bind_maps(s, s->li_step);
  /* The edges rain_runoff_flux_edges writes, which the fused step reads. */
  cl_int fixed = 0;
  for (int e = 0; e < 4; ++e)
    fixed |= v->bnd[e] != GR_RAIN_RUNOFF_B_OPEN ? 1 << e : 0;
  if (st == GR_OK)
    st = gr_kernel_arg(s->ctx, s->li_step, "fixed", sizeof(fixed), &fixed);
  if (st == GR_OK && s->li_local[0] > 0)
    st = gr_kernel_arg(s->ctx, s->li_step, "lmem",
                       3 * s->li_local[0] * s->li_local[1] * sizeof(cl_float), NULL);
  return st;
}

/* Binds every step-kernel argument but the alternating face arrays, when
 * something they hold has changed since the last step. */
static gr_status gr_rain_runoff_bind(gr_rain_runoff *s, cl_float dt) {
  /* The fused step sets the depth and limiter every step (they alternate),
   * the merged limiter and update the depth; the other kernels keep those
   * they were bound to. */
  int li = s->params.flow_model == GR_FLOW_LOCAL_INERTIAL;
  int h_set = li && (s->fused || s->merged), k_set = li && s->fused;
  if (s->args_set && s->args_dt == dt && (h_set || s->args_h == s->h) &&
      (k_set || s->args_k == s->k))
    return GR_OK;
  s->args_h = s->h;
  s->args_k = s->k;
  gr_rain_runoff_binding v;
  gr_rain_runoff_binding_init(s, dt, &v);
  gr_status st = s->params.flow_model == GR_FLOW_SHALLOW_WATER ? gr_rain_runoff_bind_sw(s, &v)
                                                               : gr_rain_runoff_bind_li(s, &v);
  s->args_set = st == GR_OK;
  s->args_dt = dt;
  return st;
}

/* The separate shallow-water launches' face arrays (six planes of x-faces
 * and of y-faces, gr_sw_line_face), made the first time a step takes that
 * path: the fused stages, the default on GPUs, keep their faces in local
 * memory, and the arrays would take 805 MB at 4096^2 (12.9 GB at 16384^2)
 * for nothing. Until then the kernels get the one-float dummy for them. */
static gr_status gr_rain_runoff_face_arrays(gr_rain_runoff *s) {
  if (s->fx)
    return GR_OK;
  size_t nx = (size_t)s->nxl, ny = (size_t)s->nyl;
  gr_status st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, (nx + 1) * ny * 6 * sizeof(cl_float),
                                  NULL, &s->fx);
  if (st == GR_OK)
    st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, nx * (ny + 1) * 6 * sizeof(cl_float), NULL,
                          &s->fy);
  if (st != GR_OK) {
    gr_buffer_release(&s->fx);
    gr_buffer_release(&s->fy);
  }
  s->args_set = 0;
  return st;
}

/* A batch of steps being enqueued (gr_rain_runoff_enqueue). */
typedef struct gr_rain_runoff_batch {
  double dt;
  gr_rain_runoff_watch *w; /* advance's, with a progress callback; or NULL */
  int *stop;               /* becomes 1 when the watch's callback asks to stop */
  int done;                /* the steps enqueued */
  int exchange;            /* a piece with a halo exchange: one after every step */
  int per_step;            /* edge hydrographs: the sources made again before every step */
  /* The end time of each step, summed as s->time is (the flood maps'
   * arrival times; the one before, the step's start, where wet spells
   * begin and end). */
  double t_end;
  gr_fixed rate_sum; /* the hyetograph's rates the steps took (m/s, floats) */
} gr_rain_runoff_batch;

/* Before a step's launches: its sources and its share of the hyetograph;
 * *map_time gets the step's start and end (gr_rain_runoff_map_time), when
 * its last launch folds the new state into the flood maps. */
static gr_status gr_rain_runoff_step_begin(gr_rain_runoff *s, gr_rain_runoff_batch *b,
                                           cl_float4 *map_time) {
  gr_status st = GR_OK;
  if (b->per_step)
    st = gr_rain_runoff_sources_update(s, b->t_end, b->t_end + b->dt);
  if (st == GR_OK && s->hy_n)
    st = gr_rain_runoff_hyetograph_step(s, b->t_end, b->t_end + b->dt, &b->rate_sum);
  double t0 = b->t_end;
  *map_time = gr_rain_runoff_map_time(t0, b->t_end += b->dt);
  return st;
}

/* After a step's launches (st: how their enqueueing went): the step counts,
 * a piece exchanges its halo, and the watch sees the time it reaches. */
static gr_status gr_rain_runoff_step_end(gr_rain_runoff *s, gr_rain_runoff_batch *b, gr_status st) {
  if (st == GR_OK)
    ++b->done;
  if (st == GR_OK && b->exchange)
    st = gr_rain_runoff_exchange(s, s->steps + b->done);
  if (st == GR_OK && b->w)
    st = gr_rain_runoff_watch_step(s, b->w, s->time + b->dt * (double)b->done, b->stop);
  return st;
}

/* One shallow-water step's launches; stage 2's update folds the new state
 * into the flood maps at map_time. */
static gr_status gr_rain_runoff_sw_launch(gr_rain_runoff *s, cl_float4 map_time) {
  gr_status st = GR_OK;
  /* Fused: each of Heun's stages in two launches, the interior's tiles
   * and the rim's, their faces in local memory (rain_runoff_sw_inner1, 2
   * and rain_runoff_sw_stage1, 2). */
  if (st == GR_OK && s->sw_fused)
    st = gr_kernel_arg(s->ctx, s->sw_stage[1], "map_time", sizeof(map_time), &map_time);
  if (st == GR_OK && s->sw_fused)
    st = gr_kernel_arg(s->ctx, s->sw_inner[1], "map_time", sizeof(map_time), &map_time);
  for (int stage = 0; st == GR_OK && s->sw_fused && stage < 2; ++stage) {
    const cl_int *t = s->sw_tiles;
    if (t[1] > t[0] && t[3] > t[2])
      st = gr_enqueue_2d(s->ctx, s->sw_inner[stage], 0, 0, (size_t)(t[1] - t[0]) * s->sw_local[0],
                         (size_t)(t[3] - t[2]) * s->sw_local[1], s->sw_local);
    if (st == GR_OK && s->sw_rim)
      st = gr_enqueue_2d(s->ctx, s->sw_stage[stage], 0, 0, s->sw_rim * s->sw_local[0],
                         s->sw_local[1], s->sw_local);
  }
  /* Or stage 1's points, then Heun's two stages: every face once, then
   * every cell from its four faces. */
  if (st == GR_OK && !s->sw_fused)
    st = gr_enqueue_2d(s->ctx, s->sw_prep, 0, 0, (size_t)s->nxl, (size_t)s->nyl, NULL);
  if (st == GR_OK && !s->sw_fused)
    st = gr_kernel_arg(s->ctx, s->sw_update[1], "map_time", sizeof(map_time), &map_time);
  for (int stage = 0; st == GR_OK && !s->sw_fused && stage < 2; ++stage) {
    /* The interior's faces (rain_runoff_sw_faces*, at offset (2, 2)),
     * then the rim's (rain_runoff_sw_rim*). */
    size_t nx = (size_t)s->nxl, ny = (size_t)s->nyl, rim = (nx + 1) * (ny + 1);
    if (nx >= 4 && ny >= 4) {
      st = gr_enqueue_2d(s->ctx, s->sw_faces[stage], 2, 2, nx - 3, ny - 3, NULL);
      rim = 4 * (nx + 1) + 4 * (ny - 3);
    }
    if (st == GR_OK)
      st = gr_enqueue_1d(s->ctx, s->sw_rim_faces[stage], rim);
    if (st == GR_OK)
      st = gr_enqueue_2d(s->ctx, s->sw_update[stage], 0, 0, (size_t)s->nxl, (size_t)s->nyl, NULL);
    /* The rim's cells book the stage's edge flows (after their update). */
    if (st == GR_OK)
      st = gr_enqueue_1d(s->ctx, s->sw_edges, 2 * ((size_t)s->nxl + (size_t)s->nyl));
  }
  return st;
}

/* One local inertial step's launches: the fused step (in work-groups of
 * li_local, gx x gy work-items) or the three launches; edges: a domain
 * edge is not open (rain_runoff_flux_edges rewrites it). The update folds
 * the new state into the flood maps at map_time. */
static gr_status gr_rain_runoff_li_launch(gr_rain_runoff *s, int fused, int edges, size_t gx,
                                          size_t gy, cl_float4 map_time) {
  const size_t m = sizeof(cl_mem);
  int old = s->cur, now = 1 - s->cur;
  gr_status st = GR_OK;
  /* The edges that are not open, from the step's start: the fused step
   * reads them, the three launches' flux kernel writes them open first. */
  const cl_mem *eargs[6] = {&s->h, &s->k, &s->qx[old], &s->qy[old], &s->qx[now], &s->qy[now]};
  for (int a = 0; st == GR_OK && edges && a < (fused ? 6 : 4); ++a)
    st = gr_rain_runoff_arg_at(s, s->flux_edges, s->ix_edges[fused ? a : a + 2], m,
                               eargs[fused ? a : a + 2]);
  if (fused) {
    const cl_mem *sargs[8] = {&s->h,       &s->h_alt,   &s->k,       &s->k_alt,
                              &s->qx[old], &s->qy[old], &s->qx[now], &s->qy[now]};
    for (int a = 0; st == GR_OK && a < 8; ++a)
      st = gr_rain_runoff_arg_at(s, s->li_step, s->ix_step[a], m, sargs[a]);
    if (st == GR_OK)
      st = gr_rain_runoff_arg_at(s, s->li_step, s->ix_step[8], sizeof(map_time), &map_time);
    if (st == GR_OK && edges)
      st = gr_enqueue_1d(s->ctx, s->flux_edges, 2 * ((size_t)s->nxl + (size_t)s->nyl));
    if (st == GR_OK)
      st = gr_enqueue_2d(s->ctx, s->li_step, 0, 0, gx, gy, s->li_local);
    if (st == GR_OK) {
      /* The new faces, depth and limiters are current. */
      cl_mem t = s->h;
      s->h = s->h_alt;
      s->h_alt = t;
      t = s->k;
      s->k = s->k_alt;
      s->k_alt = t;
      s->cur = now;
    }
    return st;
  }
  for (int a = 0; st == GR_OK && a < 4; ++a)
    st = gr_rain_runoff_arg_at(s, s->flux, s->ix_flux[a], m, eargs[a + 2]);
  for (int a = 0; st == GR_OK && !s->merged && a < 2; ++a)
    st = gr_rain_runoff_arg_at(s, s->limit, s->ix_limit[a], m, eargs[a + 4]);
  for (int a = 0; st == GR_OK && !s->merged && a < 2; ++a)
    st = gr_rain_runoff_arg_at(s, s->update, s->ix_update[a], m, eargs[a + 4]);
  if (st == GR_OK && !s->merged)
    st = gr_rain_runoff_arg_at(s, s->update, s->ix_update[2], sizeof(map_time), &map_time);
  /* Merged: the depth alternates (limit_update reads h, writes h_alt), so
   * the flux kernels and limit_update take it every step. */
  const cl_mem *largs[5] = {&s->qx[now], &s->qy[now], NULL, &s->h, &s->h_alt};
  for (int a = 0; st == GR_OK && s->merged && a < 5; ++a)
    st = a == 2
             ? gr_rain_runoff_arg_at(s, s->limit_update, s->ix_lu[a], sizeof(map_time), &map_time)
             : gr_rain_runoff_arg_at(s, s->limit_update, s->ix_lu[a], m, largs[a]);
  if (st == GR_OK && s->merged)
    st = gr_rain_runoff_arg_at(s, s->flux, s->ix_flux[4], m, &s->h);
  if (st == GR_OK && s->merged && edges)
    st = gr_rain_runoff_arg_at(s, s->flux_edges, s->ix_edges[0], m, &s->h);
  /* GPUs: a warp a row (GR_RAIN_RUNOFF_LI_GROUP_X); CPUs: the runtime's. */
  static const size_t li_group[2] = {GR_RAIN_RUNOFF_LI_GROUP_X, GR_RAIN_RUNOFF_LI_GROUP_Y};
  const size_t *lg = s->gpu ? li_group : NULL;
  if (st == GR_OK)
    st = gr_enqueue_2d(s->ctx, s->flux, 0, 0, (size_t)s->nxl + 1, (size_t)s->nyl + 1, lg);
  /* The edges that are not open, after the flux kernel wrote them so. */
  if (st == GR_OK && edges)
    st = gr_enqueue_1d(s->ctx, s->flux_edges, 2 * ((size_t)s->nxl + (size_t)s->nyl));
  if (st == GR_OK)
    s->cur = now; /* the flux kernel is enqueued: the new faces are current */
  if (st == GR_OK && s->merged) {
    st = gr_enqueue_2d(s->ctx, s->limit_update, 0, 0, (size_t)s->nxl, (size_t)s->nyl, lg);
    if (st == GR_OK) {
      cl_mem t = s->h; /* the new depth is current */
      s->h = s->h_alt;
      s->h_alt = t;
    }
    return st;
  }
  if (st == GR_OK)
    st = gr_enqueue_2d(s->ctx, s->limit, 0, 0, (size_t)s->nxl, (size_t)s->nyl, lg);
  if (st == GR_OK)
    st = gr_enqueue_2d(s->ctx, s->update, 0, 0, (size_t)s->nxl, (size_t)s->nyl, lg);
  return st;
}

/* Enqueues up to nsteps steps of dt; *done gets the steps enqueued. With a
 * watch (advance with a progress callback) it may stop early at a step
 * boundary: *stop becomes 1. */
gr_status gr_rain_runoff_enqueue(gr_rain_runoff *s, double dt, int nsteps, gr_rain_runoff_watch *w,
                                 int *done_out, int *stop) {
  cl_float dtf = (cl_float)dt;
  gr_status st = gr_rain_runoff_specialise(s);
  if (st == GR_OK && s->params.flow_model == GR_FLOW_SHALLOW_WATER && !s->sw_fused)
    st = gr_rain_runoff_face_arrays(s);
  if (st == GR_OK)
    st = gr_rain_runoff_bind(s, dtf);
  int sw = s->params.flow_model == GR_FLOW_SHALLOW_WATER;
  gr_rain_runoff_batch b = {dt,
                            w,
                            stop,
                            0,
                            s->halo_exchange && gr_rain_runoff_has_ring(s),
                            gr_rain_runoff_has_edge_inflow(s),
                            s->time,
                            {0, 0}};
  /* Any of the domain's edges not open: rain_runoff_flux_edges rewrites it. */
  int edges = 0;
  for (int e = 0; e < 4; ++e)
    edges |= !s->ring[e] && s->params.boundary[e] != GR_BOUNDARY_OPEN;
  while (sw && st == GR_OK && b.done < nsteps && !*stop) {
    cl_float4 map_time;
    st = gr_rain_runoff_step_begin(s, &b, &map_time);
    if (st == GR_OK)
      st = gr_rain_runoff_sw_launch(s, map_time);
    st = gr_rain_runoff_step_end(s, &b, st);
  }
  int fused = !sw && s->fused;
  size_t bytes = gr_rain_runoff_cells(s) * sizeof(cl_float);
  if (st == GR_OK && !sw && (fused || s->merged) && !s->h_alt)
    st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, bytes, NULL, &s->h_alt);
  if (st == GR_OK && fused && !s->k_alt)
    st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, bytes, NULL, &s->k_alt);
  /* The fused step's work-groups: tiles of li_local - 3 cells each way. */
  size_t tx = fused ? s->li_local[0] - 3 : 1, ty = fused ? s->li_local[1] - 3 : 1;
  size_t gx = ((size_t)s->nxl + tx - 1) / tx * s->li_local[0];
  size_t gy = ((size_t)s->nyl + ty - 1) / ty * s->li_local[1];
  while (!sw && st == GR_OK && b.done < nsteps && !*stop) {
    cl_float4 map_time;
    st = gr_rain_runoff_step_begin(s, &b, &map_time);
    if (st == GR_OK)
      st = gr_rain_runoff_li_launch(s, fused, edges, gx, gy, map_time);
    st = gr_rain_runoff_step_end(s, &b, st);
  }
  /* The ledger counts the steps whose launches were all enqueued, with the
   * rain the device added: the float dt it was given. */
  gr_rain_runoff_rain_book(s, &b.rate_sum, dtf, b.done);
  /* Step by step, not dt * done: a piece that steps one step per call (to
   * exchange its halo) then keeps the same time, to the bit, as the whole
   * grid stepping many per call. */
  for (int k = 0; k < b.done; ++k)
    s->time += dt;
  s->steps += b.done;
  *done_out = b.done;
  return st;
}

static gr_status gr_rain_runoff_step_impl(gr_rain_runoff *s, double dt, int nsteps) {
  double max_dt = gr_rain_runoff_core_max(GR_RAIN_RUNOFF_P_MAX_DT);
  if (!(dt >= GR_RAIN_RUNOFF_MIN_DT && dt <= max_dt))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The time step dt must lie between %g and %g s (got %g s).",
                        GR_RAIN_RUNOFF_MIN_DT, max_dt, dt);
  if (nsteps < 0)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The number of steps must be 0 or more (got %d).", nsteps);
  if (nsteps == 0)
    return GR_OK;
  if (nsteps > 1 && gr_rain_runoff_has_ring(s) && !s->halo_exchange)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "A rain runoff piece with neighbours and no halo exchange takes one step "
                        "per call (got %d): exchange its halo between steps, or give it an "
                        "exchange with gr_rain_runoff_set_halo_exchange.",
                        nsteps);
  gr_status st = GR_OK;
  for (int left = nsteps; st == GR_OK && left > 0;) {
    int k = left < GR_RAIN_RUNOFF_IN_FLIGHT ? left : GR_RAIN_RUNOFF_IN_FLIGHT, done = 0, stop = 0;
    if (left < nsteps) /* after the first batch: wait for the one before */
      st = gr_finish(s->ctx);
    if (st == GR_OK)
      st = gr_rain_runoff_enqueue(s, dt, k, NULL, &done, &stop);
    left -= k;
  }
  return st;
}

gr_status gr_rain_runoff_step(gr_rain_runoff *s, double dt, int nsteps) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT, "gr_rain_runoff_step needs a simulation.");
  return GR_RAIN_RUNOFF_KEEP_ERROR(s, gr_rain_runoff_step_impl(s, dt, nsteps));
}
