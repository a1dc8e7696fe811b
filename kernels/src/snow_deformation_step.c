/* Snow deformation core, host side: the step (snow_deformation_internal.h):
 * each object's press, contour and deposit, the step that runs them and the
 * talus (snow_deformation_talus.c), and what it gives back (fields, the
 * ledger, the objects' forces). */
#include "snow_deformation_internal.h"

/* Sets the arguments in `args` of kernel k by name (gr_snow_arg). */
gr_status gr_snow_args(gr_snow_deformation *s, cl_kernel k, const gr_snow_arg *args, size_t n) {
  gr_status st = GR_OK;
  for (size_t q = 0; st == GR_OK && q < n; ++q)
    st = gr_kernel_arg(s->ctx, k, args[q].name, args[q].size, args[q].value);
  return st;
}

/* The press parameters both press kernels take. */
static gr_status gr_snow_press_args(gr_snow_deformation *s, cl_kernel k) {
  float rho_min = (float)s->params.min_density, rho_max = (float)s->params.max_density;
  float w_const = s->params.compression_model == GR_SNOW_COMPRESSION_CONSTANT
                      ? (float)(1.0 - GR_SNOW_DEFORMATION_CONSTANT_COMPRESSION)
                      : -1.0f;
  float gap = (float)GR_SNOW_DEFORMATION_CONTACT_GAP;
  gr_status st = GR_SNOW_ARG(s, k, "ground", s->ground);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "depth", s->depth[s->cur]);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "density", s->density[s->cur]);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "under", s->under);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "overlap", s->overlap);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "weight", s->weight);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "rho_min", rho_min);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "rho_max", rho_max);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "w_const", w_const);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "gap", gap);
  return st;
}

/* Grows the box of the points this step's objects wrote (their overlap
 * sum, contact and lowest underside), which the next step clears. */
static void gr_snow_dirty(gr_snow_deformation *s, int x0, int y0, int x1, int y1) {
  int *d = s->dirty;
  if (d[0] > d[2]) {
    d[0] = x0, d[1] = y0, d[2] = x1, d[3] = y1;
    return;
  }
  d[0] = d[0] < x0 ? d[0] : x0;
  d[1] = d[1] < y0 ? d[1] : y0;
  d[2] = d[2] > x1 ? d[2] : x1;
  d[3] = d[3] > y1 ? d[3] : y1;
}

/* The start of a step: the overlap sum and contact 0 and the lowest
 * underside +inf where the last step's objects wrote them (everywhere
 * after the state was set). */
static gr_status gr_snow_reset(gr_snow_deformation *s) {
  int nx = s->grid.nx, ny = s->grid.ny, *d = s->dirty;
  if (s->reset_full) {
    d[0] = d[1] = 0;
    d[2] = nx - 1;
    d[3] = ny - 1;
    s->reset_full = 0;
  }
  if (d[0] > d[2] || d[1] > d[3])
    return GR_OK;
  cl_kernel k = s->reset;
  cl_int x_end = d[2] + 1, y_end = d[3] + 1;
  gr_status st = GR_SNOW_ARG(s, k, "nx", nx);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "ny", ny);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "x_end", x_end);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "y_end", y_end);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "overlap_sum", s->overlap_sum);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "contact", s->contact);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, k, "under_min", s->under_min);
  if (st == GR_OK)
    st = gr_enqueue_2d(s->ctx, k, (size_t)d[0], (size_t)d[1], (size_t)(d[2] - d[0] + 1),
                       (size_t)(d[3] - d[1] + 1), NULL);
  d[0] = d[1] = 0;
  d[2] = d[3] = -1; /* clean */
  return st;
}

/* The contour window of an object's step: [x0, x0 + w) x [y0, y0 + h) of
 * the local arrays (on: not empty), and the piece's own points of it for
 * the sums: from (rx0, ry0), rw wide, rn in all. */
typedef struct gr_snow_cwin {
  size_t x0, y0, w, h;
  cl_int x_end, y_end, rx0, ry0, rw, rn;
  int on;
} gr_snow_cwin;

/* Rings a deposit goes out at most (gr_snow_deposit); what is left after
 * them waits for the next press, as the rounding's rest does. */
#define GR_SNOW_DEPOSIT_RINGS 64

/* The contour weights of ring `ring` (snow_contour) on the window. */
static gr_status gr_snow_contour_ring(gr_snow_deformation *s, const gr_snow_cwin *win, cl_int ring,
                                      float vx, float vy, float rest) {
  cl_int nx = s->grid.nx, ny = s->grid.ny;
  float gap = (float)GR_SNOW_DEFORMATION_CONTACT_GAP, clearance = 2.0f * gap;
  const gr_snow_arg args[] = {{"ground", sizeof(cl_mem), &s->ground},
                              {"depth", sizeof(cl_mem), &s->depth[s->cur]},
                              {"under", sizeof(cl_mem), &s->under},
                              {"under_min", sizeof(cl_mem), &s->under_min},
                              {"overlap", sizeof(cl_mem), &s->overlap},
                              {"nx", sizeof(nx), &nx},
                              {"ny", sizeof(ny), &ny},
                              {"vx", sizeof(vx), &vx},
                              {"vy", sizeof(vy), &vy},
                              {"rest", sizeof(rest), &rest},
                              {"gap", sizeof(gap), &gap},
                              {"clearance", sizeof(clearance), &clearance},
                              {"ring", sizeof(ring), &ring},
                              {"x_end", sizeof(cl_int), &win->x_end},
                              {"y_end", sizeof(cl_int), &win->y_end},
                              {"weight", sizeof(cl_mem), &s->weight}};
  gr_status st = gr_snow_args(s, s->contour, args, sizeof(args) / sizeof(args[0]));
  if (st == GR_OK)
    st = gr_enqueue_2d(s->ctx, s->contour, win->x0, win->y0, win->w, win->h, NULL);
  return st;
}

/* After a ring's deposit (and the next ring's weights), over the domain
 * (snow_ring_reduce): q[0] the quanta the ring received, q[1] its points
 * that got less than their share, q[2] the next ring's weights (units of
 * 2^-20), q[3] its points. */
static gr_status gr_snow_ring_sums(gr_snow_deformation *s, const gr_snow_cwin *win,
                                   long long q[4]) {
  cl_int nx = s->grid.nx;
  const gr_snow_arg args[] = {
      {"got", sizeof(cl_mem), &s->scratch},   {"full", sizeof(cl_mem), &s->movable},
      {"weight", sizeof(cl_mem), &s->weight}, {"nx", sizeof(nx), &nx},
      {"x0", sizeof(cl_int), &win->rx0},      {"y0", sizeof(cl_int), &win->ry0},
      {"w", sizeof(cl_int), &win->rw},        {"n", sizeof(cl_int), &win->rn}};
  gr_status st = gr_snow_args(s, s->ring_reduce, args, sizeof(args) / sizeof(args[0]));
  if (st == GR_OK)
    st = gr_reduction_i64_run(s->ctx, &s->red_ring, s->ring_reduce, q);
  if (st == GR_OK)
    st = gr_snow_allreduce_i64(s, q, 4);
  return st;
}

/* snow_apply on the window: ring 0 presses (press) and deposits, a later
 * ring only deposits; each point's deposit to scratch, its lack of room to
 * movable (for gr_snow_ring_sums). */
static gr_status gr_snow_apply_ring(gr_snow_deformation *s, const gr_snow_cwin *win, cl_int ring,
                                    cl_int press, float add_depth, float add_rho) {
  cl_int nx = s->grid.nx, ny = s->grid.ny;
  float clearance = (float)(2.0 * GR_SNOW_DEFORMATION_CONTACT_GAP);
  const gr_snow_arg args[] = {{"clearance", sizeof(clearance), &clearance},
                              {"add_depth", sizeof(add_depth), &add_depth},
                              {"add_rho", sizeof(add_rho), &add_rho},
                              {"press", sizeof(press), &press},
                              {"ring", sizeof(ring), &ring},
                              {"nx", sizeof(nx), &nx},
                              {"ny", sizeof(ny), &ny},
                              {"x_end", sizeof(cl_int), &win->x_end},
                              {"y_end", sizeof(cl_int), &win->y_end},
                              {"overlap_sum", sizeof(cl_mem), &s->overlap_sum},
                              {"contact", sizeof(cl_mem), &s->contact},
                              {"under_min", sizeof(cl_mem), &s->under_min},
                              {"got", sizeof(cl_mem), &s->scratch},
                              {"full", sizeof(cl_mem), &s->movable}};
  gr_status st = gr_snow_press_args(s, s->apply);
  if (st == GR_OK)
    st = gr_snow_args(s, s->apply, args, sizeof(args) / sizeof(args[0]));
  if (st == GR_OK)
    st = gr_enqueue_2d(s->ctx, s->apply, win->x0, win->y0, win->w, win->h, NULL);
  return st;
}

/* An object's press and deposit (header, steps 4 to 6): give (per unit
 * cell area: the displaced snow and what waited) goes to the contour at
 * add_depth per unit weight, each point taking at most its room under the
 * objects (snow_room: snow is never put under an object up to its
 * underside). What did not fit under an overhang goes on to the next ring
 * out, the points bordering the full ones, with the same direction
 * weights (or evenly, where none faces the motion), ring by ring until it
 * is placed: at most GR_SNOW_DEPOSIT_RINGS rings, and what is left (the
 * rounding to whole quanta, less than a quantum a point) waits for the
 * next press. One read-back a ring: its deposit and the next ring's
 * weights together. Every decision is on global integer sums: the same on
 * every split. */
static gr_status gr_snow_deposit(gr_snow_deformation *s, const gr_snow_cwin *win, cl_int press,
                                 float add_depth, float add_rho, double give, float vx, float vy,
                                 float rest) {
  const double quantum = 1.0 / GR_SNOW_QUANTUM_INV;
  long long q[4] = {0, 0, 0, 0};
  gr_status st = GR_OK;
  double left = give;
  for (cl_int ring = 0; st == GR_OK; ++ring) {
    if (win->on)
      st = gr_snow_apply_ring(s, win, ring, press, add_depth, add_rho);
    /* A piece's ring: the contour and the deposits beside its outer edge
     * lacked their neighbours; the neighbours' own points replace them. */
    if (st == GR_OK)
      st = gr_snow_piece_sync(s);
    if (st != GR_OK || add_depth <= 0.0f)
      return st; /* nothing deposited: what waits still waits */
    if (win->on)
      st = gr_snow_contour_ring(s, win, ring + 1, vx, vy, rest);
    if (st == GR_OK)
      st = gr_snow_ring_sums(s, win, q);
    if (st != GR_OK)
      break;
    left -= (double)q[0] * quantum;
    if (q[1] == 0 || ring == GR_SNOW_DEPOSIT_RINGS)
      break;                     /* all placed but the rounding's rest, or the last ring */
    if (q[3] > 0 && q[2] == 0) { /* no point of the next ring faces the motion: evenly */
      if (win->on)
        st = gr_snow_contour_ring(s, win, ring + 1, vx, vy, 1.0f);
      if (st == GR_OK)
        st = gr_snow_ring_sums(s, win, q);
    }
    if (st != GR_OK || q[2] <= 0)
      break; /* no ring left on the grid */
    double per = left / ((double)q[2] / GR_SNOW_WEIGHT_INV);
    add_depth = (float)per;
    if ((double)add_depth > per)
      add_depth = nextafterf(add_depth, 0.0f);
  }
  /* The rest waits for the next press (and counts in the ledger). */
  s->pending_mass = left > 0.0 ? left * add_rho : 0.0;
  s->pending = left > 0.0 ? left : 0.0;
  return st;
}

/* An object's windows on the local arrays. The kernels run on the object's
 * box grown by two (W: the underside, +inf beyond the box, and the
 * overlap, 0 there) and by one (C: the contour ring and everything that
 * reads the contour). Outside W nothing changes, and the step's reset
 * clears W again. On a piece the windows are cut to the local arrays, ring
 * included, and may be empty there: the piece still takes part in the
 * object's global sums and halo exchange. A launch is rounded up to whole
 * work-groups: the kernels stop at the window's end (x_end, y_end), as
 * what lies beyond is another object's or step's. */
typedef struct gr_snow_obj_win {
  int wx0, wy0, wx1, wy1, cx0, cy0, cx1, cy1;
  int w_on, c_on;
  size_t WX0, WY0, WW, WH, CX0, CY0, CW, CH;
  cl_int wx_end, wy_end, cx_end, cy_end;
} gr_snow_obj_win;

static void gr_snow_object_windows(const gr_snow_deformation *s, const gr_snow_object *ob,
                                   gr_snow_obj_win *w) {
  int nx = s->grid.nx, ny = s->grid.ny;
  w->wx0 = ob->bi0 - 2 > 0 ? ob->bi0 - 2 : 0;
  w->wy0 = ob->bj0 - 2 > 0 ? ob->bj0 - 2 : 0;
  w->wx1 = ob->bi1 + 2 < nx - 1 ? ob->bi1 + 2 : nx - 1;
  w->wy1 = ob->bj1 + 2 < ny - 1 ? ob->bj1 + 2 : ny - 1;
  w->cx0 = ob->bi0 - 1 > 0 ? ob->bi0 - 1 : 0;
  w->cy0 = ob->bj0 - 1 > 0 ? ob->bj0 - 1 : 0;
  w->cx1 = ob->bi1 + 1 < nx - 1 ? ob->bi1 + 1 : nx - 1;
  w->cy1 = ob->bj1 + 1 < ny - 1 ? ob->bj1 + 1 : ny - 1;
  w->w_on = w->wx0 <= w->wx1 && w->wy0 <= w->wy1;
  w->c_on = w->cx0 <= w->cx1 && w->cy0 <= w->cy1;
  w->WX0 = (size_t)w->wx0, w->WY0 = (size_t)w->wy0;
  w->WW = (size_t)(w->wx1 - w->wx0 + 1), w->WH = (size_t)(w->wy1 - w->wy0 + 1);
  w->CX0 = (size_t)w->cx0, w->CY0 = (size_t)w->cy0;
  w->CW = (size_t)(w->cx1 - w->cx0 + 1), w->CH = (size_t)(w->cy1 - w->cy0 + 1);
  w->wx_end = w->wx1 + 1, w->wy_end = w->wy1 + 1, w->cx_end = w->cx1 + 1, w->cy_end = w->cy1 + 1;
}

/* The object's underside: W cleared, then its triangles rastered. */
static gr_status gr_snow_object_raster(gr_snow_deformation *s, const gr_snow_object *ob,
                                       gr_snow_obj_win *w) {
  gr_context *ctx = s->ctx;
  int nx = s->grid.nx, ny = s->grid.ny;
  float dx = (float)s->grid.dx, dy = (float)s->grid.dy;
  /* The raster's box and loop in the domain's indices (the same floats on
   * every piece), cut to the local arrays. */
  cl_int first = ob->first, count = ob->count, ox = s->ox, oy = s->oy;
  cl_int bi0 = (ob->bi0 > 0 ? ob->bi0 : 0) + ox, bi1 = (ob->bi1 < nx - 1 ? ob->bi1 : nx - 1) + ox,
         bj0 = (ob->bj0 > 0 ? ob->bj0 : 0) + oy, bj1 = (ob->bj1 < ny - 1 ? ob->bj1 : ny - 1) + oy;
  gr_status st = GR_OK;
  if (w->w_on) {
    gr_snow_dirty(s, w->wx0, w->wy0, w->wx1, w->wy1);
    st = GR_SNOW_ARG(s, s->raster_clear, "nx", nx);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->raster_clear, "ny", ny);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->raster_clear, "x_end", w->wx_end);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->raster_clear, "y_end", w->wy_end);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->raster_clear, "under", s->under);
    if (st == GR_OK)
      st = gr_enqueue_2d(ctx, s->raster_clear, w->WX0, w->WY0, w->WW, w->WH, NULL);
  }
  const gr_snow_arg raster[] = {{"tri", sizeof(cl_mem), &s->tri},
                                {"first", sizeof(first), &first},
                                {"count", sizeof(count), &count},
                                {"nx", sizeof(nx), &nx},
                                {"dx", sizeof(dx), &dx},
                                {"dy", sizeof(dy), &dy},
                                {"bi0", sizeof(bi0), &bi0},
                                {"bi1", sizeof(bi1), &bi1},
                                {"bj0", sizeof(bj0), &bj0},
                                {"bj1", sizeof(bj1), &bj1},
                                {"ox", sizeof(ox), &ox},
                                {"oy", sizeof(oy), &oy},
                                {"under", sizeof(cl_mem), &s->under}};
  if (st == GR_OK && bi0 <= bi1 && bj0 <= bj1 && count > 0) {
    st = gr_snow_args(s, s->raster, raster, sizeof(raster) / sizeof(raster[0]));
    if (st == GR_OK)
      st = gr_enqueue_1d(ctx, s->raster, (size_t)count); /* one work-item per triangle */
  }
  if (st == GR_OK)
    st = gr_snow_mark(s, &s->tm.raster_ms);
  return st;
}

/* The overlap of the underside and the snow on W. */
static gr_status gr_snow_object_overlap(gr_snow_deformation *s, gr_snow_obj_win *w) {
  int nx = s->grid.nx, ny = s->grid.ny;
  gr_status st = GR_OK;
  if (w->w_on) {
    st = GR_SNOW_ARG(s, s->overlap_k, "ground", s->ground);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->overlap_k, "depth", s->depth[s->cur]);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->overlap_k, "under", s->under);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->overlap_k, "nx", nx);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->overlap_k, "ny", ny);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->overlap_k, "overlap", s->overlap);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->overlap_k, "x_end", w->wx_end);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->overlap_k, "y_end", w->wy_end);
    if (st == GR_OK)
      st = gr_enqueue_2d(s->ctx, s->overlap_k, w->WX0, w->WY0, w->WW, w->WH, NULL);
  }
  if (st == GR_OK)
    st = gr_snow_mark(s, &s->tm.press_ms);
  return st;
}

/* The contour's direction: the object's motion in x and y, and the weight
 * of the ring at rest (straight down: a uniform ring). */
static void gr_snow_object_direction(const gr_snow_deformation *s, const gr_snow_object *ob,
                                     float *vx, float *vy, float *rest) {
  double vn = sqrt(ob->v[0] * ob->v[0] + ob->v[1] * ob->v[1] + ob->v[2] * ob->v[2]);
  double ux = 0.0, uy = 0.0, uz = -1.0; /* at rest: straight down, a uniform ring */
  if (vn > 0.0) {
    ux = ob->v[0] / vn;
    uy = ob->v[1] / vn;
    uz = ob->v[2] / vn;
  }
  *vx = (float)ux, *vy = (float)uy, *rest = (float)(uz * uz / s->params.direction_falloff);
}

/* Totals over the piece's own points of the contour window (fixed point:
 * the same integers however the domain is split), then over the domain,
 * into q; win gets the own part of the window. */
static gr_status gr_snow_object_sums(gr_snow_deformation *s, const gr_snow_obj_win *w,
                                     gr_snow_cwin *win, long long q[GR_SNOW_OBJ_SUMS]) {
  int nx = s->grid.nx;
  int rx0 = w->cx0, ry0 = w->cy0, rx1 = w->cx1, ry1 = w->cy1;
  gr_snow_own_clip(s, &rx0, &ry0, &rx1, &ry1);
  cl_int cw = rx1 - rx0 + 1, cn = rx0 <= rx1 && ry0 <= ry1 ? cw * (ry1 - ry0 + 1) : 0;
  cw = cw > 0 ? cw : 1;
  win->rx0 = rx0, win->ry0 = ry0, win->rw = cw, win->rn = cn;
  gr_status st = gr_snow_press_args(s, s->obj_reduce);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, s->obj_reduce, "nx", nx);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, s->obj_reduce, "x0", rx0);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, s->obj_reduce, "y0", ry0);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, s->obj_reduce, "w", cw);
  if (st == GR_OK)
    st = GR_SNOW_ARG(s, s->obj_reduce, "n", cn);
  if (st == GR_OK)
    st = gr_reduction_i64_run(s->ctx, &s->red_obj, s->obj_reduce, q);
  if (st == GR_OK)
    st = gr_snow_allreduce_i64(s, q, GR_SNOW_OBJ_SUMS);
  if (st == GR_OK)
    st = gr_snow_mark(s, &s->tm.press_ms);
  return st;
}

/* The press from the object's sums q: the ledger's compressed and
 * displaced snow, the force on the object and its contact area, then the
 * displaced snow deposited on the contour. */
static gr_status gr_snow_object_press(gr_snow_deformation *s, int o, double dt,
                                      const gr_snow_cwin *win, const long long q[GR_SNOW_OBJ_SUMS],
                                      float vx, float vy, float rest) {
  const gr_snow_object *ob = &s->objects[o];
  /* sums, per unit cell area: 0 e, 1 e rho, 2 weights, 3 contour points,
   * 4 D rho, 5 D - e, 6 contact points */
  const double quantum = 1.0 / GR_SNOW_QUANTUM_INV, press_mass = 1.0 / GR_SNOW_PRESS_MASS_INV;
  double sums[GR_SNOW_OBJ_SUMS] = {(double)q[0] * quantum,
                                   (double)q[1] * press_mass,
                                   (double)q[2] / GR_SNOW_WEIGHT_INV,
                                   (double)q[3],
                                   (double)q[4] * press_mass,
                                   (double)q[5] * quantum,
                                   (double)q[6]};
  double area = s->grid.dx * s->grid.dy;
  int press = sums[3] > 0.0 && sums[2] > 0.0 && sums[0] > 0.0;
  if (sums[0] <= 0.0 && sums[5] > 0.0)
    press = 1; /* all compressed, nothing to distribute */
  float add_depth = 0.0f, add_rho = (float)s->params.max_density;
  /* What the contour receives: this object's displaced snow and what the
   * rounding to whole quanta kept back before (pending), per unit weight,
   * rounded down so that the contour never receives more. */
  double give = sums[0] + s->pending;
  if (press && sums[2] > 0.0 && sums[0] > 0.0) {
    double per = give / sums[2];
    add_depth = (float)per;
    if ((double)add_depth > per)
      add_depth = nextafterf(add_depth, 0.0f);
    add_rho = (float)fmin(s->params.max_density, sums[1] / sums[0]);
  }
  if (press) {
    s->compressed += sums[5] * area;
    s->displaced += sums[0] * area;
    double m = sums[4] * area;
    for (int a = 0; a < 3; ++a)
      s->force[o][a] += -m * ob->v[a] / dt;
  }
  s->area[o] = sums[6] * area;
  gr_status st = gr_snow_deposit(s, win, press, add_depth, add_rho, give, vx, vy, rest);
  if (st == GR_OK)
    st = gr_snow_mark(s, &s->tm.distribution_ms);
  return st;
}

/* One object's press on the snow: its underside, the overlap, the contour
 * ring, the sums over the domain, then the press itself. */
static gr_status gr_snow_object_step(gr_snow_deformation *s, int o, double dt) {
  const gr_snow_object *ob = &s->objects[o];
  s->area[o] = 0.0;
  if (ob->bi0 > ob->bi1 || ob->bj0 > ob->bj1)
    return GR_OK; /* wholly off the (whole) grid: it touches nothing, on every piece */
  gr_snow_obj_win w;
  gr_snow_object_windows(s, ob, &w);
  gr_status st = gr_snow_object_raster(s, ob, &w);
  if (st == GR_OK)
    st = gr_snow_object_overlap(s, &w);
  float vx, vy, rest;
  gr_snow_object_direction(s, ob, &vx, &vy, &rest);
  gr_snow_cwin win = {w.CX0, w.CY0, w.CW, w.CH, w.cx_end, w.cy_end, 0, 0, 1, 0, w.c_on};
  if (st == GR_OK && w.c_on)
    st = gr_snow_contour_ring(s, &win, 0, vx, vy, rest);
  if (st == GR_OK)
    st = gr_snow_mark(s, &s->tm.contour_ms);
  long long q[GR_SNOW_OBJ_SUMS];
  if (st == GR_OK)
    st = gr_snow_object_sums(s, &w, &win, q);
  if (st != GR_OK)
    return st;
  return gr_snow_object_press(s, o, dt, &win, q, vx, vy, rest);
}

gr_status gr_snow_deformation_step(gr_snow_deformation *s, double dt) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_step needs a simulation.");
  if (!(dt >= GR_SNOW_MIN_DT && dt <= GR_SNOW_MAX_DT))
    return GR_SNOW_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow deformation time step must lie between 1e-9 and 3600 s (got "
                        "%g s).",
                        dt));
  if (s->aborted)
    return GR_SNOW_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_ABORTED,
                        "The snow deformation was stopped by its progress callback%s; set the "
                        "callback again or reset to go on.",
                        s->allreduce ? " (of this or another piece of the domain)" : ""));
  if (gr_snow_has_ring(s) && (!s->allreduce || !s->halo_exchange))
    return GR_SNOW_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "A snow deformation piece with neighbours steps only with a global "
                        "reduction and a halo exchange (it has %s and %s): set them with "
                        "gr_snow_deformation_set_allreduce and "
                        "gr_snow_deformation_set_halo_exchange.",
                        s->allreduce ? "one" : "none", s->halo_exchange ? "one" : "none"));
  gr_status st = gr_snow_reset(s);
  memset(s->force, 0, sizeof(s->force));
  if (st == GR_OK && s->timing) {
    st = gr_finish(s->ctx);
    s->t_mark = gr_snow_now_ms();
  }
  for (int o = 0; st == GR_OK && o < s->nobjects; ++o)
    st = gr_snow_object_step(s, o, dt);
  if (st == GR_OK)
    st = gr_snow_relax(s, dt);
  if (st == GR_OK)
    st = gr_snow_mark(s, &s->tm.relax_ms);
  if (st == GR_OK && s->timing) {
    s->tm.steps++;
    s->tm.relax_iterations += s->relax_iterations;
  }
  if (st == GR_OK)
    st = gr_finish(s->ctx);
  if (st != GR_OK)
    return GR_SNOW_KEEP_ERROR(s, st);
  s->time += dt;
  s->steps++;
  /* The impulse: the force of a step acts over the step. */
  for (int o = 0; o < s->nobjects; ++o) {
    const double *f = s->force[o];
    for (int a = 0; a < 3; ++a)
      s->impulse[o][a] += f[a] * dt;
    s->peak[o] = fmax(s->peak[o], sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]));
  }
  s->impulse_time += dt;
  int stop = s->progress && s->progress(s->progress_user, s->time) != 0;
  /* Pieces: a stop asked on any piece stops every piece after this step
   * (every piece makes this call at every step, callback or not). */
  if (s->allreduce) {
    double flag = stop ? 1.0 : 0.0;
    st = gr_snow_allreduce(s, &flag, 1, GR_REDUCE_MAX);
    stop = flag != 0.0;
  }
  if (stop)
    s->aborted = 1;
  return st == GR_OK ? GR_OK : GR_SNOW_KEEP_ERROR(s, st);
}

gr_status gr_snow_deformation_get_field(gr_snow_deformation *s, gr_field f, float *host) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_get_field needs a simulation.");
  if (!host)
    return GR_SNOW_KEEP_ERROR(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                              "gr_snow_deformation_get_field needs a place for "
                                              "the values (got NULL)."));
  cl_mem src = NULL;
  gr_status st = GR_OK;
  switch (f) {
  case GR_FIELD_SNOW_DEPTH:
    src = s->depth[s->cur];
    break;
  case GR_FIELD_SNOW_DENSITY:
    src = s->density[s->cur];
    break;
  case GR_FIELD_OVERLAP:
    src = s->overlap_sum;
    break;
  case GR_FIELD_CONTACT:
    src = s->contact;
    break;
  case GR_FIELD_ELEVATION:
    src = s->ground;
    break;
  case GR_FIELD_SNOW_SURFACE: {
    int n = (int)gr_snow_cells(s);
    st = GR_SNOW_ARG(s, s->surface, "ground", s->ground);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->surface, "depth", s->depth[s->cur]);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->surface, "n", n);
    if (st == GR_OK)
      st = GR_SNOW_ARG(s, s->surface, "out", s->scratch);
    if (st == GR_OK)
      st = gr_enqueue_1d(s->ctx, s->surface, (size_t)n);
    src = s->scratch;
    break;
  }
  default: {
    const char *name = gr_field_name(f);
    return GR_SNOW_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "The snow deformation simulation has no output field '%s'; it gives "
                        "snow_depth, snow_surface, snow_density, overlap, contact and elevation.",
                        name ? name : "(unknown field)"));
  }
  }
  if (st == GR_OK)
    st = gr_snow_read_own(s, src, host);
  return st == GR_OK ? GR_OK : GR_SNOW_KEEP_ERROR(s, st);
}

gr_status gr_snow_deformation_ledger_get(gr_snow_deformation *s, gr_snow_deformation_ledger *out) {
  if (!s || !out)
    return s ? GR_SNOW_KEEP_ERROR(s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                                  "gr_snow_deformation_ledger_get needs a place "
                                                  "for the ledger."))
             : gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                            "gr_snow_deformation_ledger_get needs a simulation.");
  /* Fixed point over the own points, then over every piece (collective):
   * the whole grid's integers, so its very doubles. */
  long long q[4] = {0, 0, s->initial_q, s->initial_m};
  gr_status st = gr_snow_ledger_sums(s, &q[0], &q[1]);
  if (st == GR_OK)
    st = gr_snow_allreduce_i64(s, q, 4);
  if (st != GR_OK)
    return GR_SNOW_KEEP_ERROR(s, st);
  const double a = s->grid.dx * s->grid.dy, quantum = 1.0 / GR_SNOW_QUANTUM_INV,
               mass = 1.0 / GR_SNOW_LEDGER_MASS_INV;
  double v = (double)q[0] * quantum * a, m = (double)q[1] * mass * a;
  memset(out, 0, sizeof(*out));
  out->time = s->time;
  out->steps = s->steps;
  out->initial_volume = (double)q[2] * quantum * a;
  out->initial_mass = (double)q[3] * mass * a;
  /* Displaced snow waiting for a contour is still snow. */
  v += s->pending * a;
  m += s->pending_mass * a;
  out->snow_volume = v;
  out->snow_mass = m;
  out->compressed_volume = s->compressed;
  out->displaced_volume = s->displaced;
  out->balance_error = m - out->initial_mass;
  out->volume_error = out->initial_volume - s->compressed - v;
  out->relax_iterations = s->relax_iterations;
  return GR_OK;
}

gr_status gr_snow_deformation_object_forces(gr_snow_deformation *s, double *force3, double *area,
                                            int n) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_object_forces needs a simulation.");
  if (n != s->nobjects)
    return GR_SNOW_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_object_forces was asked for %d objects but %d are "
                        "set; pass the number given to set_objects.",
                        n, s->nobjects));
  for (int o = 0; o < n; ++o) {
    if (force3)
      for (int a = 0; a < 3; ++a)
        force3[3 * o + a] = s->force[o][a];
    if (area)
      area[o] = s->area[o];
  }
  return GR_OK;
}

gr_status gr_snow_deformation_object_mean_forces(gr_snow_deformation *s, double *force3,
                                                 double *peak, double *seconds, int n) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_object_mean_forces needs a simulation.");
  if (n != s->nobjects)
    return GR_SNOW_KEEP_ERROR(
        s, gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_deformation_object_mean_forces was asked for %d objects but %d "
                        "are set; pass the number given to set_objects.",
                        n, s->nobjects));
  const double span = s->impulse_time;
  for (int o = 0; o < n; ++o) {
    if (force3)
      for (int a = 0; a < 3; ++a)
        force3[3 * o + a] = span > 0.0 ? s->impulse[o][a] / span : 0.0;
    if (peak)
      peak[o] = s->peak[o];
  }
  if (seconds)
    *seconds = span;
  return GR_OK;
}

void gr_snow_deformation_clear_impulses(gr_snow_deformation *s) {
  if (!s)
    return;
  memset(s->impulse, 0, sizeof(s->impulse));
  memset(s->peak, 0, sizeof(s->peak));
  s->impulse_time = 0.0;
}

void gr_snow_deformation_set_progress(gr_snow_deformation *s, gr_progress_fn fn, void *user) {
  if (!s)
    return;
  s->progress = fn;
  s->progress_user = user;
  s->aborted = 0;
}
