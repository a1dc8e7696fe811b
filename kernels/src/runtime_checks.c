/* Graupel core runtime: the checks of what callers pass in: grids (whole,
 * strips and pieces of a split domain), meshes, point sets, field values
 * and parameter tables. */
#include "graupel/cl_runtime.h"
#include "runtime_internal.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------ grids */

gr_status gr_grid_validate(const gr_grid *g, char *msg, size_t msg_len) {
  const char *why = NULL;
  if (!g)
    why = "no grid was given";
  else if (g->nx < 1 || g->ny < 1)
    why = "the grid needs at least one point in x and in y";
  else if (!(g->dx > 0.0) || !(g->dy > 0.0) || g->dx > 1e12 || g->dy > 1e12)
    why = "the grid spacing must be a positive, finite number of metres";
  else if (!(g->x0 > -1e15 && g->x0 < 1e15 && g->y0 > -1e15 && g->y0 < 1e15))
    why = "the grid origin must be finite";
  else if ((double)g->nx * (double)g->ny > 4.0e9)
    why = "the grid has more than 4e9 points";
  else if (g->i0 < 0 || g->j0 < 0 || (double)g->i0 + g->nx > 2147483647.0 ||
           (double)g->j0 + g->ny > 2147483647.0)
    why = "the piece offset (i0, j0) must be non-negative and fit in int";
  if (!why)
    return GR_OK;
  if (msg && msg_len)
    snprintf(msg, msg_len, "Invalid grid: %s.", why);
  return GR_ERR_INVALID_ARGUMENT;
}

/* ------------------------------------------------------- meshes, points */

static gr_status gr_invalid(char *msg, size_t msg_len, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static gr_status gr_invalid(char *msg, size_t msg_len, const char *fmt, ...) {
  if (msg && msg_len) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, msg_len, fmt, ap);
    va_end(ap);
  }
  return GR_ERR_INVALID_ARGUMENT;
}

static const char *const gr_axis[3] = {"x", "y", "z"};

/* |det| of the 4x4 column-major m, and Hadamard's bound on it (the product
 * of the column lengths): their ratio says how far m is from singular,
 * whatever its scale. */
static double gr_det4(const double *m, double *bound) {
  double a[4][4];
  *bound = 1.0;
  for (int c = 0; c < 4; ++c) {
    double len = 0.0;
    for (int r = 0; r < 4; ++r) {
      a[r][c] = m[4 * c + r];
      len += a[r][c] * a[r][c];
    }
    *bound *= sqrt(len);
  }
  double det = 1.0;
  for (int c = 0; c < 4; ++c) { /* Gaussian elimination, partial pivoting */
    int piv = c;
    for (int r = c + 1; r < 4; ++r)
      if (fabs(a[r][c]) > fabs(a[piv][c]))
        piv = r;
    if (a[piv][c] == 0.0)
      return 0.0;
    if (piv != c) {
      for (int k = 0; k < 4; ++k) {
        double t = a[c][k];
        a[c][k] = a[piv][k];
        a[piv][k] = t;
      }
      det = -det;
    }
    det *= a[c][c];
    for (int r = c + 1; r < 4; ++r) {
      double f = a[r][c] / a[c][c];
      for (int k = c; k < 4; ++k)
        a[r][k] -= f * a[c][k];
    }
  }
  return fabs(det);
}

/* A directed edge of a triangle, keyed by its undirected vertex pair. */
typedef struct gr_edge {
  int lo, hi;   /* vertex indices, lo < hi */
  int forward;  /* 1 when the triangle runs lo -> hi */
  int triangle; /* the triangle it belongs to */
} gr_edge;

static int gr_edge_cmp(const void *pa, const void *pb) {
  const gr_edge *a = pa, *b = pb;
  if (a->lo != b->lo)
    return a->lo < b->lo ? -1 : 1;
  if (a->hi != b->hi)
    return a->hi < b->hi ? -1 : 1;
  return (a->triangle > b->triangle) - (a->triangle < b->triangle);
}

gr_status gr_grid_strip_check(const gr_grid *g, const char *core, const char *split_why, int need,
                              const char *need_for, int *ring_s, int *ring_n, char *msg,
                              size_t msg_len) {
  *ring_s = *ring_n = 0;
  if (g->global_nx < 0 || g->global_ny < 0 || g->ghost < 0)
    return gr_invalid(msg, msg_len,
                      "Invalid grid: global_nx, global_ny and ghost must be 0 or more (got %d, "
                      "%d, %d).",
                      g->global_nx, g->global_ny, g->ghost);
  if (g->i0 != 0 || (g->global_nx != 0 && g->global_nx != g->nx))
    return gr_invalid(msg, msg_len,
                      "The %s splits a domain along y only, into strips of whole rows%s: this "
                      "piece starts at column %d and has %d of %d columns; give i0 = 0 and nx = "
                      "global_nx.",
                      core, split_why, g->i0, g->nx, g->global_nx);
  long long gny = g->global_ny > 0 ? g->global_ny : g->ny;
  if (g->j0 < 0 || (g->global_ny <= 0 && g->j0 != 0) || (long long)g->j0 + g->ny > gny)
    return gr_invalid(msg, msg_len,
                      "Invalid grid: the strip of %d rows at row %d reaches beyond the domain of "
                      "%lld rows; give global_ny of the whole domain.",
                      g->ny, g->j0, gny);
  int south = g->j0 > 0, north = (long long)g->j0 + g->ny < gny;
  if ((south || north) && g->ghost < need)
    return gr_invalid(msg, msg_len,
                      "Invalid grid: a %s piece with neighbours needs a ghost ring of at least %d "
                      "rows %s (got ghost = %d); set grid.ghost to %d.",
                      core, need, need_for, g->ghost, need);
  if ((south || north) && g->ny < g->ghost)
    return gr_invalid(msg, msg_len,
                      "Invalid grid: a %s piece of %d rows is narrower than its ghost ring of %d "
                      "rows; split the domain into fewer pieces.",
                      core, g->ny, g->ghost);
  *ring_s = south ? g->ghost : 0;
  *ring_n = north ? g->ghost : 0;
  return GR_OK;
}

gr_status gr_grid_piece_check(const gr_grid *g, const char *core, int need, const char *need_for,
                              int origin_checked, int ring[4], char *msg, size_t msg_len) {
  long long gnx = g->global_nx > 0 ? g->global_nx : g->nx;
  long long gny = g->global_ny > 0 ? g->global_ny : g->ny;
  int whole_x = g->global_nx <= 0, whole_y = g->global_ny <= 0;
  memset(ring, 0, 4 * sizeof(int));
  if (!origin_checked && (g->global_nx < 0 || g->global_ny < 0 || g->ghost < 0))
    return gr_invalid(
        msg, msg_len,
        "Invalid grid: global_nx, global_ny and ghost must be 0 or more (got %d, %d, %d).",
        g->global_nx, g->global_ny, g->ghost);
  if (origin_checked &&
      (g->global_nx < 0 || g->global_ny < 0 || g->ghost < 0 || g->i0 < 0 || g->j0 < 0))
    return gr_invalid(msg, msg_len,
                      "Invalid grid: i0, j0, global_nx, global_ny and ghost must be 0 or more "
                      "(got %d, %d, %d, %d, %d).",
                      g->i0, g->j0, g->global_nx, g->global_ny, g->ghost);
  if ((origin_checked && ((whole_x && g->i0 != 0) || (whole_y && g->j0 != 0))) ||
      (!whole_x && (long long)g->i0 + g->nx > gnx) || (!whole_y && (long long)g->j0 + g->ny > gny))
    return gr_invalid(msg, msg_len,
                      "Invalid grid: the piece of %d x %d points at (%d, %d) reaches beyond the "
                      "domain of %lld x %lld points; give global_nx and global_ny of the whole "
                      "domain.",
                      g->nx, g->ny, g->i0, g->j0, gnx, gny);
  if (!whole_x) {
    ring[0] = g->i0 > 0 ? need : 0;
    ring[1] = (long long)g->i0 + g->nx < gnx ? need : 0;
  }
  if (!whole_y) {
    ring[2] = g->j0 > 0 ? need : 0;
    ring[3] = (long long)g->j0 + g->ny < gny ? need : 0;
  }
  int any = ring[0] || ring[1] || ring[2] || ring[3];
  if (any && g->ghost != need)
    return gr_invalid(msg, msg_len,
                      "Invalid grid: a %s piece with neighbours needs a ghost ring of %d points%s "
                      "(got ghost = %d); set grid.ghost to %d.",
                      core, need, need_for, g->ghost, need);
  if (((ring[0] || ring[1]) && g->nx < need) || ((ring[2] || ring[3]) && g->ny < need))
    return gr_invalid(msg, msg_len,
                      "Invalid grid: a %s piece of %d x %d points is narrower than its ghost ring "
                      "of %d toward a neighbour; split the domain into fewer pieces.",
                      core, g->nx, g->ny, need);
  return GR_OK;
}

/* The transform's part of gr_mesh_validate. */
static gr_status gr_mesh_transform_check(const double *T, char *msg, size_t msg_len) {
  for (int k = 0; k < 16; ++k)
    if (!isfinite(T[k]))
      return gr_invalid(msg, msg_len,
                        "Invalid mesh: transform element %d (column %d, row %d) is %g; the "
                        "transform must be finite.",
                        k, k / 4, k % 4, T[k]);
  double bound = 0.0, det = gr_det4(T, &bound);
  if (!(det > 1e-12 * bound))
    return gr_invalid(msg, msg_len,
                      "Invalid mesh: the transform is singular (determinant %g); it must map the "
                      "object's frame to the world invertibly (no zero scale).",
                      det);
  return GR_OK;
}

void gr_mesh_memo_free(gr_mesh_memo *memo) {
  if (!memo)
    return;
  free(memo->vertices);
  free(memo->triangles);
  memset(memo, 0, sizeof(*memo));
}

gr_status gr_mesh_check(gr_mesh_memo *memo, const gr_mesh *m, int closed, char *msg,
                        size_t msg_len) {
  if (!memo)
    return gr_mesh_validate(m, closed, msg, msg_len);
  if (m && m->vertices && m->triangles && memo->vertices && memo->nvertices == m->nvertices &&
      memo->ntriangles == m->ntriangles && memo->closed >= (closed != 0) &&
      memcmp(memo->vertices, m->vertices, (size_t)m->nvertices * 3 * sizeof(float)) == 0 &&
      memcmp(memo->triangles, m->triangles, (size_t)m->ntriangles * 3 * sizeof(int)) == 0)
    return gr_mesh_transform_check(m->transform, msg, msg_len);
  gr_mesh_memo_free(memo);
  gr_status st = gr_mesh_validate(m, closed, msg, msg_len);
  if (st != GR_OK)
    return st;
  size_t vb = (size_t)m->nvertices * 3 * sizeof(float),
         tb = (size_t)m->ntriangles * 3 * sizeof(int);
  memo->vertices = malloc(vb);
  memo->triangles = malloc(tb);
  if (!memo->vertices || !memo->triangles) {
    gr_mesh_memo_free(memo); /* no memo: the next call checks in full */
    return GR_OK;
  }
  memcpy(memo->vertices, m->vertices, vb);
  memcpy(memo->triangles, m->triangles, tb);
  memo->nvertices = m->nvertices;
  memo->ntriangles = m->ntriangles;
  memo->closed = closed != 0;
  return GR_OK;
}

/* The vertices' part of gr_mesh_validate: every coordinate finite. */
static gr_status gr_mesh_vertices_check(const gr_mesh *m, char *msg, size_t msg_len) {
  for (int v = 0; v < m->nvertices; ++v)
    for (int a = 0; a < 3; ++a)
      if (!isfinite(m->vertices[3 * v + a]))
        return gr_invalid(msg, msg_len,
                          "Invalid mesh: vertex %d has %s = %g; vertex coordinates must be "
                          "finite metres.",
                          v, gr_axis[a], (double)m->vertices[3 * v + a]);
  return GR_OK;
}

/* Triangle t's part of gr_mesh_validate: its indices in range and its
 * corners not collinear. */
static gr_status gr_mesh_triangle_check(const gr_mesh *m, int t, char *msg, size_t msg_len) {
  const int *tri = m->triangles + 3 * t;
  for (int k = 0; k < 3; ++k)
    if (tri[k] < 0 || tri[k] >= m->nvertices)
      return gr_invalid(msg, msg_len,
                        "Invalid mesh: triangle %d refers to vertex %d, but the vertices are "
                        "0 to %d.",
                        t, tri[k], m->nvertices - 1);
  const float *p0 = m->vertices + 3 * tri[0], *p1 = m->vertices + 3 * tri[1],
              *p2 = m->vertices + 3 * tri[2];
  double e1[3], e2[3];
  for (int a = 0; a < 3; ++a) {
    e1[a] = (double)p1[a] - p0[a];
    e2[a] = (double)p2[a] - p0[a];
  }
  double cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2],
         cz = e1[0] * e2[1] - e1[1] * e2[0];
  double cross = sqrt(cx * cx + cy * cy + cz * cz);
  double l1 = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
  double l2 = sqrt(e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2]);
  /* Relative to the edge lengths: collinear corners, not small ones. */
  if (!(cross > 1e-12 * l1 * l2))
    return gr_invalid(msg, msg_len,
                      "Invalid mesh: triangle %d (vertices %d, %d, %d) has zero area; remove "
                      "it or move its corners apart.",
                      t, tri[0], tri[1], tri[2]);
  return GR_OK;
}

/* The 3 * ntriangles edges of m in gr_edge_cmp's order: counted into
 * buckets by their lower vertex in triangle order (a stable counting sort,
 * linear: a simulation checks its objects every step), then each bucket, a
 * vertex's few edges, sorted by the upper vertex, stably. NULL when out of
 * memory. */
static gr_edge *gr_mesh_sorted_edges(const gr_mesh *m) {
  size_t ne = 3 * (size_t)m->ntriangles;
  gr_edge *edges = malloc(ne * sizeof(*edges));
  size_t *start = calloc((size_t)m->nvertices + 1, sizeof(*start));
  if (!edges || !start) {
    free(edges);
    free(start);
    return NULL;
  }
  for (size_t q = 0; q < ne; ++q) {
    int a = m->triangles[q], b = m->triangles[q % 3 == 2 ? q - 2 : q + 1];
    ++start[(a < b ? a : b) + 1];
  }
  for (int v = 0; v < m->nvertices; ++v)
    start[v + 1] += start[v];
  for (int t = 0; t < m->ntriangles; ++t)
    for (int k = 0; k < 3; ++k) {
      int a = m->triangles[3 * t + k], b = m->triangles[3 * t + (k + 1) % 3];
      gr_edge *e = &edges[start[a < b ? a : b]++];
      e->lo = a < b ? a : b;
      e->hi = a < b ? b : a;
      e->forward = a < b;
      e->triangle = t;
    }
  for (size_t i = 0; i < ne;) {
    size_t n = 1;
    while (i + n < ne && edges[i + n].lo == edges[i].lo)
      ++n;
    if (n > 32) {
      qsort(edges + i, n, sizeof(*edges), gr_edge_cmp);
    } else {
      for (size_t a = i + 1; a < i + n; ++a) {
        gr_edge e = edges[a];
        size_t b = a;
        for (; b > i && gr_edge_cmp(&edges[b - 1], &e) > 0; --b)
          edges[b] = edges[b - 1];
        edges[b] = e;
      }
    }
    i += n;
  }
  free(start);
  return edges;
}

/* The closed surface's part of gr_mesh_validate, on the sorted edges:
 * every edge shared by exactly two triangles, run in opposite ways. */
static gr_status gr_mesh_edges_check(const gr_edge *edges, size_t ne, char *msg, size_t msg_len) {
  gr_status st = GR_OK;
  for (size_t i = 0; i < ne && st == GR_OK;) {
    size_t n = 1;
    while (i + n < ne && edges[i + n].lo == edges[i].lo && edges[i + n].hi == edges[i].hi)
      ++n;
    const gr_edge *e = &edges[i];
    if (n == 1)
      st = gr_invalid(msg, msg_len,
                      "Invalid mesh: the edge between vertices %d and %d belongs to triangle %d "
                      "only, so the surface is open there; close it (or check it as an open "
                      "mesh).",
                      e->lo, e->hi, e->triangle);
    else if (n > 2)
      st = gr_invalid(msg, msg_len,
                      "Invalid mesh: the edge between vertices %d and %d is shared by %zu "
                      "triangles (%d, %d, ...); a closed surface shares each edge between two.",
                      e->lo, e->hi, n, e[0].triangle, e[1].triangle);
    else if (e[0].forward == e[1].forward)
      st = gr_invalid(msg, msg_len,
                      "Invalid mesh: triangles %d and %d run the same way along their shared "
                      "edge (vertices %d and %d): the winding is inconsistent; flip one so that "
                      "every triangle is counter-clockwise seen from outside.",
                      e[0].triangle, e[1].triangle, e->lo, e->hi);
    i += n;
  }
  return st;
}

gr_status gr_mesh_validate(const gr_mesh *m, int closed, char *msg, size_t msg_len) {
  if (!m)
    return gr_invalid(msg, msg_len, "Invalid mesh: no mesh was given.");
  if (m->ntriangles < 1 || !m->triangles)
    return gr_invalid(msg, msg_len,
                      "Invalid mesh: it has %d triangles; give at least one triangle.",
                      m->ntriangles);
  if (m->nvertices < 3 || !m->vertices)
    return gr_invalid(msg, msg_len,
                      "Invalid mesh: it has %d vertices; a triangle needs at least three.",
                      m->nvertices);
  gr_status st = gr_mesh_vertices_check(m, msg, msg_len);
  for (int t = 0; st == GR_OK && t < m->ntriangles; ++t)
    st = gr_mesh_triangle_check(m, t, msg, msg_len);
  if (st == GR_OK)
    st = gr_mesh_transform_check(m->transform, msg, msg_len);
  if (st != GR_OK || !closed)
    return st;
  gr_edge *edges = gr_mesh_sorted_edges(m);
  if (!edges) {
    if (msg && msg_len)
      snprintf(msg, msg_len, "Out of host memory while checking a mesh of %d triangles.",
               m->ntriangles);
    return GR_ERR_OUT_OF_MEMORY;
  }
  st = gr_mesh_edges_check(edges, 3 * (size_t)m->ntriangles, msg, msg_len);
  free(edges);
  return st;
}

gr_status gr_points_validate(const gr_points *p, char *msg, size_t msg_len) {
  if (!p)
    return gr_invalid(msg, msg_len, "Invalid points: no points were given.");
  if (p->npoints < 0)
    return gr_invalid(msg, msg_len, "Invalid points: the count is %lld; it must be 0 or more.",
                      p->npoints);
  if (p->npoints > 0 && !p->positions)
    return gr_invalid(msg, msg_len, "Invalid points: %lld points but no positions were given.",
                      p->npoints);
  if (p->narrays < 0 || (p->narrays > 0 && !p->arrays))
    return gr_invalid(msg, msg_len,
                      "Invalid points: %d arrays announced but none given; pass the arrays or "
                      "set narrays to 0.",
                      p->narrays);
  for (long long i = 0; i < p->npoints; ++i)
    for (int a = 0; a < 3; ++a)
      if (!isfinite(p->positions[3 * i + a]))
        return gr_invalid(msg, msg_len,
                          "Invalid points: point %lld has %s = %g; positions must be finite "
                          "metres.",
                          i, gr_axis[a], (double)p->positions[3 * i + a]);
  for (int k = 0; k < p->narrays; ++k) {
    const gr_points_array *arr = &p->arrays[k];
    if (!arr->name || !arr->name[0])
      return gr_invalid(msg, msg_len, "Invalid points: array %d has no name; name every array.", k);
    for (int j = 0; j < k; ++j)
      if (p->arrays[j].name && strcmp(p->arrays[j].name, arr->name) == 0)
        return gr_invalid(msg, msg_len,
                          "Invalid points: arrays %d and %d are both named '%s'; array names "
                          "must be distinct.",
                          j, k, arr->name);
    if (arr->components < 1 || arr->components > 9)
      return gr_invalid(msg, msg_len, "Invalid points: array '%s' has %d components; give 1 to 9.",
                        arr->name, arr->components);
    if (p->npoints > 0 && !arr->values)
      return gr_invalid(msg, msg_len, "Invalid points: array '%s' has no values.", arr->name);
    for (long long i = 0; i < p->npoints; ++i)
      for (int c = 0; c < arr->components; ++c)
        if (!isfinite(arr->values[i * arr->components + c]))
          return gr_invalid(msg, msg_len,
                            "Invalid points: array '%s' has the value %g at point %lld "
                            "(component %d); values must be finite.",
                            arr->name, (double)arr->values[i * arr->components + c], i, c);
  }
  return GR_OK;
}

/* ------------------------------------------------------ parameter tables */

const gr_param_bound *gr_param_find(const gr_param_bound *table, int count, const char *property) {
  for (int k = 0; table && property && k < count; ++k)
    if (table[k].property && strcmp(table[k].property, property) == 0)
      return &table[k];
  return NULL;
}

int gr_param_accepts(const gr_param_bound *b, double core_value) {
  if (!b)
    return 0;
  double lo = b->min * b->to_core, hi = b->max * b->to_core;
  int above = b->min_open ? core_value > lo : core_value >= lo; /* false for NaN */
  return above && core_value <= hi && (!b->integer || core_value == floor(core_value));
}

double gr_param_clamp(const gr_param_bound *b, double user_value) {
  if (!b || user_value != user_value)
    return user_value;
  return user_value < b->min ? b->min : (user_value > b->max ? b->max : user_value);
}

void gr_param_explain(const gr_param_bound *b, double core_value, const char *what, char *msg,
                      size_t msg_len) {
  if (!b || !msg || !msg_len)
    return;
  const char *w = what ? what : "Invalid parameters";
  const char *sp = b->unit[0] ? " " : "";
  double user = core_value / b->to_core;
  if (b->integer)
    snprintf(msg, msg_len, "%s: %s must be a whole number from %g to %g (got %g).", w, b->property,
             b->min, b->max, user);
  else if (b->min_open)
    snprintf(msg, msg_len, "%s: %s must be above %g and at most %g%s%s (got %g%s%s).", w,
             b->property, b->min, b->max, sp, b->unit, user, sp, b->unit);
  else
    snprintf(msg, msg_len, "%s: %s must lie between %g and %g%s%s (got %g%s%s).", w, b->property,
             b->min, b->max, sp, b->unit, user, sp, b->unit);
}

/* The "is" wordings of gr_params_check_table for row b refusing v. */
static void gr_param_explain_is(const gr_param_bound *b, const char *hint, double v,
                                const char *what, gr_param_wording wording, char *msg,
                                size_t msg_len) {
  const char *sep = b->unit[0] ? " " : "";
  int whole = b->integer && wording != GR_PARAM_SAY_IS_RANGE &&
              !(wording == GR_PARAM_SAY_IS_OPEN_FIRST && b->min_open);
  if (whole)
    snprintf(msg, msg_len, "%s: %s%s is %.15g but must be a whole number from %.15g to %.15g.",
             what, b->property, hint, v, b->min_open ? b->min + 1.0 : b->min, b->max);
  else if (b->min_open)
    snprintf(msg, msg_len, "%s: %s%s is %.15g but must be above %.15g and at most %.15g%s%s.", what,
             b->property, hint, v, b->min, b->max, sep, b->unit);
  else
    snprintf(msg, msg_len, "%s: %s%s is %.15g but must lie between %.15g and %.15g%s%s.", what,
             b->property, hint, v, b->min, b->max, sep, b->unit);
}

gr_status gr_params_check_table(const gr_param_bound *table, const int *rows, int n,
                                const double *values, const char *what, const char *const *hints,
                                gr_param_wording wording, char *msg, size_t msg_len) {
  for (int k = 0; k < n; ++k) {
    int row = rows ? rows[k] : k;
    const gr_param_bound *b = &table[row];
    if (gr_param_accepts(b, values[k]))
      continue;
    if (wording == GR_PARAM_SAY_GOT)
      gr_param_explain(b, values[k], what, msg, msg_len);
    else if (msg && msg_len)
      gr_param_explain_is(b, hints && hints[row] ? hints[row] : "", values[k], what, wording, msg,
                          msg_len);
    return GR_ERR_INVALID_ARGUMENT;
  }
  return GR_OK;
}

gr_status gr_params_missing(const char *what, char *msg, size_t msg_len) {
  if (msg && msg_len)
    snprintf(msg, msg_len, "%s: no parameters were given.", what);
  return GR_ERR_INVALID_ARGUMENT;
}

/* ------------------------------------------------------------------ fields */

gr_status gr_field_check_range(const char *name, const float *values, size_t n, size_t nx,
                               double lo, double hi, const char *rule, char *msg, size_t msg_len) {
  if (!values && n > 0) {
    if (msg && msg_len)
      snprintf(msg, msg_len, "The field '%s' has no values (got NULL for %zu points); pass them.",
               name, n);
    return GR_ERR_INVALID_ARGUMENT;
  }
  size_t row = nx > 0 ? nx : (n > 0 ? n : 1);
  for (size_t c = 0; c < n; ++c) {
    double v = values[c];
    if (isfinite(v) && v >= lo && v <= hi)
      continue;
    if (msg && msg_len)
      snprintf(msg, msg_len, "The field '%s' has the value %g at point (%zu, %zu): %s.", name, v,
               c % row, c / row, rule);
    return GR_ERR_INVALID_ARGUMENT;
  }
  return GR_OK;
}

gr_status gr_state_check(const char *core, const char *fn, const void *bytes,
                         const gr_state_part *parts, int nparts) {
  for (int k = 0; k < nparts; ++k) {
    const gr_state_part *p = &parts[k];
    const size_t width = p->kind == 'f' ? 4 : 8;
    const unsigned char *at = (const unsigned char *)bytes + p->offset;
    for (size_t c = 0; c < p->count; ++c, at += width) {
      double v;
      long long w = 0;
      if (p->kind == 'f') {
        float f;
        memcpy(&f, at, sizeof(f));
        v = f;
      } else if (p->kind == 'd') {
        memcpy(&v, at, sizeof(v));
      } else {
        memcpy(&w, at, sizeof(w));
        v = (double)w;
      }
      if (isfinite(v) && v >= p->lo && v <= p->hi)
        continue;
      char value[48], range[96] = "";
      if (p->kind == 'l')
        snprintf(value, sizeof(value), "%lld", w);
      else
        snprintf(value, sizeof(value), "%g", v);
      if (p->lo > -HUGE_VAL || p->hi < HUGE_VAL)
        snprintf(range, sizeof(range), " and from %.9g to %.9g", p->lo, p->hi);
      return gr_set_error(NULL, GR_ERR_FORMAT,
                          "The %s state's %s has the value %s at entry %zu of %zu, where every "
                          "value is finite%s: the bytes are damaged; pass the bytes "
                          "gr_%s_state_save wrote.",
                          core, p->name, value, c, p->count, range, fn);
    }
  }
  return GR_OK;
}
