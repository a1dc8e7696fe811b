/* Snow deformation core, host side: the talus relaxation
 * (snow_deformation_internal.h): its thresholds and arguments, the
 * convergence checks, the blocked and work-group iterations, and the reach
 * a SlumpSpeed gives a step. */
#include "snow_deformation_internal.h"

/* RelaxTolerance, but at least GR_SNOW_MIN_MOVE (below it an iteration
 * could move nothing). */
static float gr_snow_tolerance(const gr_snow_deformation *s) {
  float tol = (float)s->params.relax_tolerance;
  return tol > GR_SNOW_MIN_MOVE ? tol : GR_SNOW_MIN_MOVE;
}

/* The check: the largest amount a point of the givers' window R can still
 * move, and the box of the points that can move more than the tolerance
 * (out[1..4]: -x0, x1, -y0, y1), in two halves so that the host need not
 * wait between them: start enqueues the reduction on r (on a piece, over
 * its own points of the window; *empty when it has none), finish reads it
 * back and, on a piece, takes the largest over every piece
 * (GR_REDUCE_MAX), the box in the domain's indices and back in the local
 * arrays': every piece goes on, and stops, with the whole grid's window. */
static gr_status gr_snow_relax_check_start(gr_snow_deformation *s, gr_reduction *r, int x0, int y0,
                                           int x1, int y1, int *empty) {
  if (gr_snow_has_ring(s))
    gr_snow_own_clip(s, &x0, &y0, &x1, &y1);
  *empty = x0 > x1 || y0 > y1;
  if (*empty)
    return GR_OK;
  cl_kernel k = s->check_reduce;
  cl_int nx = s->grid.nx, w = x1 - x0 + 1, cnt = w * (y1 - y0 + 1);
  float tol = gr_snow_tolerance(s);
  gr_status st = GR_SNOW_ARG(s, k, "movable", s->movable);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "nx", nx);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "x0", x0);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "y0", y0);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "w", w);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "n", cnt);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "tol", tol);
  if (st == GR_OK)
    st = gr_reduction_start(s->ctx, r, k);
  return st;
}

static gr_status gr_snow_relax_check_finish(gr_snow_deformation *s, gr_reduction *r, int empty,
                                            double out[GR_SNOW_CHECK_MAXES]) {
  gr_status st = GR_OK;
  if (!empty) {
    st = gr_reduction_finish(s->ctx, r, NULL, out);
  } else {
    out[0] = 0.0;
    for (int q = 1; q < GR_SNOW_CHECK_MAXES; ++q)
      out[q] = -1.0e9;
  }
  if (st != GR_OK || !gr_snow_has_ring(s))
    return st;
  const double shift[GR_SNOW_CHECK_MAXES] = {0.0, -(double)s->ox, (double)s->ox, -(double)s->oy,
                                             (double)s->oy};
  for (int q = 1; q < GR_SNOW_CHECK_MAXES; ++q)
    if (out[q] > -1.0e8)
      out[q] += shift[q];
  if (s->allreduce)
    st = gr_snow_allreduce(s, out, GR_SNOW_CHECK_MAXES, GR_REDUCE_MAX);
  for (int q = 1; q < GR_SNOW_CHECK_MAXES; ++q)
    if (out[q] > -1.0e8)
      out[q] -= shift[q];
  return st;
}

/* The talus thresholds: MaxSlope times the distance along x, y and the
 * diagonal. */
static void gr_snow_thresholds(const gr_snow_deformation *s, float thr[3]) {
  double slope = s->params.max_slope, dx = s->grid.dx, dy = s->grid.dy;
  thr[0] = (float)(slope * dx);
  thr[1] = (float)(slope * dy);
  thr[2] = (float)(slope * sqrt(dx * dx + dy * dy));
}

/* The arguments every talus kernel shares: the ground, the lowest
 * underside (or the reach's ceilings) and its clearance (snow_excess), the
 * grid and the thresholds. */
static gr_status gr_snow_talus_args(gr_snow_deformation *s, cl_kernel k) {
  cl_int nx = s->grid.nx, ny = s->grid.ny;
  float thr[3];
  gr_snow_thresholds(s, thr);
  float clearance = (float)(2.0 * GR_SNOW_DEFORMATION_CONTACT_GAP);
  /* Under a reach the ceilings are its plane (snow_reach_ceiling). */
  cl_mem ceiling = s->reach_on ? s->scratch : s->under_min;
  const gr_snow_arg args[] = {{"ground", sizeof(cl_mem), &s->ground},
                              {"under_min", sizeof(cl_mem), &ceiling},
                              {"clearance", sizeof(clearance), &clearance},
                              {"nx", sizeof(nx), &nx},
                              {"ny", sizeof(ny), &ny},
                              {"tx", sizeof(float), &thr[0]},
                              {"ty", sizeof(float), &thr[1]},
                              {"td", sizeof(float), &thr[2]}};
  return gr_snow_args(s, k, args, sizeof(args) / sizeof(args[0]));
}

/* snow_relax_rate over [x0, x_end) x [y0, y_end) (nothing when that is
 * empty, as a piece's cut may be): the rates of iteration t of a launch
 * whose givers' window at t = 0 is [gx0, gx_end) x [gy0, gy_end). */
static gr_status gr_snow_relax_rate(gr_snow_deformation *s, float tol, cl_int gx0, cl_int gy0,
                                    cl_int gx_end, cl_int gy_end, cl_int t, cl_int x0, cl_int y0,
                                    cl_int x_end, cl_int y_end) {
  const gr_snow_arg rate[] = {{"depth", sizeof(cl_mem), &s->depth[s->cur]},
                              {"tol", sizeof(tol), &tol},
                              {"gx0", sizeof(gx0), &gx0},
                              {"gy0", sizeof(gy0), &gy0},
                              {"gx_end", sizeof(gx_end), &gx_end},
                              {"gy_end", sizeof(gy_end), &gy_end},
                              {"t", sizeof(t), &t},
                              {"x_end", sizeof(x_end), &x_end},
                              {"y_end", sizeof(y_end), &y_end},
                              {"rate", sizeof(cl_mem), &s->rate},
                              {"rate_in", sizeof(cl_mem), &s->rate_in},
                              {"movable", sizeof(cl_mem), &s->movable}};
  gr_status st = gr_snow_talus_args(s, s->relax_rate);
  if (st == GR_OK)
    st = gr_snow_args(s, s->relax_rate, rate, sizeof(rate) / sizeof(rate[0]));
  if (st == GR_OK && x_end > x0 && y_end > y0)
    st = gr_enqueue_2d(s->ctx, s->relax_rate, (size_t)x0, (size_t)y0, (size_t)(x_end - x0),
                       (size_t)(y_end - y0), NULL);
  return st;
}

/* Iteration t of a launch whose givers' window at t = 0 is [gx0, gx_end) x
 * [gy0, gy_end), in two launches: the rates on the window grown by t + 2,
 * the moves on it grown by t + 1; the state flips buffers. */
static gr_status gr_snow_relax_once(gr_snow_deformation *s, cl_int gx0, cl_int gy0, cl_int gx_end,
                                    cl_int gy_end, cl_int t, float tol) {
  cl_int nx = s->grid.nx, ny = s->grid.ny, nxt = 1 - s->cur;
  cl_int rx0 = gx0 - t - 2 > 0 ? gx0 - t - 2 : 0, ry0 = gy0 - t - 2 > 0 ? gy0 - t - 2 : 0;
  cl_int rx_end = gx_end + t + 2 < nx ? gx_end + t + 2 : nx,
         ry_end = gy_end + t + 2 < ny ? gy_end + t + 2 : ny;
  cl_int mx0 = gx0 - t - 1 > 0 ? gx0 - t - 1 : 0, my0 = gy0 - t - 1 > 0 ? gy0 - t - 1 : 0;
  cl_int mx_end = gx_end + t + 1 < nx ? gx_end + t + 1 : nx,
         my_end = gy_end + t + 1 < ny ? gy_end + t + 1 : ny;
  gr_status st = gr_snow_relax_rate(s, tol, gx0, gy0, gx_end, gy_end, t, rx0, ry0, rx_end, ry_end);
  const gr_snow_arg move[] = {{"depth", sizeof(cl_mem), &s->depth[s->cur]},
                              {"density", sizeof(cl_mem), &s->density[s->cur]},
                              {"rate", sizeof(cl_mem), &s->rate},
                              {"rate_in", sizeof(cl_mem), &s->rate_in},
                              {"x_end", sizeof(mx_end), &mx_end},
                              {"y_end", sizeof(my_end), &my_end},
                              {"depth_out", sizeof(cl_mem), &s->depth[nxt]},
                              {"density_out", sizeof(cl_mem), &s->density[nxt]}};
  if (st == GR_OK)
    st = gr_snow_talus_args(s, s->relax_move);
  if (st == GR_OK)
    st = gr_snow_args(s, s->relax_move, move, sizeof(move) / sizeof(move[0]));
  if (st == GR_OK && mx_end > mx0 && my_end > my0)
    st = gr_enqueue_2d(s->ctx, s->relax_move, (size_t)mx0, (size_t)my0, (size_t)(mx_end - mx0),
                       (size_t)(my_end - my0), NULL);
  if (st == GR_OK)
    s->cur = nxt;
  return st;
}

/* iters iterations in one launch of snow_relax_block over the move window
 * [mx0, mx_end) x [my0, my_end); the state flips buffers. */
static gr_status gr_snow_relax_blocked(gr_snow_deformation *s, cl_int gx0, cl_int gy0,
                                       cl_int gx_end, cl_int gy_end, cl_int mx0, cl_int my0,
                                       cl_int mx_end, cl_int my_end, cl_int iters, float tol) {
  cl_int nxt = 1 - s->cur;
  size_t bw = s->block[0], bh = s->block[1];
  size_t lbytes = 8 * (bw + 4 * GR_SNOW_BLOCK_ITERATIONS) * (bh + 4 * GR_SNOW_BLOCK_ITERATIONS) *
                  sizeof(cl_float);
  const gr_snow_arg args[] = {{"depth", sizeof(cl_mem), &s->depth[s->cur]},
                              {"density", sizeof(cl_mem), &s->density[s->cur]},
                              {"tol", sizeof(tol), &tol},
                              {"gx0", sizeof(gx0), &gx0},
                              {"gy0", sizeof(gy0), &gy0},
                              {"gx_end", sizeof(gx_end), &gx_end},
                              {"gy_end", sizeof(gy_end), &gy_end},
                              {"x_end", sizeof(mx_end), &mx_end},
                              {"y_end", sizeof(my_end), &my_end},
                              {"iters", sizeof(iters), &iters},
                              {"depth_out", sizeof(cl_mem), &s->depth[nxt]},
                              {"density_out", sizeof(cl_mem), &s->density[nxt]},
                              {"movable", sizeof(cl_mem), &s->movable},
                              {"lmem", lbytes, NULL}};
  const size_t local[2] = {bw, bh};
  gr_status st = gr_snow_talus_args(s, s->relax_block);
  if (st == GR_OK)
    st = gr_snow_args(s, s->relax_block, args, sizeof(args) / sizeof(args[0]));
  if (st == GR_OK && mx_end > mx0 && my_end > my0) /* a piece's cut may be empty */
    st = gr_enqueue_2d(s->ctx, s->relax_block, (size_t)mx0, (size_t)my0, (size_t)(mx_end - mx0),
                       (size_t)(my_end - my0), local);
  if (st == GR_OK)
    s->cur = nxt;
  return st;
}

/* The talus' tail in one launch of snow_relax_group from the givers'
 * window [*x0, *x1] x [*y0, *y1] (inclusive), at most cap iterations: adds
 * the iterations run to *ran, sets *done when nothing could move any more,
 * and leaves the window of the next iteration in *x0.. (waits). The count
 * is the one the checked launches would give: they check every align
 * iterations, so a relaxation that ends at iteration e counts e rounded up
 * to align, and one that would not end before the cap counts the cap. */
static gr_status gr_snow_relax_group(gr_snow_deformation *s, int *x0, int *y0, int *x1, int *y1,
                                     cl_int cap, cl_int align, float tol, int *ran, int *done) {
  cl_int nxt = 1 - s->cur;
  cl_int max_area = s->group_area;
  cl_int w[4] = {*x0, *y0, *x1, *y1}, first = *ran, left = cap - first;
  const gr_snow_arg args[] = {{"depth", sizeof(cl_mem), &s->depth[s->cur]},
                              {"density", sizeof(cl_mem), &s->density[s->cur]},
                              {"depth_tmp", sizeof(cl_mem), &s->depth[nxt]},
                              {"density_tmp", sizeof(cl_mem), &s->density[nxt]},
                              {"tol", sizeof(tol), &tol},
                              {"x0", sizeof(cl_int), &w[0]},
                              {"y0", sizeof(cl_int), &w[1]},
                              {"x1", sizeof(cl_int), &w[2]},
                              {"y1", sizeof(cl_int), &w[3]},
                              {"cap", sizeof(left), &left},
                              {"max_area", sizeof(max_area), &max_area},
                              {"first", sizeof(first), &first},
                              {"align", sizeof(align), &align},
                              {"rate", sizeof(cl_mem), &s->rate},
                              {"rate_in", sizeof(cl_mem), &s->rate_in},
                              {"result", sizeof(cl_mem), &s->group_result}};
  const size_t local[2] = {s->group_size, 1};
  cl_int res[6];
  gr_status st = gr_snow_talus_args(s, s->relax_group);
  if (st == GR_OK)
    st = gr_snow_args(s, s->relax_group, args, sizeof(args) / sizeof(args[0]));
  if (st == GR_OK)
    st = gr_enqueue_2d(s->ctx, s->relax_group, 0, 0, s->group_size, 1, local);
  if (st == GR_OK)
    st = gr_buffer_read(s->ctx, s->group_result, 0, sizeof(res), res);
  if (st == GR_OK) {
    int end = first + res[0], counted = (end + align - 1) / align * align;
    *done = res[1] != 0 && counted < cap;
    *ran = *done ? counted : (res[1] != 0 ? cap : end);
    *x0 = res[2], *y0 = res[3], *x1 = res[4], *y1 = res[5];
  }
  return st;
}

/* The reach of a step's talus in points (8-neighbour steps): with a
 * SlumpSpeed c, ceil(c dt / d) for the finer spacing d (at least one); 0
 * (no bound) for c = 0 or where it spans the whole domain anyway. A talus
 * iteration moves snow one point, so without a bound the snow would slide
 * as far as the iterations reach (about 60 m/s at 4096 points over 20 m
 * with 200 a step): the slump's speed, and the shape of a trail, would
 * change with the resolution. The same on every piece: dt and the spacing
 * are the domain's. */
static int gr_snow_reach_hops(const gr_snow_deformation *s, double dt) {
  const gr_snow_deformation_params *p = &s->params;
  if (!(p->slump_speed > 0.0))
    return 0;
  double d = s->grid.dx < s->grid.dy ? s->grid.dx : s->grid.dy;
  double n = ceil(p->slump_speed * dt / d - 1e-9), all = s->gnx > s->gny ? s->gnx : s->gny;
  return n >= all ? 0 : (n < 1.0 ? 1 : (int)n);
}

/* One pass of the reach's max filter (snow_reach_rows, snow_reach_cols):
 * the points within h of a point of src above thr in the box src_box
 * (local, inclusive, cut to the arrays; empty: none) into `weight`, on
 * out_box. */
static gr_status gr_snow_reach_dilate(gr_snow_deformation *s, cl_mem src, float thr,
                                      const int src_box[4], const int out_box[4], cl_int h) {
  cl_int nx = s->grid.nx, ny = s->grid.ny, sx0 = src_box[0], sy0 = src_box[1], sx1 = src_box[2],
         sy1 = src_box[3];
  cl_int x_end = out_box[2] + 1, y_end = sy1 + 1;
  const gr_snow_arg rows[] = {{"src", sizeof(cl_mem), &src},
                              {"thr", sizeof(thr), &thr},
                              {"sx0", sizeof(sx0), &sx0},
                              {"sy0", sizeof(sy0), &sy0},
                              {"sx1", sizeof(sx1), &sx1},
                              {"sy1", sizeof(sy1), &sy1},
                              {"h", sizeof(h), &h},
                              {"nx", sizeof(nx), &nx},
                              {"ny", sizeof(ny), &ny},
                              {"x_end", sizeof(x_end), &x_end},
                              {"y_end", sizeof(y_end), &y_end},
                              {"out", sizeof(cl_mem), &s->scratch}};
  gr_status st = gr_snow_args(s, s->reach_rows, rows, sizeof(rows) / sizeof(rows[0]));
  if (st == GR_OK && sy0 <= sy1) /* no rows: the columns read none */
    st = gr_enqueue_2d(s->ctx, s->reach_rows, (size_t)out_box[0], (size_t)sy0,
                       (size_t)(out_box[2] - out_box[0] + 1), (size_t)(sy1 - sy0 + 1), NULL);
  cl_int y_end2 = out_box[3] + 1;
  const gr_snow_arg cols[] = {{"src", sizeof(cl_mem), &s->scratch},
                              {"sy0", sizeof(sy0), &sy0},
                              {"sy1", sizeof(sy1), &sy1},
                              {"h", sizeof(h), &h},
                              {"nx", sizeof(nx), &nx},
                              {"ny", sizeof(ny), &ny},
                              {"x_end", sizeof(x_end), &x_end},
                              {"y_end", sizeof(y_end2), &y_end2},
                              {"out", sizeof(cl_mem), &s->weight}};
  if (st == GR_OK)
    st = gr_snow_args(s, s->reach_cols, cols, sizeof(cols) / sizeof(cols[0]));
  if (st == GR_OK)
    st = gr_enqueue_2d(s->ctx, s->reach_cols, (size_t)out_box[0], (size_t)out_box[1],
                       (size_t)(out_box[2] - out_box[0] + 1), (size_t)(out_box[3] - out_box[1] + 1),
                       NULL);
  return st;
}

/* A box (x0 y0 x1 y1) cut to the local arrays; 0 when nothing is left. */
static int gr_snow_clip_box(const gr_snow_deformation *s, const int in[4], int out[4]) {
  out[0] = in[0] > 0 ? in[0] : 0;
  out[1] = in[1] > 0 ? in[1] : 0;
  out[2] = in[2] < s->grid.nx - 1 ? in[2] : s->grid.nx - 1;
  out[3] = in[3] < s->grid.ny - 1 ? in[3] : s->grid.ny - 1;
  return out[0] <= out[2] && out[1] <= out[3];
}

/* The reach of this step's talus (SlumpSpeed; header): the points within
 * hops of a seed, a point that can move more than the tolerance at the
 * step's start (a mover, found on the window [*x0, *x1] x [*y0, *y1],
 * where every point that can move lies) or one on a slope
 * (snow_reach_seed), as far as the talus can reach in the step (the cap's
 * iterations from the movers). Only those points give or receive (their
 * ceilings, snow_reach_ceiling, are -inf elsewhere), and within them the
 * snow settles: a slide spreads over flat snow at SlumpSpeed, and what an
 * object feeds becomes a heap at MaxSlope on every grid (a talus cut to a
 * number of iterations carries a flux that shrinks with the spacing, and
 * piled a wall). The mask is a max filter of the seeds in passes of at
 * most the ring's width less one (GR_SNOW_DEFORMATION_GHOST - 1 on a whole
 * grid), each exchanged on a piece (a seed reads its neighbours: a ring of
 * 8 gives 7 points), so a piece's mask is the whole grid's (a square max
 * filter of h then h' points is one of h + h'). Leaves the movers' box in
 * *x0.. (the givers' window) and the reach's box in s->reach_box and
 * s->reach_all; *any = 0 when nothing can move. */
static gr_status gr_snow_relax_reach(gr_snow_deformation *s, int hops, float tol, int *x0, int *y0,
                                     int *x1, int *y1, int *any) {
  cl_int gx0 = *x0, gy0 = *y0, gx_end = *x1 + 1, gy_end = *y1 + 1, t = 0;
  s->reach_on = 0;
  *any = 0;
  /* The movers: snow_relax_rate's movable amounts at t = 0, everyone a giver. */
  gr_status st = gr_snow_relax_rate(s, tol, gx0, gy0, gx_end, gy_end, t, gx0, gy0, gx_end, gy_end);
  double m[GR_SNOW_CHECK_MAXES];
  int empty = 0;
  if (st == GR_OK)
    st = gr_snow_relax_check_start(s, &s->red_check[0], *x0, *y0, *x1, *y1, &empty);
  if (st == GR_OK)
    st = gr_snow_relax_check_finish(s, &s->red_check[0], empty, m);
  if (st != GR_OK || m[0] <= tol)
    return st;
  *any = 1;
  /* The boxes in the local arrays' indices, not cut: the same box of the
   * domain on every piece. The seeds: wherever this step's talus can
   * reach, snow moving a point an iteration, so within the cap of the
   * movers. */
  int movers[4] = {(int)-m[1], (int)-m[3], (int)m[2], (int)m[4]}, src[4], out[4], cut[4],
      cut_out[4];
  int far = s->params.max_relax_iterations;
  src[0] = movers[0] - far, src[1] = movers[1] - far, src[2] = movers[2] + far,
  src[3] = movers[3] + far;
  *x0 = movers[0], *y0 = movers[1], *x1 = movers[2], *y1 = movers[3];
  float t3[3];
  gr_snow_thresholds(s, t3);
  if (gr_snow_clip_box(s, src, cut)) {
    cl_int nx = s->grid.nx, ny = s->grid.ny, x_end = cut[2] + 1, y_end = cut[3] + 1;
    const gr_snow_arg args[] = {{"ground", sizeof(cl_mem), &s->ground},
                                {"depth", sizeof(cl_mem), &s->depth[s->cur]},
                                {"movable", sizeof(cl_mem), &s->movable},
                                {"tol", sizeof(tol), &tol},
                                {"ax0", sizeof(cl_int), &movers[0]},
                                {"ay0", sizeof(cl_int), &movers[1]},
                                {"ax1", sizeof(cl_int), &movers[2]},
                                {"ay1", sizeof(cl_int), &movers[3]},
                                {"tx", sizeof(float), &t3[0]},
                                {"ty", sizeof(float), &t3[1]},
                                {"td", sizeof(float), &t3[2]},
                                {"nx", sizeof(nx), &nx},
                                {"ny", sizeof(ny), &ny},
                                {"x_end", sizeof(x_end), &x_end},
                                {"y_end", sizeof(y_end), &y_end},
                                {"reach", sizeof(cl_mem), &s->weight}};
    st = gr_snow_args(s, s->reach_seed, args, sizeof(args) / sizeof(args[0]));
    if (st == GR_OK)
      st = gr_enqueue_2d(s->ctx, s->reach_seed, (size_t)cut[0], (size_t)cut[1],
                         (size_t)(cut[2] - cut[0] + 1), (size_t)(cut[3] - cut[1] + 1), NULL);
  }
  /* The max filter, hops points, in passes a piece's ring can feed. */
  const int pass = (gr_snow_has_ring(s) ? gr_snow_ring_width(s) : GR_SNOW_DEFORMATION_GHOST) - 1;
  for (int left = hops; st == GR_OK && left > 0;) {
    int h = left < pass ? left : pass;
    out[0] = src[0] - h, out[1] = src[1] - h, out[2] = src[2] + h, out[3] = src[3] + h;
    if (!gr_snow_clip_box(s, src, cut)) /* no seeds here */
      cut[0] = cut[1] = 0, cut[2] = cut[3] = -1;
    if (gr_snow_clip_box(s, out, cut_out))
      st = gr_snow_reach_dilate(s, s->weight, 0.5f, cut, cut_out, h);
    if (st == GR_OK) {
      s->halo_reach = 1; /* pieces: the ring's mask from its own piece */
      st = gr_snow_piece_sync(s);
      s->halo_reach = 0;
    }
    memcpy(src, out, sizeof(src));
    left -= h;
  }
  memcpy(s->reach_all, src, sizeof(src));
  if (st == GR_OK && !gr_snow_clip_box(s, src, s->reach_box))
    s->reach_box[0] = s->reach_box[1] = 0, s->reach_box[2] = s->reach_box[3] = -1;
  /* The ceilings, as far as a talus launch on the reach reads: a blocked
   * launch's moves reach GR_SNOW_BLOCK_ITERATIONS beyond its givers and read
   * twice that farther. */
  const int pad = 3 * GR_SNOW_BLOCK_ITERATIONS;
  int wide[4] = {src[0] - pad, src[1] - pad, src[2] + pad, src[3] + pad};
  if (st == GR_OK && gr_snow_clip_box(s, wide, cut)) {
    cl_int nx = s->grid.nx, ny = s->grid.ny, x_end = cut[2] + 1, y_end = cut[3] + 1;
    const gr_snow_arg args[] = {{"under_min", sizeof(cl_mem), &s->under_min},
                                {"reach", sizeof(cl_mem), &s->weight},
                                {"bx0", sizeof(cl_int), &s->reach_box[0]},
                                {"by0", sizeof(cl_int), &s->reach_box[1]},
                                {"bx1", sizeof(cl_int), &s->reach_box[2]},
                                {"by1", sizeof(cl_int), &s->reach_box[3]},
                                {"nx", sizeof(nx), &nx},
                                {"ny", sizeof(ny), &ny},
                                {"x_end", sizeof(x_end), &x_end},
                                {"y_end", sizeof(y_end), &y_end},
                                {"ceiling", sizeof(cl_mem), &s->scratch}};
    st = gr_snow_args(s, s->reach_ceiling, args, sizeof(args) / sizeof(args[0]));
    if (st == GR_OK)
      st = gr_enqueue_2d(s->ctx, s->reach_ceiling, (size_t)cut[0], (size_t)cut[1],
                         (size_t)(cut[2] - cut[0] + 1), (size_t)(cut[3] - cut[1] + 1), NULL);
  }
  if (st == GR_OK)
    s->reach_on = 1;
  return st;
}

/* The box of the points the step touched, [*x0, *x1] x [*y0, *y1]
 * (inclusive, not yet cut to the arrays; empty when nothing did): every
 * point after a full change, else the objects' boxes grown by two and the
 * points the last step left unrelaxed. */
static void gr_snow_relax_box(const gr_snow_deformation *s, int *x0, int *y0, int *x1, int *y1) {
  int nx = s->grid.nx, ny = s->grid.ny;
  *x0 = nx, *x1 = -1, *y0 = ny, *y1 = -1;
  if (s->relax_full) {
    *x0 = *y0 = 0;
    *x1 = nx - 1;
    *y1 = ny - 1;
    return;
  }
  for (int o = 0; o < s->nobjects; ++o) {
    const gr_snow_object *ob = &s->objects[o];
    if (ob->bi0 > ob->bi1 || ob->bj0 > ob->bj1)
      continue;
    *x0 = *x0 < ob->bi0 - 2 ? *x0 : ob->bi0 - 2;
    *x1 = *x1 > ob->bi1 + 2 ? *x1 : ob->bi1 + 2;
    *y0 = *y0 < ob->bj0 - 2 ? *y0 : ob->bj0 - 2;
    *y1 = *y1 > ob->bj1 + 2 ? *y1 : ob->bj1 + 2;
  }
  if (s->rest[0] <= s->rest[2] && s->rest[1] <= s->rest[3]) {
    *x0 = *x0 < s->rest[0] ? *x0 : s->rest[0];
    *y0 = *y0 < s->rest[1] ? *y0 : s->rest[1];
    *x1 = *x1 > s->rest[2] ? *x1 : s->rest[2];
    *y1 = *y1 > s->rest[3] ? *y1 : s->rest[3];
  }
}

/* One relaxation's iterations in flight. Launches in flight: on GPUs,
 * where a read-back between launches costs more than the launch, only
 * every GR_SNOW_CHECK_EVERY-th launch is checked and a check is read back
 * GR_SNOW_CHECK_LAG checks later, so the window of a launch is the last box
 * read grown by every iteration launched since. A launch after the one
 * whose check says nothing could move changes nothing (no point gives), so
 * the lag changes what is computed, never the result or the iteration
 * count. */
typedef struct gr_snow_relax_run {
  int nx, ny;
  float tol;
  int x0, y0, x1, y1;     /* the givers' box */
  int lx0, ly0, lx1, ly1; /* the last launch's window */
  int lag, cap, every;
  /* per check in flight: the iterations launched before its launch, and
   * whether it is empty (a piece with none of the window) */
  int before[GR_SNOW_CHECK_LAG + 1], empty[GR_SNOW_CHECK_LAG + 1];
  int launched, started, read, it_launched, done;
  int it;       /* the iterations the relaxation counts */
  int stale;    /* a piece: the ring's points gone stale since its last exchange */
  int cx0, cx1; /* a piece: the columns its launches wrote since then (cx0 > cx1: none) */
} gr_snow_relax_run;

/* Cuts the givers' box to the local arrays. */
static void gr_snow_relax_cut(gr_snow_relax_run *r) {
  r->x0 = r->x0 > 0 ? r->x0 : 0;
  r->y0 = r->y0 > 0 ? r->y0 : 0;
  r->x1 = r->x1 < r->nx - 1 ? r->x1 : r->nx - 1;
  r->y1 = r->y1 < r->ny - 1 ? r->y1 : r->ny - 1;
}

/* The tail: whether the givers' window grown by two is small enough for
 * one work-group (not on a piece with a ring: it would need an exchange
 * every iteration). */
static int gr_snow_relax_in_tail(const gr_snow_deformation *s, const gr_snow_relax_run *r) {
  int nx = r->nx, ny = r->ny;
  int gx = (r->x1 + 2 < nx - 1 ? r->x1 + 2 : nx - 1) - (r->x0 - 2 > 0 ? r->x0 - 2 : 0) + 1,
      gy = (r->y1 + 2 < ny - 1 ? r->y1 + 2 : ny - 1) - (r->y0 - 2 > 0 ? r->y0 - 2 : 0) + 1;
  return s->group && !gr_snow_has_ring(s) && r->it_launched < r->cap &&
         (double)gx * gy <= (double)s->group_area;
}

/* The tail in one work-group, once every check in flight is read. */
static gr_status gr_snow_relax_tail(gr_snow_deformation *s, gr_snow_relax_run *r) {
  gr_snow_relax_cut(r);
  gr_status st =
      gr_snow_relax_group(s, &r->x0, &r->y0, &r->x1, &r->y1, r->cap,
                          GR_SNOW_BLOCK_ITERATIONS * r->every, r->tol, &r->it_launched, &r->done);
  if (st == GR_OK)
    r->it = r->it_launched;
  return st;
}

/* A piece: the exchange the talus owes its ring, now when `need` more
 * stale points would not fit in it (or at the end: need = 0, any stale
 * point). An iteration makes two more of the ring's points stale, from its
 * outer edge in (a move reads points two away), so a ring of
 * GR_SNOW_DEFORMATION_GHOST takes one launch of GR_SNOW_BLOCK_ITERATIONS
 * iterations between exchanges and a ring m times as wide m launches: the
 * own points stay the whole grid's, and the exchanges drop m-fold. The
 * same counts on every piece: the same exchanges. */
static gr_status gr_snow_relax_ring(gr_snow_deformation *s, gr_snow_relax_run *r, int need) {
  if (!gr_snow_has_ring(s) || r->stale == 0 ||
      (need > 0 && r->stale + need <= gr_snow_ring_width(s)))
    return GR_OK;
  /* Only the columns the launches wrote since the last exchange changed,
   * on either side of a cut (the windows are the domain's, the same on
   * every piece): the exchange copies those (at 16384^2 the bench's talus
   * writes about an eighth of the columns). */
  s->halo_cols_on = r->cx0 <= r->cx1;
  s->halo_cols[0] = r->cx0, s->halo_cols[1] = r->cx1;
  r->stale = 0;
  r->cx0 = r->nx, r->cx1 = -1;
  gr_status st = gr_snow_piece_sync(s);
  s->halo_cols_on = 0;
  return st;
}

/* One launch of up to GR_SNOW_BLOCK_ITERATIONS iterations on the givers'
 * box (first, on a piece, the exchange when the ring has no room left for
 * them), and its check when one is due. */
static gr_status gr_snow_relax_launch(gr_snow_deformation *s, gr_snow_relax_run *r) {
  int nx = r->nx, ny = r->ny;
  gr_status st = GR_OK;
  int left = r->cap - r->it_launched;
  cl_int iters = left < GR_SNOW_BLOCK_ITERATIONS ? left : GR_SNOW_BLOCK_ITERATIONS;
  gr_snow_relax_cut(r);
  int x0 = r->x0, y0 = r->y0, x1 = r->x1, y1 = r->y1;
  cl_int gx0 = x0, gy0 = y0, gx_end = x1 + 1, gy_end = y1 + 1;
  /* The launch's window: R grown by the iterations. */
  int mx0 = x0 - iters > 0 ? x0 - iters : 0, my0 = y0 - iters > 0 ? y0 - iters : 0;
  cl_int mx_end = x1 + iters + 1 < nx ? x1 + iters + 1 : nx,
         my_end = y1 + iters + 1 < ny ? y1 + iters + 1 : ny;
  /* The buffer the first write goes to lags the state on the last
   * window; it must not where that write does not reach: all of the
   * launch's window in one blocked launch, R grown by one in the first
   * of the one-launch iterations (each later one covers its
   * predecessor's). */
  int grow = s->blocked ? iters : 1;
  int fx0 = x0 - grow > 0 ? x0 - grow : 0, fy0 = y0 - grow > 0 ? y0 - grow : 0;
  int fx1 = x1 + grow < nx - 1 ? x1 + grow : nx - 1, fy1 = y1 + grow < ny - 1 ? y1 + grow : ny - 1;
  if (r->lx0 < fx0 || r->ly0 < fy0 || r->lx1 > fx1 || r->ly1 > fy1)
    st = gr_snow_sync_rect(s, r->lx0, r->ly0, r->lx1, r->ly1);
  if (st == GR_OK)
    st = gr_snow_relax_ring(s, r, 2 * iters); /* pieces: room in the ring for the launch */
  if (st == GR_OK && s->blocked)
    st =
        gr_snow_relax_blocked(s, gx0, gy0, gx_end, gy_end, mx0, my0, mx_end, my_end, iters, r->tol);
  for (cl_int t = 0; st == GR_OK && !s->blocked && t < iters; ++t)
    st = gr_snow_relax_once(s, gx0, gy0, gx_end, gy_end, t, r->tol);
  if (st == GR_OK) {
    r->stale += 2 * iters; /* pieces: the ring the launch used up, its columns */
    r->cx0 = mx0 < r->cx0 ? mx0 : r->cx0;
    r->cx1 = mx_end - 1 > r->cx1 ? mx_end - 1 : r->cx1;
  }
  if (st == GR_OK)
    r->lx0 = mx0, r->ly0 = my0, r->lx1 = mx_end - 1, r->ly1 = my_end - 1;
  int slot = r->started % (r->lag + 1);
  if (st == GR_OK && r->launched % r->every == 0) {
    st = gr_snow_relax_check_start(s, &s->red_check[slot], x0, y0, x1, y1, &r->empty[slot]);
    r->before[slot] = r->it_launched;
    r->started += st == GR_OK;
  }
  if (st == GR_OK) {
    r->it_launched += iters;
    ++r->launched;
    /* until a box is read */
    r->x0 -= iters, r->x1 += iters, r->y0 -= iters, r->y1 += iters;
  }
  return st;
}

/* Reads the oldest check in flight: done when nothing could move at its
 * launch, else the givers' box it found, grown by the iterations since. */
static gr_status gr_snow_relax_read(gr_snow_deformation *s, gr_snow_relax_run *r) {
  double m[GR_SNOW_CHECK_MAXES];
  int slot = r->read % (r->lag + 1);
  gr_status st = gr_snow_relax_check_finish(s, &s->red_check[slot], r->empty[slot], m);
  ++r->read;
  if (st == GR_OK && m[0] <= r->tol) {
    /* nothing could move: that launch and those after changed nothing */
    r->it = r->before[slot];
    r->done = 1;
  } else if (st == GR_OK) {
    r->it = r->it_launched;
    int g = r->it_launched - r->before[slot]; /* iterations since that check's launch began */
    r->x0 = (int)-m[1] - g, r->x1 = (int)m[2] + g;
    r->y0 = (int)-m[3] - g, r->y1 = (int)m[4] + g;
  }
  return st;
}

/* The iterations until nothing can move or the cap, then the wait for the
 * checks still in flight (after the end, or an error). */
static gr_status gr_snow_relax_iterate(gr_snow_deformation *s, gr_snow_relax_run *r) {
  gr_status st = GR_OK;
  while (st == GR_OK && !r->done) {
    if (s->reach_on) { /* no giver beyond the reach (and no read beyond its ceilings) */
      const int *b = s->reach_box;
      r->x0 = r->x0 > b[0] ? r->x0 : b[0], r->y0 = r->y0 > b[1] ? r->y0 : b[1];
      r->x1 = r->x1 < b[2] ? r->x1 : b[2], r->y1 = r->y1 < b[3] ? r->y1 : b[3];
    }
    int tail = gr_snow_relax_in_tail(s, r);
    if (tail && r->read == r->started)
      st = gr_snow_relax_tail(s, r);
    else if (!tail && r->it_launched < r->cap && r->started - r->read <= r->lag)
      st = gr_snow_relax_launch(s, r);
    else if (r->read == r->started)
      break; /* the cap, every check read */
    else
      st = gr_snow_relax_read(s, r);
  }
  for (; r->read < r->started; ++r->read)
    if (!r->empty[r->read % (r->lag + 1)])
      gr_reduction_finish(s->ctx, &s->red_check[r->read % (r->lag + 1)], NULL, NULL);
  return st;
}

/* The points the next step's talus starts from (s->rest). Stopped by the
 * cap: the last box read, grown by the iterations since, holds every point
 * that may still move. Under a reach: snow moved a point an iteration from
 * the points that could move (movers), within the reach, so only there,
 * and next to it, may a point have an excess now (the edge of the reach,
 * where the front slides on next step). Not cut to the local arrays: the
 * domain's box, so that every piece goes on with the next step's talus
 * alike. */
static void gr_snow_relax_rest(gr_snow_deformation *s, const gr_snow_relax_run *r, int ok,
                               const int movers[4]) {
  int nx = r->nx, ny = r->ny;
  s->rest[0] = s->rest[1] = 0;
  s->rest[2] = s->rest[3] = -1;
  if (ok && !r->done) {
    s->rest[0] = r->x0 > 0 ? r->x0 : 0, s->rest[1] = r->y0 > 0 ? r->y0 : 0;
    s->rest[2] = r->x1 < nx - 1 ? r->x1 : nx - 1, s->rest[3] = r->y1 < ny - 1 ? r->y1 : ny - 1;
  }
  if (ok && s->reach_on) {
    const int *b = s->reach_all, g = r->it_launched + 1;
    int e[4] = {movers[0] - g, movers[1] - g, movers[2] + g, movers[3] + g};
    e[0] = e[0] > b[0] - 1 ? e[0] : b[0] - 1, e[1] = e[1] > b[1] - 1 ? e[1] : b[1] - 1;
    e[2] = e[2] < b[2] + 1 ? e[2] : b[2] + 1, e[3] = e[3] < b[3] + 1 ? e[3] : b[3] + 1;
    if (s->rest[0] > s->rest[2] || s->rest[1] > s->rest[3])
      memcpy(s->rest, e, sizeof(e));
    s->rest[0] = s->rest[0] < e[0] ? s->rest[0] : e[0];
    s->rest[1] = s->rest[1] < e[1] ? s->rest[1] : e[1];
    s->rest[2] = s->rest[2] > e[2] ? s->rest[2] : e[2];
    s->rest[3] = s->rest[3] > e[3] ? s->rest[3] : e[3];
  }
}

/* Talus relaxation on a window that follows the snow that can move.
 *
 * The window: the givers R (at first the objects' boxes grown by the
 * contour ring, or the whole grid after the snow or the ground was set:
 * relax_full). Snow leaves only points of R, so after an iteration only
 * points within one of R changed, and only those and their neighbours can
 * have gained an excess: R grows by one per iteration. A launch of
 * snow_relax_block runs GR_SNOW_BLOCK_ITERATIONS iterations and writes the
 * moves' window, R grown by that many. Then the check reads the first
 * iteration's largest movable amount (the end when it is at most
 * RelaxTolerance: then nothing moved in the launch) and the box of the
 * points that could move more; only those gave (a point gives only while
 * it can move more than RelaxTolerance), so R shrinks to that box grown by
 * the iterations run. The window decides what is computed, never the
 * result: a run from the whole grid ends bit for bit where a run from the
 * objects' boxes does when the rest was relaxed.
 *
 * The pair of buffers: a launch writes the other buffer on its window only,
 * so outside it the other buffer must equal the state. That holds at the
 * start of a step but where the objects pressed (synchronised first), and
 * is restored when a window does not cover the last one and at the end (the
 * last window copied across). */
gr_status gr_snow_relax(gr_snow_deformation *s, double dt) {
  int nx = s->grid.nx, ny = s->grid.ny;
  gr_status st = GR_OK;
  gr_snow_relax_run r;
  memset(&r, 0, sizeof(r));
  r.nx = nx, r.ny = ny;
  r.tol = gr_snow_tolerance(s);
  s->relax_iterations = 0;
  gr_snow_relax_box(s, &r.x0, &r.y0, &r.x1, &r.y1);
  if (s->params.max_relax_iterations == 0) {
    s->sync_full |= r.x0 <= r.x1;       /* the objects changed the state alone */
    if (r.x0 <= r.x1 && r.y0 <= r.y1) { /* all of it may still move */
      s->rest[0] = r.x0 > 0 ? r.x0 : 0, s->rest[1] = r.y0 > 0 ? r.y0 : 0;
      s->rest[2] = r.x1 < nx - 1 ? r.x1 : nx - 1, s->rest[3] = r.y1 < ny - 1 ? r.y1 : ny - 1;
    }
    return GR_OK;
  }
  if (r.x0 > r.x1 || r.y0 > r.y1)
    return GR_OK; /* nothing touched the snow: it stays as relaxed as it was */
  gr_snow_relax_cut(&r);
  if (s->sync_full || s->relax_full)
    st = gr_snow_sync_rect(s, 0, 0, nx - 1, ny - 1);
  else
    st = gr_snow_sync_rect(s, r.x0, r.y0, r.x1, r.y1);
  s->relax_full = s->sync_full = 0;
  /* SlumpSpeed: the talus runs on the step's reach only (the givers'
   * window from the movers on). */
  const int hops = gr_snow_reach_hops(s, dt);
  int movers[4] = {0, 0, -1, -1}; /* under a reach: the box of the points that could move */
  s->reach_on = 0;
  if (st == GR_OK && hops > 0) {
    int any = 0;
    st = gr_snow_relax_reach(s, hops, r.tol, &r.x0, &r.y0, &r.x1, &r.y1, &any);
    movers[0] = r.x0, movers[1] = r.y0, movers[2] = r.x1, movers[3] = r.y1;
    if (st != GR_OK || !any) {
      s->reach_on = 0;
      s->rest[0] = s->rest[1] = 0;
      s->rest[2] = s->rest[3] = -1;
      return st; /* nothing can move: the snow is as relaxed as it was */
    }
  }
  r.lx0 = 0, r.ly0 = 0, r.lx1 = -1, r.ly1 = -1; /* no launch yet */
  r.cx0 = nx, r.cx1 = -1;
  r.lag = s->blocked ? GR_SNOW_CHECK_LAG : 0, r.cap = s->params.max_relax_iterations;
  r.every = s->blocked ? GR_SNOW_CHECK_EVERY : 1;
  if (st == GR_OK)
    st = gr_snow_relax_iterate(s, &r);
  if (st == GR_OK)
    st = gr_snow_relax_ring(s, &r, 0); /* pieces: the ring fresh for the next stage */
  gr_snow_relax_rest(s, &r, st == GR_OK, movers);
  s->reach_on = 0;
  /* Both buffers equal again: the last window from the state. */
  if (st == GR_OK)
    st = gr_snow_sync_rect(s, r.lx0, r.ly0, r.lx1, r.ly1);
  s->relax_iterations = r.it;
  return st;
}
