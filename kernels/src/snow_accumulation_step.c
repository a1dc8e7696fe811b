/* Snow accumulation core, host side: the step (snow_accumulation_internal.h)
 * in its stages, and what it gives back (fields, the ledger). The
 * snowfall's direction and the exposure view are in
 * snow_accumulation_view.c. */
#include "snow_accumulation_internal.h"

/* What the stages of one step pass their kernels: the grid, the view, the
 * snowfall's direction and the step's rates, in the kernels' types. */
typedef struct gr_snac_step_vars {
  cl_int nx, ny, gi0, gj0;
  float dx, dy, zref;
  float dir_x, dir_y, dir_z;
  float rate_dt, amplitude, max_depth, kdt, keep;
  cl_uint seed;
  cl_int terrain_drawn, pieced, vw, vh;
  gr_snac_view v;
} gr_snac_step_vars;

/* Whether the terrain is drawn into the view: only where it could hide
 * itself, where a triangle of the snow surface rises faster than the snow
 * falls steeply (snow_accumulation_slope_reduce). Snow straight down, or a
 * surface gentler than the snow's descent, leaves a view of the objects
 * alone, and a far cheaper step. A piece's cells (its local arrays, ring
 * included, are all the domain's) give its share of the maximum; the
 * pieces then agree on it and on the view's box through the allreduce. */
static gr_status gr_snac_terrain_drawn(gr_snow_accumulation *s, const double dd[3],
                                       gr_snac_step_vars *sv) {
  gr_context *ctx = s->ctx;
  sv->terrain_drawn = 1;
  double horiz = hypot(dd[0], dd[1]);
  double g2[2] = {0.0, 0.0};
  {
    cl_int cells = sv->nx * sv->ny;
    const gr_snac_arg sa[] = {GR_SNAC_MEM("ground", s->ground), GR_SNAC_MEM("depth", s->arr[0]),
                              GR_SNAC_VAL("nx", sv->nx),        GR_SNAC_VAL("ny", sv->ny),
                              GR_SNAC_VAL("dx", sv->dx),        GR_SNAC_VAL("dy", sv->dy),
                              GR_SNAC_VAL("n", cells)};
    /* Snow straight down cannot be hidden by the surface: no reduction
     * (and no read-back) that step. */
    gr_status sst =
        horiz == 0.0 ? GR_OK : gr_snac_args(s, s->slope_k, sa, sizeof(sa) / sizeof(sa[0]));
    if (sst == GR_OK && horiz > 0.0)
      sst = gr_reduction_run(ctx, &s->red_slope, s->slope_k, NULL, g2);
    if (sst != GR_OK)
      return sst;
  }
  if (sv->pieced) {
    /* What the view's box and the drawing decision rest on, over the
     * domain: every piece then sets up the same view as the whole grid. */
    double m[6] = {g2[0], g2[1], -s->bmin, s->bmax, s->init_max, s->snow_bound};
    gr_status rst = gr_snac_allreduce(s, m, 6, GR_REDUCE_MAX);
    if (rst != GR_OK)
      return rst;
    g2[0] = m[0], g2[1] = m[1];
    s->bmin = -m[2], s->bmax = m[3], s->init_max = m[4], s->snow_bound = m[5];
    if (s->zref != s->bmin) {
      s->zref = s->bmin;
      rst = gr_snac_upload_geometry(s);
      if (rst != GR_OK)
        return rst;
    }
  }
  double steepest = sqrt(g2[0] * g2[0] + g2[1] * g2[1]);
  if (horiz == 0.0 || steepest * (1.0 + GR_SNAC_SLOPE_MARGIN) * horiz < fabs(dd[2]))
    sv->terrain_drawn = 0;
  return GR_OK;
}

/* The step's view and rates, once the terrain decision is made. */
static void gr_snac_step_rates(const gr_snow_accumulation *s, double dt, const double dd[3],
                               gr_snac_step_vars *sv) {
  gr_snac_view_of(s, dd, &sv->v);
  sv->vw = sv->v.vw, sv->vh = sv->v.vh;
  sv->zref = (float)s->zref;
  sv->dir_x = (float)dd[0], sv->dir_y = (float)dd[1], sv->dir_z = (float)dd[2];
  const gr_snow_accumulation_params *p = &s->params;
  sv->rate_dt = (float)(p->snowfall_rate * dt), sv->amplitude = (float)p->noise_amplitude;
  sv->max_depth = (float)p->max_depth;
  /* Stability as a relaxation rate: k = -ln(1 - f), so that an excess
   * alone keeps (1 - f)^t after t seconds; the step integrates it with the
   * growth (snac_settle) from keep = e^-k dt and k dt. f = 1: k infinite
   * (kdt 1e30), all the excess goes. */
  double krate = p->stability_factor >= 1.0 ? HUGE_VAL : -log1p(-p->stability_factor);
  sv->kdt = (float)fmin(krate * dt, 1.0e30);
  sv->keep = (float)exp(-krate * dt);
  sv->seed = (cl_uint)p->seed;
}

/* The noise is fixed in space: made again only for another seed or
 * scale. */
static gr_status gr_snac_make_noise(gr_snow_accumulation *s, const gr_snac_step_vars *sv) {
  const gr_grid *g = &s->grid;
  double inv_scale = 1.0 / s->params.noise_scale;
  float noise_x0 = (float)fmod(g->x0 * inv_scale, GR_SNAC_NOISE_PERIOD);
  float noise_y0 = (float)fmod(g->y0 * inv_scale, GR_SNAC_NOISE_PERIOD);
  float noise_dx = (float)(g->dx * inv_scale), noise_dy = (float)(g->dy * inv_scale);
  cl_uint seed = sv->seed;
  gr_status nst = GR_OK;
  if (!s->noise_made || s->noise_seed != seed || s->noise_key[0] != noise_x0 ||
      s->noise_key[1] != noise_y0 || s->noise_key[2] != noise_dx || s->noise_key[3] != noise_dy) {
    const gr_snac_arg na[] = {GR_SNAC_VAL("nx", sv->nx),         GR_SNAC_VAL("ny", sv->ny),
                              GR_SNAC_VAL("gi0", sv->gi0),       GR_SNAC_VAL("gj0", sv->gj0),
                              GR_SNAC_VAL("noise_x0", noise_x0), GR_SNAC_VAL("noise_y0", noise_y0),
                              GR_SNAC_VAL("noise_dx", noise_dx), GR_SNAC_VAL("noise_dy", noise_dy),
                              GR_SNAC_VAL("seed", seed),         GR_SNAC_MEM("noise", s->noise)};
    nst = gr_snac_args(s, s->noise_k, na, sizeof(na) / sizeof(na[0]));
    if (nst == GR_OK)
      nst = gr_enqueue_2d(s->ctx, s->noise_k, 0, 0, (size_t)sv->nx, (size_t)sv->ny, NULL);
    if (nst == GR_OK) {
      s->noise_made = 1;
      s->noise_seed = seed;
      s->noise_key[0] = noise_x0, s->noise_key[1] = noise_y0;
      s->noise_key[2] = noise_dx, s->noise_key[3] = noise_dy;
    }
  }
  return nst;
}

/* 1. the view: the terrain (when drawn) and the objects' triangles; a
 * piece's views are then merged over the pieces. */
static gr_status gr_snac_draw_view(gr_snow_accumulation *s, gr_snac_step_vars *sv) {
  gr_context *ctx = s->ctx;
  const gr_snac_view *v = &sv->v;
  cl_int empty = GR_SNAC_EMPTY;
  gr_status st = gr_cl_check(
      ctx,
      clEnqueueFillBuffer(gr_context_queue(ctx), s->view, &empty, sizeof(empty), 0,
                          (size_t)sv->vw * (size_t)sv->vh * sizeof(cl_int), 0, NULL, NULL),
      "Clearing the exposure view");
  const gr_snac_arg rt[] = {
      GR_SNAC_MEM("ground", s->ground), GR_SNAC_MEM("depth", s->arr[0]),
      GR_SNAC_VAL("nx", sv->nx),        GR_SNAC_VAL("ny", sv->ny),
      GR_SNAC_VAL("gi0", sv->gi0),      GR_SNAC_VAL("gj0", sv->gj0),
      GR_SNAC_VAL("dx", sv->dx),        GR_SNAC_VAL("dy", sv->dy),
      GR_SNAC_VAL("zref", sv->zref),    GR_SNAC_VAL("tau_x", v->tau_x),
      GR_SNAC_VAL("tau_y", v->tau_y),   GR_SNAC_VAL("qx0", v->qx0),
      GR_SNAC_VAL("qy0", v->qy0),       GR_SNAC_VAL("inv_texel", v->inv_texel),
      GR_SNAC_VAL("vw", sv->vw),        GR_SNAC_VAL("vh", sv->vh),
      GR_SNAC_MEM("view", s->view)};
  if (st == GR_OK)
    st = gr_snac_args(s, s->raster_terrain, rt, sizeof(rt) / sizeof(rt[0]));
  if (st == GR_OK && sv->nx > 1 && sv->ny > 1 && sv->terrain_drawn)
    st = gr_enqueue_2d(ctx, s->raster_terrain, 0, 0, (size_t)(sv->nx - 1), (size_t)(sv->ny - 1),
                       NULL);
  /* The objects: every row on a whole grid, and on a piece whose view
   * stays its own (no terrain drawn); else its share of the rows, the
   * pieces' shares covering the view (the maximum over the pieces is
   * then the whole view wherever it is combined, and a piece's grid points
   * read only rows of its own share). */
  cl_int ntri = s->ntri, row_lo = 0, row_hi = sv->vh - 1;
  if (sv->pieced && sv->terrain_drawn) {
    int lo, hi;
    gr_snac_object_rows(s, v, &lo, &hi);
    row_lo = lo, row_hi = hi;
  }
  if (st == GR_OK && ntri > 0) {
    const gr_snac_arg ro[] = {GR_SNAC_MEM("tri", s->o_tri),
                              GR_SNAC_VAL("ntri", ntri),
                              GR_SNAC_VAL("tau_x", v->tau_x),
                              GR_SNAC_VAL("tau_y", v->tau_y),
                              GR_SNAC_VAL("qx0", v->qx0),
                              GR_SNAC_VAL("qy0", v->qy0),
                              GR_SNAC_VAL("inv_texel", v->inv_texel),
                              GR_SNAC_VAL("vw", sv->vw),
                              GR_SNAC_VAL("vh", sv->vh),
                              GR_SNAC_VAL("row_lo", row_lo),
                              GR_SNAC_VAL("row_hi", row_hi),
                              GR_SNAC_MEM("view", s->view)};
    st = gr_snac_args(s, s->raster_objects, ro, sizeof(ro) / sizeof(ro[0]));
    if (st == GR_OK)
      st = gr_enqueue_1d(ctx, s->raster_objects, (size_t)ntri);
  }
  if (st == GR_OK)
    st = gr_snac_mark(s, &s->tm.view_ms);
  /* A piece drew its own cells: the views' maximum over the pieces, texel
   * by texel, is the whole grid's view (see "Pieces" in the header). */
  s->objects_by_point = 0;
  const float dir[3] = {sv->dir_x, sv->dir_y, sv->dir_z};
  if (st == GR_OK && sv->pieced && sv->terrain_drawn)
    st = gr_snac_view_reduce(s, v, dir);
  if (st == GR_OK && sv->pieced)
    st = gr_snac_mark(s, &s->tm.combine_ms);
  return st;
}

/* 2-3. exposure and growth of the grid points. */
static gr_status gr_snac_grow_points(gr_snow_accumulation *s, gr_snac_step_vars *sv) {
  const gr_snac_view *v = &sv->v;
  const gr_snac_arg ex[] = {GR_SNAC_MEM("ground", s->ground),
                            GR_SNAC_MEM("depth", s->arr[0]),
                            GR_SNAC_VAL("nx", sv->nx),
                            GR_SNAC_VAL("ny", sv->ny),
                            GR_SNAC_VAL("gi0", sv->gi0),
                            GR_SNAC_VAL("gj0", sv->gj0),
                            GR_SNAC_VAL("dx", sv->dx),
                            GR_SNAC_VAL("dy", sv->dy),
                            GR_SNAC_VAL("zref", sv->zref),
                            GR_SNAC_VAL("dir_x", sv->dir_x),
                            GR_SNAC_VAL("dir_y", sv->dir_y),
                            GR_SNAC_VAL("dir_z", sv->dir_z),
                            GR_SNAC_VAL("tau_x", v->tau_x),
                            GR_SNAC_VAL("tau_y", v->tau_y),
                            GR_SNAC_VAL("qx0", v->qx0),
                            GR_SNAC_VAL("qy0", v->qy0),
                            GR_SNAC_VAL("inv_texel", v->inv_texel),
                            GR_SNAC_VAL("texel", v->texel),
                            GR_SNAC_VAL("vw", sv->vw),
                            GR_SNAC_VAL("vh", sv->vh),
                            GR_SNAC_MEM("view", s->view),
                            GR_SNAC_VAL("rate_dt", sv->rate_dt),
                            GR_SNAC_VAL("amplitude", sv->amplitude),
                            GR_SNAC_MEM("noise", s->noise),
                            GR_SNAC_MEM("exposure", s->arr[6]),
                            GR_SNAC_MEM("growth", s->growth)};
  gr_status st = gr_snac_args(s, s->exposure_k, ex, sizeof(ex) / sizeof(ex[0]));
  if (st == GR_OK)
    st = gr_enqueue_2d(s->ctx, s->exposure_k, 0, 0, (size_t)sv->nx, (size_t)sv->ny, NULL);
  if (st == GR_OK)
    st = gr_snac_mark(s, &s->tm.exposure_ms);
  return st;
}

/* 4. blur and dilation, between growth and scratch; *cur gets the buffer
 * that holds the result. */
static gr_status gr_snac_blur_growth(gr_snow_accumulation *s, gr_snac_step_vars *sv,
                                     cl_mem *cur_out) {
  gr_context *ctx = s->ctx;
  gr_status st = GR_OK;
  cl_mem cur = s->growth, other = s->scratch;
  cl_int radius = s->params.blur_radius;
  for (cl_int axis = 0; st == GR_OK && radius > 0 && axis < 2; ++axis) {
    const gr_snac_arg bl[] = {GR_SNAC_MEM("in", cur),    GR_SNAC_VAL("nx", sv->nx),
                              GR_SNAC_VAL("ny", sv->ny), GR_SNAC_VAL("radius", radius),
                              GR_SNAC_VAL("axis", axis), GR_SNAC_MEM("w", s->weights),
                              GR_SNAC_MEM("out", other)};
    st = gr_snac_args(s, s->blur, bl, sizeof(bl) / sizeof(bl[0]));
    if (st == GR_OK)
      st = gr_enqueue_2d(ctx, s->blur, 0, 0, (size_t)sv->nx, (size_t)sv->ny, NULL);
    cl_mem t = cur;
    cur = other, other = t;
  }
  if (st == GR_OK && s->params.dilation) {
    const gr_snac_arg dl[] = {GR_SNAC_MEM("in", cur), GR_SNAC_VAL("nx", sv->nx),
                              GR_SNAC_VAL("ny", sv->ny), GR_SNAC_MEM("out", other)};
    st = gr_snac_args(s, s->dilate, dl, sizeof(dl) / sizeof(dl[0]));
    if (st == GR_OK)
      st = gr_enqueue_2d(ctx, s->dilate, 0, 0, (size_t)sv->nx, (size_t)sv->ny, NULL);
    cl_mem t = cur;
    cur = other, other = t;
  }
  if (st == GR_OK)
    st = gr_snac_mark(s, &s->tm.blur_ms);
  *cur_out = cur;
  return st;
}

/* 5. increment and stability of the grid points from the growth in cur;
 * then a piece's ring: the snow depth the next step's normals, blur and
 * view (and this step's objects) read beyond its own rows. */
static gr_status gr_snac_apply_growth(gr_snow_accumulation *s, gr_snac_step_vars *sv, cl_mem cur) {
  gr_context *ctx = s->ctx;
  const gr_snac_arg ap[] = {GR_SNAC_MEM("ground", s->ground),
                            GR_SNAC_VAL("nx", sv->nx),
                            GR_SNAC_VAL("ny", sv->ny),
                            GR_SNAC_VAL("dx", sv->dx),
                            GR_SNAC_VAL("dy", sv->dy),
                            GR_SNAC_MEM("growth", cur),
                            GR_SNAC_VAL("max_depth", sv->max_depth),
                            GR_SNAC_VAL("keep", sv->keep),
                            GR_SNAC_VAL("kdt", sv->kdt),
                            GR_SNAC_MEM("depth", s->arr[0]),
                            GR_SNAC_MEM("depth_lo", s->arr[1]),
                            GR_SNAC_MEM("fall", s->arr[2]),
                            GR_SNAC_MEM("fall_lo", s->arr[3]),
                            GR_SNAC_MEM("shed", s->arr[4]),
                            GR_SNAC_MEM("shed_lo", s->arr[5])};
  gr_status st = gr_snac_args(s, s->apply, ap, sizeof(ap) / sizeof(ap[0]));
  if (st == GR_OK)
    st = gr_enqueue_2d(ctx, s->apply, 0, 0, (size_t)sv->nx, (size_t)sv->ny, NULL);
  if (st == GR_OK)
    st = gr_snac_mark(s, &s->tm.apply_ms);
  if (st == GR_OK && sv->pieced) {
    st = s->halo_exchange(s->halo_user);
    if (st != GR_OK)
      st = gr_set_error(ctx, st,
                        "The snow accumulation piece's halo exchange (the callback given to "
                        "gr_snow_accumulation_set_halo_exchange) failed in step %lld with %s; the "
                        "piece's ring is not fresh, so restore a checkpoint before stepping on.",
                        s->steps + 1, gr_status_string(st));
    else
      st = gr_snac_mark(s, &s->tm.combine_ms);
  }
  return st;
}

/* The same exposure, growth and stability on the objects' own arrays:
 * pass 0 their faces (centroids), pass 1 the accumulation textures'
 * samples. */
static gr_status gr_snac_grow_objects(gr_snow_accumulation *s, gr_snac_step_vars *sv, int pass) {
  gr_context *ctx = s->ctx;
  const gr_snac_view *v = &sv->v;
  gr_status st = GR_OK;
  cl_int nv = pass ? s->ns : s->ntri;
  if (nv == 0)
    return GR_OK;
  const cl_mem *A = pass ? s->t_arr : s->o_arr;
  const cl_mem *P = pass ? &s->t_pos : &s->o_pos, *N = pass ? &s->t_nrm : &s->o_nrm,
               *L = pass ? &s->t_local : &s->o_local;
  const gr_snac_arg ob[] = {GR_SNAC_MEM("pos", *P),
                            GR_SNAC_MEM("nrm", *N),
                            GR_SNAC_MEM("lattice", *L),
                            GR_SNAC_VAL("nv", nv),
                            GR_SNAC_VAL("dir_x", sv->dir_x),
                            GR_SNAC_VAL("dir_y", sv->dir_y),
                            GR_SNAC_VAL("dir_z", sv->dir_z),
                            GR_SNAC_VAL("tau_x", v->tau_x),
                            GR_SNAC_VAL("tau_y", v->tau_y),
                            GR_SNAC_VAL("qx0", v->qx0),
                            GR_SNAC_VAL("qy0", v->qy0),
                            GR_SNAC_VAL("inv_texel", v->inv_texel),
                            GR_SNAC_VAL("texel", v->texel),
                            GR_SNAC_VAL("vw", sv->vw),
                            GR_SNAC_VAL("vh", sv->vh),
                            GR_SNAC_MEM("view", s->view),
                            GR_SNAC_VAL("rate_dt", sv->rate_dt),
                            GR_SNAC_VAL("amplitude", sv->amplitude),
                            GR_SNAC_VAL("seed", sv->seed),
                            GR_SNAC_VAL("max_depth", sv->max_depth),
                            GR_SNAC_VAL("keep", sv->keep),
                            GR_SNAC_VAL("kdt", sv->kdt),
                            GR_SNAC_VAL("terrain_drawn", sv->terrain_drawn),
                            GR_SNAC_MEM("ground", s->ground),
                            GR_SNAC_MEM("gdepth", s->arr[0]),
                            GR_SNAC_VAL("gnx", sv->nx),
                            GR_SNAC_VAL("gny", sv->ny),
                            GR_SNAC_VAL("gdx", sv->dx),
                            GR_SNAC_VAL("gdy", sv->dy),
                            GR_SNAC_VAL("zref", sv->zref),
                            GR_SNAC_MEM("exposure", A[6]),
                            GR_SNAC_MEM("depth", A[0]),
                            GR_SNAC_MEM("depth_lo", A[1]),
                            GR_SNAC_MEM("fall", A[2]),
                            GR_SNAC_MEM("fall_lo", A[3]),
                            GR_SNAC_MEM("shed", A[4]),
                            GR_SNAC_MEM("shed_lo", A[5])};
  /* On a piece, the surface under the points when the objects kernel
   * needs it (no terrain in the view) comes from the pieces that hold
   * it; their exposure in the combined view, where it was combined per
   * point, is in s->o_surface already (faces, then samples:
   * gr_snac_view_reduce). */
  cl_int have_surface = sv->pieced && !sv->terrain_drawn;
  cl_int have_exposure = sv->pieced && sv->terrain_drawn && s->objects_by_point;
  cl_int surface_first = have_exposure && pass ? s->ntri : 0;
  if (have_surface)
    st = gr_snac_object_surface(s, *P, *N, nv, v->texel);
  if (st == GR_OK && have_surface)
    st = gr_snac_mark(s, &s->tm.combine_ms);
  cl_mem surf = have_surface || have_exposure ? s->o_surface : s->ground;
  const gr_snac_arg ob2[] = {
      GR_SNAC_VAL("have_surface", have_surface), GR_SNAC_VAL("have_exposure", have_exposure),
      GR_SNAC_VAL("surface_first", surface_first), GR_SNAC_MEM("surface", surf)};
  if (st == GR_OK)
    st = gr_snac_args(s, s->objects_k, ob, sizeof(ob) / sizeof(ob[0]));
  if (st == GR_OK)
    st = gr_snac_args(s, s->objects_k, ob2, sizeof(ob2) / sizeof(ob2[0]));
  if (st == GR_OK)
    st = gr_enqueue_1d(ctx, s->objects_k, (size_t)nv);
  if (st == GR_OK)
    st = gr_snac_mark(s, &s->tm.objects_ms);
  return st;
}

static gr_status gr_snac_step_impl(gr_snow_accumulation *s, double dt) {
  gr_context *ctx = s->ctx;
  const gr_grid *g = &s->grid;
  double t0 = gr_snac_now_ms();
  if (s->timing) {
    gr_status st = gr_finish(ctx);
    if (st != GR_OK)
      return st;
    t0 = s->t_mark = gr_snac_now_ms();
  }
  double dd[3];
  gr_snac_direction(s, dd);
  gr_snac_step_vars sv;
  memset(&sv, 0, sizeof(sv));
  sv.nx = g->nx, sv.ny = g->ny, sv.gi0 = 0, sv.gj0 = s->row0;
  sv.dx = (float)g->dx, sv.dy = (float)g->dy;
  sv.pieced = gr_snac_pieced(s);
  if (sv.pieced && (!s->allreduce || !s->halo_exchange))
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "A snow accumulation piece with neighbours steps only with an allreduce "
                        "and a halo exchange set (gr_snow_accumulation_set_allreduce, "
                        "gr_snow_accumulation_set_halo_exchange).");
  gr_status st = gr_snac_terrain_drawn(s, dd, &sv);
  if (st != GR_OK)
    return st;
  gr_snac_step_rates(s, dt, dd, &sv);
  st = gr_snac_make_noise(s, &sv);
  if (s->timing)
    s->tm.host_ms += gr_snac_now_ms() - t0, s->t_mark = gr_snac_now_ms();
  if (st != GR_OK)
    return st;

  st = gr_snac_draw_view(s, &sv);
  if (st == GR_OK)
    st = gr_snac_grow_points(s, &sv);
  cl_mem cur = s->growth;
  if (st == GR_OK)
    st = gr_snac_blur_growth(s, &sv, &cur);
  if (st == GR_OK)
    st = gr_snac_apply_growth(s, &sv, cur);
  for (int pass = 0; st == GR_OK && pass < 2; ++pass)
    st = gr_snac_grow_objects(s, &sv, pass);
  if (st == GR_OK && s->timing)
    s->tm.steps++;
  if (st == GR_OK && (s->steps + 1) % GR_SNAC_SYNC_EVERY == 0)
    st = gr_finish(ctx);
  return st;
}

gr_status gr_snow_accumulation_step(gr_snow_accumulation *s, double dt) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_step needs a simulation.");
  if (!(dt >= GR_SNAC_MIN_DT && dt <= GR_SNAC_MAX_DT))
    return GR_SNAC_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow accumulation time step must lie between 1e-6 and 86400 s (got "
                        "%g s).",
                        dt));
  if (s->aborted)
    return GR_SNAC_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_ABORTED,
                        "The snow accumulation was stopped by its progress callback; set the "
                        "callback again or reset to go on."));
  gr_status st = gr_snac_step_impl(s, dt);
  if (st != GR_OK)
    return GR_SNAC_KEEP_ERROR(s, st);
  s->time += dt;
  s->steps++;
  /* The view's z range: snow never stands above this (it only grows by the
   * fall, and with StabilityFactor 1 never above the larger of MaxDepth and
   * the initial snow). */
  double grow = s->params.snowfall_rate * (1.0 + s->params.noise_amplitude) * dt;
  s->snow_bound += grow;
  if (s->params.stability_factor >= 1.0)
    s->snow_bound = fmin(s->snow_bound, fmax(s->params.max_depth, s->init_max) + grow);
  if (s->progress && s->progress(s->progress_user, s->time) != 0)
    s->aborted = 1;
  /* A stop asked on any piece stops every piece after this step. */
  if (gr_snac_pieced(s)) {
    double flag = s->aborted ? 1.0 : 0.0;
    st = gr_snac_allreduce(s, &flag, 1, GR_REDUCE_MAX);
    if (st != GR_OK)
      return GR_SNAC_KEEP_ERROR(s, st);
    s->aborted = flag != 0.0;
  }
  return GR_OK;
}

gr_status gr_snow_accumulation_get_field(gr_snow_accumulation *s, gr_field f, float *host) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_get_field needs a simulation.");
  if (!host)
    return GR_SNAC_KEEP_ERROR(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                              "gr_snow_accumulation_get_field needs a place for "
                                              "the values (got NULL)."));
  /* The own rows (a piece's local arrays hold its rings around them). */
  size_t cells = gr_snac_cells(s), own = (size_t)s->grid.nx * (size_t)s->own_ny;
  size_t offset = (size_t)s->ring_s * (size_t)s->grid.nx * sizeof(float);
  cl_mem src = NULL;
  gr_status st = GR_OK;
  switch (f) {
  case GR_FIELD_SNOW_DEPTH:
    src = s->arr[0];
    break;
  case GR_FIELD_EXPOSURE:
    src = s->arr[6];
    break;
  case GR_FIELD_ELEVATION:
    src = s->ground;
    break;
  case GR_FIELD_SNOW_DENSITY:
    for (size_t c = 0; c < own; ++c)
      host[c] = (float)s->params.snow_density;
    return GR_OK;
  case GR_FIELD_SNOW_SURFACE: {
    cl_int n = (cl_int)cells;
    const gr_snac_arg sa[] = {GR_SNAC_MEM("ground", s->ground), GR_SNAC_MEM("depth", s->arr[0]),
                              GR_SNAC_VAL("n", n), GR_SNAC_MEM("out", s->scratch)};
    st = gr_snac_args(s, s->surface, sa, sizeof(sa) / sizeof(sa[0]));
    if (st == GR_OK)
      st = gr_enqueue_1d(s->ctx, s->surface, cells);
    src = s->scratch;
    break;
  }
  default: {
    const char *name = gr_field_name(f);
    return GR_SNAC_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow accumulation simulation has no output field '%s'; it gives "
                        "snow_depth, snow_surface, snow_density, exposure and elevation.",
                        name ? name : "(unknown field)"));
  }
  }
  if (st == GR_OK)
    st = gr_buffer_read(s->ctx, src, offset, own * sizeof(float), host);
  return st == GR_OK ? GR_OK : GR_SNAC_KEEP_ERROR(s, st);
}

gr_status gr_snow_accumulation_ledger_get(gr_snow_accumulation *s,
                                          gr_snow_accumulation_ledger *out) {
  if (!s || !out)
    return s ? GR_SNAC_KEEP_ERROR(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                                  "gr_snow_accumulation_ledger_get needs a place "
                                                  "for the ledger."))
             : gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                            "gr_snow_accumulation_ledger_get needs a simulation.");
  /* The grid's sums over the domain's rows in order (collective on a
   * piece); the objects' are the same on every piece and count once. */
  double gs[4], os[GR_SNAC_SUMS];
  gr_status st = gr_snac_grid_sums(s, gs);
  if (st == GR_OK)
    st = gr_snac_sums(s, 1, 0, s->ntri, os);
  if (st != GR_OK)
    return GR_SNAC_KEEP_ERROR(s, st);
  double a = s->grid.dx * s->grid.dy;
  memset(out, 0, sizeof(*out));
  out->time = s->time;
  out->steps = s->steps;
  out->initial_volume = gs[3] * a + s->initial_objects;
  out->stored_volume_terrain = gs[0] * a;
  out->stored_volume_objects = os[0];
  out->stored_volume = out->stored_volume_terrain + out->stored_volume_objects;
  out->snowfall_volume = gs[1] * a + os[1] + s->retired_fall;
  out->shed_volume = gs[2] * a + os[2] + s->retired_shed;
  out->dropped_volume = s->dropped;
  out->balance_error = out->initial_volume + out->snowfall_volume - out->shed_volume -
                       out->dropped_volume - out->stored_volume;
  return GR_OK;
}

void gr_snow_accumulation_set_progress(gr_snow_accumulation *s, gr_progress_fn fn, void *user) {
  if (!s)
    return;
  s->progress = fn;
  s->progress_user = user;
  s->aborted = 0;
}
