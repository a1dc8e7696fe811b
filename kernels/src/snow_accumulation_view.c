/* Snow accumulation core, host side (snow_accumulation_internal.h): the
 * snowfall's direction of a step, the exposure view (its box, and its rows
 * combined over the pieces of a split domain), and the objects' exposure
 * and the snow surface under them on a piece. */
#include "snow_accumulation_internal.h"

/* A 64-bit mix (splitmix64): the flutter's random numbers per step. */
static uint64_t gr_snac_mix(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

/* This step's unit snow direction: SnowDirection turned by up to Flutter,
 * uniformly over the cone's disc, seeded by Seed and the step's number. */
void gr_snac_direction(const gr_snow_accumulation *s, double d[3]) {
  const double *p = s->params.direction;
  double len = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
  for (int a = 0; a < 3; ++a)
    d[a] = p[a] / len;
  if (!(s->params.flutter > 0.0))
    return;
  uint64_t h = gr_snac_mix(((uint64_t)(uint32_t)s->params.seed << 32) ^ (uint64_t)s->steps);
  double u1 = (double)(h >> 11) / 9007199254740992.0;
  double u2 = (double)(gr_snac_mix(h) >> 11) / 9007199254740992.0;
  double alpha = s->params.flutter * sqrt(u1), beta = 2.0 * GR_SNAC_PI * u2;
  /* e1, e2: unit vectors across d. */
  double e1[3] = {1.0, 0.0, 0.0};
  if (fabs(d[0]) > 0.9)
    e1[0] = 0.0, e1[1] = 1.0;
  double dot = e1[0] * d[0] + e1[1] * d[1] + e1[2] * d[2];
  for (int a = 0; a < 3; ++a)
    e1[a] -= dot * d[a];
  double l1 = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
  for (int a = 0; a < 3; ++a)
    e1[a] /= l1;
  double e2[3] = {d[1] * e1[2] - d[2] * e1[1], d[2] * e1[0] - d[0] * e1[2],
                  d[0] * e1[1] - d[1] * e1[0]};
  for (int a = 0; a < 3; ++a)
    d[a] = cos(alpha) * d[a] + sin(alpha) * (cos(beta) * e1[a] + sin(beta) * e2[a]);
}

void gr_snac_view_of(const gr_snow_accumulation *s, const double d[3], gr_snac_view *v) {
  const gr_grid *g = &s->grid;
  double tx = -d[0] / d[2], ty = -d[1] / d[2];
  /* The domain's extent (a piece's view is the whole domain's). */
  double W = (s->gnx - 1) * g->dx, H = (s->gny - 1) * g->dy;
  double box[2][3][2] = {
      {{0.0, W}, {0.0, H}, {s->bmin - s->zref, s->bmax + s->snow_bound - s->zref}},
      {{0, 0}, {0, 0}, {0, 0}}};
  int nbox = 1;
  if (s->nv > 0) {
    /* The objects, but no further than half the grid beyond it: an object
     * far away would coarsen the view of the terrain. */
    double lox = s->ob_lo[0] - g->x0, hix = s->ob_hi[0] - g->x0;
    double loy = s->ob_lo[1] - g->y0, hiy = s->ob_hi[1] - g->y0;
    box[1][0][0] = fmax(lox, -0.5 * W - g->dx), box[1][0][1] = fmin(hix, 1.5 * W + g->dx);
    box[1][1][0] = fmax(loy, -0.5 * H - g->dy), box[1][1][1] = fmin(hiy, 1.5 * H + g->dy);
    box[1][2][0] = s->ob_lo[2] - s->zref, box[1][2][1] = s->ob_hi[2] - s->zref;
    nbox = box[1][0][0] <= box[1][0][1] && box[1][1][0] <= box[1][1][1] ? 2 : 1;
  }
  double qlo[2] = {HUGE_VAL, HUGE_VAL}, qhi[2] = {-HUGE_VAL, -HUGE_VAL};
  for (int b = 0; b < nbox; ++b)
    for (int k = 0; k < 8; ++k) {
      double x = box[b][0][k & 1], y = box[b][1][(k >> 1) & 1], z = box[b][2][(k >> 2) & 1];
      double q[2] = {x + z * tx, y + z * ty};
      for (int a = 0; a < 2; ++a)
        qlo[a] = fmin(qlo[a], q[a]), qhi[a] = fmax(qhi[a], q[a]);
    }
  int res = s->params.exposure_resolution;
  double span = fmax(qhi[0] - qlo[0], qhi[1] - qlo[1]);
  double texel = span > 0.0 ? span / res : fmax(g->dx, g->dy) / res;
  int m = GR_SNAC_VIEW_MARGIN;
  v->tau_x = (float)tx, v->tau_y = (float)ty;
  v->texel = (float)texel;
  v->inv_texel = (float)(1.0 / texel);
  v->qx0 = (float)(qlo[0] - m * texel);
  v->qy0 = (float)(qlo[1] - m * texel);
  v->vw = (int)fmin(ceil((qhi[0] - qlo[0]) / texel), (double)res) + 2 * m + 1;
  v->vh = (int)fmin(ceil((qhi[1] - qlo[1]) / texel), (double)res) + 2 * m + 1;
}

/* The view rows [lo, hi] that points projected between heights zlo and
 * zhi (relative to zref) at y from ylo to yhi (relative to grid point
 * (0, 0)) can fall in, with two rows to spare beyond the float rounding of
 * the kernels' projection; lo > hi when none. */
static void gr_snac_band(const gr_snac_view *v, double ylo, double yhi, double zlo, double zhi,
                         int *lo, int *hi) {
  double ty = v->tau_y, qy0 = v->qy0, inv = v->inv_texel, qmin = HUGE_VAL, qmax = -HUGE_VAL;
  for (int k = 0; k < 4; ++k) {
    double y = k & 1 ? yhi : ylo, z = k & 2 ? zhi : zlo;
    double q = (y + z * ty - qy0) * inv;
    qmin = fmin(qmin, q), qmax = fmax(qmax, q);
  }
  double big = fmax(fabs(ylo), fabs(yhi)) + fmax(fabs(zlo), fabs(zhi)) * fabs(ty) + fabs(qy0);
  double slack = 2.0 + 1e-5 * big * inv;
  double a = floor(qmin - slack), b = ceil(qmax + slack);
  *lo = a < 0.0 ? 0 : (int)fmin(a, (double)v->vh);
  *hi = b > v->vh - 1.0 ? v->vh - 1 : (int)fmax(b, -1.0);
}

/* Room for n values per face or sample in s->o_surface. */
static gr_status gr_snac_point_buffer(gr_snow_accumulation *s, size_t n) {
  if (n <= s->o_surface_cap)
    return GR_OK;
  gr_buffer_release(&s->o_surface);
  s->o_surface_cap = 0;
  gr_status st =
      gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, n * sizeof(float), NULL, &s->o_surface);
  if (st == GR_OK)
    s->o_surface_cap = n;
  return st;
}

/* This piece's band: its local rows, every height the view's box allows. */
static void gr_snac_piece_band(const gr_snow_accumulation *s, const gr_snac_view *v, int *lo,
                               int *hi) {
  double zlo = fmin(0.0, s->bmin - s->zref), zhi = s->bmax + s->snow_bound - s->zref;
  gr_snac_band(v, (double)s->row0 * s->grid.dy, (double)(s->row0 + s->grid.ny - 1) * s->grid.dy,
               zlo, zhi, lo, hi);
}

void gr_snac_object_rows(const gr_snow_accumulation *s, const gr_snac_view *v, int *lo, int *hi) {
  gr_snac_piece_band(s, v, lo, hi);
  if (*lo > *hi) {
    /* No band (cannot happen for a view of the domain's box): every row. */
    *lo = 0, *hi = v->vh - 1;
    return;
  }
  /* The bands rise with the rows (a strip's band is its rows' y plus the
   * same heights times tau_y) and neighbours' overlap (their local rows
   * share the rings), so the first piece's band from row 0 and the last's
   * up to the top, with every band between, cover the view. */
  if (s->row0 == 0)
    *lo = 0;
  if (s->row0 + s->grid.ny == s->gny)
    *hi = v->vh - 1;
}

/* The view's rows marked in rows (vh of them, vw texels each) copied
 * between the device and keys, packed run by run in order: read (write 0)
 * or written back (write 1). */
static gr_status gr_snac_view_rows(gr_snow_accumulation *s, const unsigned char *rows, size_t vh,
                                   size_t vw, cl_int *keys, int write) {
  gr_status st = GR_OK;
  for (size_t r = 0, at = 0; st == GR_OK && r < vh;) {
    size_t r1 = r;
    while (r1 < vh && rows[r1])
      ++r1;
    if (r1 > r) {
      size_t off = r * vw * sizeof(cl_int), m = (r1 - r) * vw;
      st = write ? gr_buffer_write(s->ctx, s->view, off, m * sizeof(cl_int), keys + at)
                 : gr_buffer_read(s->ctx, s->view, off, m * sizeof(cl_int), keys + at);
      at += m;
    }
    r = r1 > r ? r1 : r + 1;
  }
  return st;
}

/* The pieces' views combined, texel by texel, with a maximum (ints travel
 * exactly as doubles), in the rows where that can change a texel that a
 * piece reads. A piece draws its local cells (ring included) into rows of
 * a band its rows and the surface's height range bound, and the objects
 * into that band at least (gr_snac_object_rows); its grid points read only
 * there, and outside every other piece's band the others' views hold
 * objects alone, which this piece drew too, so its own texel is already
 * the maximum. The rows two or more bands cover are found by one
 * reduction of 2 values a row (the highest and lowest piece covering it)
 * and only they are combined: a band of about the ring plus the relief
 * times the snow's slope across the cut, instead of the whole view. The
 * objects' points read rows anywhere: their exposure is combined per point
 * (snow_accumulation_object_exposure), unless combining the rows under
 * them costs fewer values. The rows and the points travel in one
 * allreduce, a read-back and a write each. Waits. */
gr_status gr_snac_view_reduce(gr_snow_accumulation *s, const gr_snac_view *v, const float dir[3]) {
  size_t vh = (size_t)v->vh, vw = (size_t)v->vw;
  if (vh > s->view_rows_cap) {
    unsigned char *r = realloc(s->view_rows, vh);
    if (r)
      s->view_rows = r;
    double *c = r ? realloc(s->view_cover, 2 * vh * sizeof(double)) : NULL;
    if (c)
      s->view_cover = c;
    if (!r || !c)
      return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
    s->view_rows_cap = vh;
  }
  unsigned char *rows = s->view_rows;
  double *cover = s->view_cover;
  int lo, hi;
  gr_snac_piece_band(s, v, &lo, &hi);
  double id = (double)(s->row0 + s->ring_s); /* the first own row: one per piece */
  for (size_t r = 0; r < vh; ++r) {
    int in = (int)r >= lo && (int)r <= hi;
    cover[2 * r] = in ? id : -HUGE_VAL;
    cover[2 * r + 1] = in ? -id : -HUGE_VAL;
  }
  gr_status st = gr_snac_allreduce(s, cover, 2 * vh, GR_REDUCE_MAX);
  if (st != GR_OK)
    return st;
  for (size_t r = 0; r < vh; ++r)
    rows[r] = cover[2 * r] > -HUGE_VAL && cover[2 * r] != -cover[2 * r + 1];
  /* The objects: the rows under their box (the same on every piece), or a
   * value per face and sample, whichever is fewer values. */
  s->objects_by_point = 0;
  size_t points = (size_t)s->ntri + (size_t)s->ns;
  if (points > 0) {
    double half = GR_SNAC_NORMAL_OFFSET * v->texel; /* a face's test position */
    gr_snac_band(v, s->ob_lo[1] - s->grid.y0 - half, s->ob_hi[1] - s->grid.y0 + half,
                 s->ob_lo[2] - s->zref - half, s->ob_hi[2] - s->zref + half, &lo, &hi);
    size_t extra = 0;
    for (int r = lo; r <= hi; ++r)
      extra += !rows[r];
    if (extra * vw > points)
      s->objects_by_point = 1;
    else
      for (int r = lo; r <= hi; ++r)
        rows[r] = 1;
  }
  /* Every value the pieces combine this step in one allreduce: the rows
   * (ints travel exactly as doubles), then with objects_by_point minus the
   * faces' and the samples' exposure from this piece's view. */
  size_t nrows = 0;
  for (size_t r = 0; r < vh; ++r)
    nrows += rows[r];
  size_t texels = nrows * vw, n = texels + (s->objects_by_point ? points : 0);
  if (n == 0)
    return GR_OK;
  if (s->objects_by_point) {
    st = gr_snac_point_buffer(s, points);
    if (st == GR_OK)
      st = gr_snac_object_exposure(s, s->o_pos, s->o_nrm, s->ntri, 0, v, dir);
    if (st == GR_OK)
      st = gr_snac_object_exposure(s, s->t_pos, s->t_nrm, s->ns, s->ntri, v, dir);
    if (st != GR_OK)
      return st;
  }
  cl_int *keys = malloc(texels * sizeof(cl_int) + 1);
  float *f = malloc((n - texels) * sizeof(float) + 1);
  double *vals = malloc(n * sizeof(double));
  if (!keys || !f || !vals)
    st = gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  if (st == GR_OK)
    st = gr_snac_view_rows(s, rows, vh, vw, keys, 0);
  if (st == GR_OK && n > texels)
    st = gr_buffer_read(s->ctx, s->o_surface, 0, (n - texels) * sizeof(float), f);
  for (size_t q = 0; st == GR_OK && q < texels; ++q)
    vals[q] = (double)keys[q];
  for (size_t q = texels; st == GR_OK && q < n; ++q)
    vals[q] = -(double)f[q - texels];
  if (st == GR_OK)
    st = gr_snac_allreduce(s, vals, n, GR_REDUCE_MAX);
  for (size_t q = 0; st == GR_OK && q < texels; ++q)
    keys[q] = (cl_int)vals[q];
  for (size_t q = texels; st == GR_OK && q < n; ++q)
    f[q - texels] = (float)-vals[q];
  if (st == GR_OK)
    st = gr_snac_view_rows(s, rows, vh, vw, keys, 1);
  if (st == GR_OK && n > texels)
    st = gr_buffer_write(s->ctx, s->o_surface, 0, (n - texels) * sizeof(float), f);
  free(keys), free(f), free(vals);
  return st;
}

/* This piece's exposure of nv faces (or samples) at pos, nrm from its own
 * view into s->o_surface from first on (snow_accumulation_object_exposure;
 * the pieces' minimum is the combined view's). Enqueues only. */
gr_status gr_snac_object_exposure(gr_snow_accumulation *s, cl_mem pos, cl_mem nrm, cl_int nv,
                                  cl_int first, const gr_snac_view *v, const float dir[3]) {
  if (nv == 0)
    return GR_OK;
  cl_int vw = v->vw, vh = v->vh;
  const gr_snac_arg a[] = {GR_SNAC_MEM("pos", pos),
                           GR_SNAC_MEM("nrm", nrm),
                           GR_SNAC_VAL("nv", nv),
                           GR_SNAC_VAL("dir_x", dir[0]),
                           GR_SNAC_VAL("dir_y", dir[1]),
                           GR_SNAC_VAL("dir_z", dir[2]),
                           GR_SNAC_VAL("tau_x", v->tau_x),
                           GR_SNAC_VAL("tau_y", v->tau_y),
                           GR_SNAC_VAL("qx0", v->qx0),
                           GR_SNAC_VAL("qy0", v->qy0),
                           GR_SNAC_VAL("inv_texel", v->inv_texel),
                           GR_SNAC_VAL("texel", v->texel),
                           GR_SNAC_VAL("vw", vw),
                           GR_SNAC_VAL("vh", vh),
                           GR_SNAC_MEM("view", s->view),
                           GR_SNAC_VAL("first", first),
                           GR_SNAC_MEM("exposure", s->o_surface)};
  gr_status st = gr_snac_args(s, s->object_exposure, a, sizeof(a) / sizeof(a[0]));
  if (st == GR_OK)
    st = gr_enqueue_1d(s->ctx, s->object_exposure, (size_t)nv);
  return st;
}

/* The snow surface under n faces (or samples) at pos, nrm into
 * s->o_surface: each piece gives the points over its own cells, the
 * allreduce the rest (snow_accumulation_object_surface). Waits. */
gr_status gr_snac_object_surface(gr_snow_accumulation *s, cl_mem pos, cl_mem nrm, cl_int nv,
                                 float texel) {
  gr_status st = gr_snac_point_buffer(s, (size_t)nv);
  if (st != GR_OK)
    return st;
  cl_int gnx = s->gnx, gny = s->gny, row0 = s->row0, own_lo = s->row0 + s->ring_s;
  cl_int own_hi = own_lo + s->own_ny - 1;
  float gdx = (float)s->grid.dx, gdy = (float)s->grid.dy, zref = (float)s->zref;
  const gr_snac_arg a[] = {GR_SNAC_MEM("pos", pos),
                           GR_SNAC_MEM("nrm", nrm),
                           GR_SNAC_VAL("nv", nv),
                           GR_SNAC_VAL("texel", texel),
                           GR_SNAC_MEM("ground", s->ground),
                           GR_SNAC_MEM("gdepth", s->arr[0]),
                           GR_SNAC_VAL("gnx", gnx),
                           GR_SNAC_VAL("gny", gny),
                           GR_SNAC_VAL("row0", row0),
                           GR_SNAC_VAL("own_lo", own_lo),
                           GR_SNAC_VAL("own_hi", own_hi),
                           GR_SNAC_VAL("gdx", gdx),
                           GR_SNAC_VAL("gdy", gdy),
                           GR_SNAC_VAL("zref", zref),
                           GR_SNAC_MEM("surface", s->o_surface)};
  st = gr_snac_args(s, s->object_surface, a, sizeof(a) / sizeof(a[0]));
  if (st == GR_OK)
    st = gr_enqueue_1d(s->ctx, s->object_surface, (size_t)nv);
  float *f = malloc((size_t)nv * sizeof(float));
  double *d = malloc((size_t)nv * sizeof(double));
  if (st == GR_OK && (!f || !d))
    st = gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  if (st == GR_OK)
    st = gr_buffer_read(s->ctx, s->o_surface, 0, (size_t)nv * sizeof(float), f);
  for (cl_int k = 0; st == GR_OK && k < nv; ++k)
    d[k] = (double)f[k];
  if (st == GR_OK)
    st = gr_snac_allreduce(s, d, (size_t)nv, GR_REDUCE_MAX);
  for (cl_int k = 0; st == GR_OK && k < nv; ++k)
    f[k] = (float)d[k];
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, s->o_surface, 0, (size_t)nv * sizeof(float), f);
  free(f), free(d);
  return st;
}
