/* OpenCL runtime of the Graupel core: device choice, the shared context,
 * checked program/kernel/buffer helpers, and error reporting. */
#include "graupel/cl_runtime.h"
#include "graupel/memory.h"
#include "runtime_internal.h"

#include <ctype.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define GR_ERROR_LEN 16384
#define GR_MAX_SHARED 8
/* Kernels whose argument names a context remembers; beyond this the oldest
 * entry is reused, so a long session that creates kernels without end keeps
 * a fixed amount of memory. */
#define GR_ARG_CACHE 64
/* Buffers from this size on are checked against the memory the process can
 * get (two /proc reads); smaller ones cannot matter. */
#define GR_BUFFER_CHECKED ((size_t)1 << 20)

typedef struct gr_program_entry {
  char *key; /* name + '\n' + options */
  cl_program program;
} gr_program_entry;

/* The argument names of one kernel, in index order. An entry is only a hint:
 * a released kernel's handle may come back for another kernel, so a hit is
 * confirmed by asking the kernel for the name at the cached index. */
typedef struct gr_arg_entry {
  cl_kernel kernel;
  cl_uint nargs;
  char **names; /* nargs strings in one allocation after the pointers */
} gr_arg_entry;

struct gr_context {
  int refcount; /* guarded by gr_shared_lock */
  int shared;
  cl_platform_id platform;
  cl_device_id device;
  cl_context cl;
  cl_command_queue queue;
  char device_name[128];
  char platform_name[128];
  int is_gpu;
  int host_memory; /* the device's buffers are host memory (gr_device_info) */
  cl_ulong max_alloc, global_mem;
  size_t local2d[2]; /* default work-group shape for 2-D kernels */
  gr_log_fn log;
  void *log_user;
  pthread_mutex_t lock;       /* guards programs and the argument cache */
  gr_program_entry *programs; /* grows: one entry per (source, options) */
  int nprograms, capacity;
  gr_arg_entry args[GR_ARG_CACHE];
  int next_arg; /* the entry replaced when the cache is full */
};

/* The only global mutable state: the table of shared contexts (one per
 * device), and the per-thread text of the latest error. Error text is per
 * thread, not per context, because filters share one context: a handle keeps
 * its own copy with gr_error_keep. */
static pthread_mutex_t gr_shared_lock = PTHREAD_MUTEX_INITIALIZER;
static gr_context *gr_shared[GR_MAX_SHARED];
static _Thread_local char gr_thread_error[GR_ERROR_LEN];

const char *gr_status_string(gr_status st) {
  switch (st) {
  case GR_OK:
    return "GR_OK";
  case GR_ERR_INVALID_ARGUMENT:
    return "GR_ERR_INVALID_ARGUMENT";
  case GR_ERR_NO_PLATFORM:
    return "GR_ERR_NO_PLATFORM";
  case GR_ERR_NO_DEVICE:
    return "GR_ERR_NO_DEVICE";
  case GR_ERR_OPENCL:
    return "GR_ERR_OPENCL";
  case GR_ERR_BUILD:
    return "GR_ERR_BUILD";
  case GR_ERR_OUT_OF_MEMORY:
    return "GR_ERR_OUT_OF_MEMORY";
  case GR_ERR_TOO_LARGE:
    return "GR_ERR_TOO_LARGE";
  case GR_ERR_IO:
    return "GR_ERR_IO";
  case GR_ERR_FORMAT:
    return "GR_ERR_FORMAT";
  case GR_ERR_ABORTED:
    return "GR_ERR_ABORTED";
  }
  return "GR_ERR_UNKNOWN";
}

const char *gr_version_string(void) {
#define GR_STR2(x) #x
#define GR_STR(x) GR_STR2(x)
  return GR_STR(GRAUPEL_VERSION_MAJOR) "." GR_STR(GRAUPEL_VERSION_MINOR) "." GR_STR(
      GRAUPEL_VERSION_PATCH);
}

/* The field vocabulary: array name, components and SI unit of every
 * gr_field, in enum order. VTK arrays, EXR channels and the docs pages use these
 * names and units; "1" is dimensionless. */
static const struct gr_field_row {
  gr_field field; /* checked against the row's index by the tests */
  const char *name;
  int components;
  const char *unit;
} gr_fields[GR_FIELD_COUNT] = {
    {GR_FIELD_ELEVATION, "elevation", 1, "m"},
    {GR_FIELD_SNOW_DEPTH, "snow_depth", 1, "m"},
    {GR_FIELD_SNOW_DENSITY, "snow_density", 1, "kg/m^3"},
    {GR_FIELD_SNOW_SURFACE, "snow_surface", 1, "m"},
    {GR_FIELD_OVERLAP, "overlap", 1, "m"},
    {GR_FIELD_EXPOSURE, "exposure", 1, "1"},
    {GR_FIELD_WATER_DEPTH, "water_depth", 1, "m"},
    {GR_FIELD_WATER_SURFACE, "water_surface", 1, "m"},
    {GR_FIELD_VELOCITY, "velocity", 3, "m/s"},
    {GR_FIELD_DISCHARGE, "discharge", 1, "m^2/s"},
    {GR_FIELD_INFILTRATED, "infiltrated", 1, "m"},
    {GR_FIELD_PERMEABILITY, "permeability", 1, "m/s"},
    {GR_FIELD_RAIN_RATE, "rain_rate", 1, "m/s"},
    {GR_FIELD_CONTACT, "contact", 1, "1"},
};

static const struct gr_field_row *gr_field_row_of(gr_field f) {
  return ((int)f >= 0 && (int)f < GR_FIELD_COUNT) ? &gr_fields[f] : NULL;
}

const char *gr_field_name(gr_field f) {
  const struct gr_field_row *r = gr_field_row_of(f);
  return r ? r->name : NULL;
}

int gr_field_from_name(const char *name) {
  if (!name)
    return -1;
  for (int i = 0; i < GR_FIELD_COUNT; ++i)
    if (strcmp(name, gr_fields[i].name) == 0)
      return (int)gr_fields[i].field;
  return -1;
}

int gr_field_components(gr_field f) {
  const struct gr_field_row *r = gr_field_row_of(f);
  return r ? r->components : 0;
}

const char *gr_field_unit(gr_field f) {
  const struct gr_field_row *r = gr_field_row_of(f);
  return r ? r->unit : NULL;
}

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
  for (int v = 0; v < m->nvertices; ++v)
    for (int a = 0; a < 3; ++a)
      if (!isfinite(m->vertices[3 * v + a]))
        return gr_invalid(msg, msg_len,
                          "Invalid mesh: vertex %d has %s = %g; vertex coordinates must be "
                          "finite metres.",
                          v, gr_axis[a], (double)m->vertices[3 * v + a]);
  for (int t = 0; t < m->ntriangles; ++t) {
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
  }
  gr_status st = gr_mesh_transform_check(m->transform, msg, msg_len);
  if (st != GR_OK)
    return st;
  if (!closed)
    return GR_OK;

  /* The edges in gr_edge_cmp's order: counted into buckets by their lower
   * vertex in triangle order (a stable counting sort, linear: a simulation
   * checks its objects every step), then each bucket, a vertex's few edges,
   * sorted by the upper vertex, stably. */
  size_t ne = 3 * (size_t)m->ntriangles;
  gr_edge *edges = malloc(ne * sizeof(*edges));
  size_t *start = calloc((size_t)m->nvertices + 1, sizeof(*start));
  if (!edges || !start) {
    free(edges);
    free(start);
    if (msg && msg_len)
      snprintf(msg, msg_len, "Out of host memory while checking a mesh of %d triangles.",
               m->ntriangles);
    return GR_ERR_OUT_OF_MEMORY;
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
  st = GR_OK;
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

/* ------------------------------------------------------------------ errors */

static void gr_log(const gr_context *ctx, gr_log_level level, const char *msg) {
  if (ctx && ctx->log)
    ctx->log(ctx->log_user, level, msg);
}

gr_status gr_set_error(const gr_context *ctx, gr_status st, const char *fmt, ...) {
  /* Formatted aside first: callers may pass the current error as an argument
   * ("%s", gr_last_error(ctx)) to add context to it. */
  static _Thread_local char scratch[GR_ERROR_LEN];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(scratch, sizeof(scratch), fmt, ap);
  va_end(ap);
  memcpy(gr_thread_error, scratch, sizeof(gr_thread_error));
  /* Not logged as well: the caller gets the status and reports the sentence
   * once (a filter as its one error); the log is for what is not an error. */
  (void)ctx;
  return st;
}

gr_status gr_error_keep(char *dst, size_t len, gr_status st) {
  if (st != GR_OK && dst && len > 0 && dst != gr_thread_error)
    snprintf(dst, len, "%s", gr_thread_error);
  return st;
}

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

const char *gr_last_error(const gr_context *ctx) {
  (void)ctx; /* kept for compatibility: the text is the calling thread's */
  return gr_thread_error;
}

const char *gr_cl_error_name(cl_int err) {
  switch (err) {
#define GR_CASE(e)                                                                                 \
  case e:                                                                                          \
    return #e;
    GR_CASE(CL_SUCCESS)
    GR_CASE(CL_DEVICE_NOT_FOUND)
    GR_CASE(CL_DEVICE_NOT_AVAILABLE)
    GR_CASE(CL_COMPILER_NOT_AVAILABLE)
    GR_CASE(CL_MEM_OBJECT_ALLOCATION_FAILURE)
    GR_CASE(CL_OUT_OF_RESOURCES)
    GR_CASE(CL_OUT_OF_HOST_MEMORY)
    GR_CASE(CL_PROFILING_INFO_NOT_AVAILABLE)
    GR_CASE(CL_MEM_COPY_OVERLAP)
    GR_CASE(CL_IMAGE_FORMAT_MISMATCH)
    GR_CASE(CL_IMAGE_FORMAT_NOT_SUPPORTED)
    GR_CASE(CL_BUILD_PROGRAM_FAILURE)
    GR_CASE(CL_MAP_FAILURE)
    GR_CASE(CL_MISALIGNED_SUB_BUFFER_OFFSET)
    GR_CASE(CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST)
    GR_CASE(CL_COMPILE_PROGRAM_FAILURE)
    GR_CASE(CL_LINKER_NOT_AVAILABLE)
    GR_CASE(CL_LINK_PROGRAM_FAILURE)
    GR_CASE(CL_DEVICE_PARTITION_FAILED)
    GR_CASE(CL_KERNEL_ARG_INFO_NOT_AVAILABLE)
    GR_CASE(CL_INVALID_VALUE)
    GR_CASE(CL_INVALID_DEVICE_TYPE)
    GR_CASE(CL_INVALID_PLATFORM)
    GR_CASE(CL_INVALID_DEVICE)
    GR_CASE(CL_INVALID_CONTEXT)
    GR_CASE(CL_INVALID_QUEUE_PROPERTIES)
    GR_CASE(CL_INVALID_COMMAND_QUEUE)
    GR_CASE(CL_INVALID_HOST_PTR)
    GR_CASE(CL_INVALID_MEM_OBJECT)
    GR_CASE(CL_INVALID_IMAGE_FORMAT_DESCRIPTOR)
    GR_CASE(CL_INVALID_IMAGE_SIZE)
    GR_CASE(CL_INVALID_SAMPLER)
    GR_CASE(CL_INVALID_BINARY)
    GR_CASE(CL_INVALID_BUILD_OPTIONS)
    GR_CASE(CL_INVALID_PROGRAM)
    GR_CASE(CL_INVALID_PROGRAM_EXECUTABLE)
    GR_CASE(CL_INVALID_KERNEL_NAME)
    GR_CASE(CL_INVALID_KERNEL_DEFINITION)
    GR_CASE(CL_INVALID_KERNEL)
    GR_CASE(CL_INVALID_ARG_INDEX)
    GR_CASE(CL_INVALID_ARG_VALUE)
    GR_CASE(CL_INVALID_ARG_SIZE)
    GR_CASE(CL_INVALID_KERNEL_ARGS)
    GR_CASE(CL_INVALID_WORK_DIMENSION)
    GR_CASE(CL_INVALID_WORK_GROUP_SIZE)
    GR_CASE(CL_INVALID_WORK_ITEM_SIZE)
    GR_CASE(CL_INVALID_GLOBAL_OFFSET)
    GR_CASE(CL_INVALID_EVENT_WAIT_LIST)
    GR_CASE(CL_INVALID_EVENT)
    GR_CASE(CL_INVALID_OPERATION)
    GR_CASE(CL_INVALID_GL_OBJECT)
    GR_CASE(CL_INVALID_BUFFER_SIZE)
    GR_CASE(CL_INVALID_MIP_LEVEL)
    GR_CASE(CL_INVALID_GLOBAL_WORK_SIZE)
    GR_CASE(CL_INVALID_PROPERTY)
#undef GR_CASE
  case -1001:
    return "CL_PLATFORM_NOT_FOUND_KHR";
  }
  return "an unknown OpenCL error";
}

gr_status gr_cl_check(const gr_context *ctx, cl_int err, const char *what) {
  if (err == CL_SUCCESS)
    return GR_OK;
  gr_status st = (err == CL_MEM_OBJECT_ALLOCATION_FAILURE || err == CL_OUT_OF_HOST_MEMORY ||
                  err == CL_OUT_OF_RESOURCES)
                     ? GR_ERR_OUT_OF_MEMORY
                     : GR_ERR_OPENCL;
  return gr_set_error(ctx, st, "%s failed: %s (%d).", what, gr_cl_error_name(err), (int)err);
}

/* ----------------------------------------------------------------- devices */

static void gr_device_string(cl_device_id d, cl_device_info what, char *buf, size_t len) {
  buf[0] = '\0';
  if (clGetDeviceInfo(d, what, len, buf, NULL) != CL_SUCCESS)
    buf[0] = '\0';
  buf[len - 1] = '\0';
}

static void gr_fill_device_info(cl_platform_id p, cl_device_id d, gr_device_info *info) {
  cl_device_type type = 0;
  cl_uint cu = 0;
  cl_ulong mem = 0, alloc = 0;
  memset(info, 0, sizeof(*info));
  gr_device_string(d, CL_DEVICE_NAME, info->name, sizeof(info->name));
  gr_device_string(d, CL_DEVICE_VENDOR, info->vendor, sizeof(info->vendor));
  gr_device_string(d, CL_DEVICE_VERSION, info->version, sizeof(info->version));
  if (clGetPlatformInfo(p, CL_PLATFORM_NAME, sizeof(info->platform), info->platform, NULL) !=
      CL_SUCCESS)
    info->platform[0] = '\0';
  info->platform[sizeof(info->platform) - 1] = '\0';
  clGetDeviceInfo(d, CL_DEVICE_TYPE, sizeof(type), &type, NULL);
  clGetDeviceInfo(d, CL_DEVICE_MAX_COMPUTE_UNITS, sizeof(cu), &cu, NULL);
  clGetDeviceInfo(d, CL_DEVICE_GLOBAL_MEM_SIZE, sizeof(mem), &mem, NULL);
  clGetDeviceInfo(d, CL_DEVICE_MAX_MEM_ALLOC_SIZE, sizeof(alloc), &alloc, NULL);
  info->is_gpu = (type & CL_DEVICE_TYPE_GPU) != 0;
  info->is_cpu = (type & CL_DEVICE_TYPE_CPU) != 0;
  info->compute_units = (int)cu;
  info->global_mem_bytes = mem;
  info->max_alloc_bytes = alloc;
  cl_bool unified = CL_FALSE;
  if (clGetDeviceInfo(d, CL_DEVICE_HOST_UNIFIED_MEMORY, sizeof(unified), &unified, NULL) !=
      CL_SUCCESS)
    unified = CL_FALSE;
  info->host_memory = info->is_cpu || unified == CL_TRUE;
}

/* Visits every device of every platform; stops when visit returns nonzero. */
typedef int (*gr_device_visit)(void *user, cl_platform_id p, cl_device_id d);

static gr_status gr_for_each_device(gr_device_visit visit, void *user) {
  cl_uint np = 0;
  cl_int err = clGetPlatformIDs(0, NULL, &np);
  if (err == -1001 /* CL_PLATFORM_NOT_FOUND_KHR */ || (err == CL_SUCCESS && np == 0))
    return gr_set_error(NULL, GR_ERR_NO_PLATFORM,
                        "No OpenCL platform is installed: install an OpenCL "
                        "driver (for the CPU, Debian's pocl-opencl-icd) and "
                        "check that /etc/OpenCL/vendors lists it.");
  if (err != CL_SUCCESS)
    return gr_cl_check(NULL, err, "Listing the OpenCL platforms");
  cl_platform_id plats[16];
  if (np > 16)
    np = 16;
  err = clGetPlatformIDs(np, plats, NULL);
  if (err != CL_SUCCESS)
    return gr_cl_check(NULL, err, "Listing the OpenCL platforms");
  for (cl_uint p = 0; p < np; ++p) {
    cl_uint nd = 0;
    if (clGetDeviceIDs(plats[p], CL_DEVICE_TYPE_ALL, 0, NULL, &nd) != CL_SUCCESS || nd == 0)
      continue;
    cl_device_id devs[32];
    if (nd > 32)
      nd = 32;
    if (clGetDeviceIDs(plats[p], CL_DEVICE_TYPE_ALL, nd, devs, NULL) != CL_SUCCESS)
      continue;
    for (cl_uint d = 0; d < nd; ++d)
      if (visit(user, plats[p], devs[d]))
        return GR_OK;
  }
  return GR_OK;
}

typedef struct gr_list_state {
  gr_device_info *infos;
  int max, count;
} gr_list_state;

static int gr_list_visit(void *user, cl_platform_id p, cl_device_id d) {
  gr_list_state *s = user;
  if (s->count < s->max)
    gr_fill_device_info(p, d, &s->infos[s->count]);
  s->count++;
  return 0;
}

gr_status gr_device_list(gr_device_info *infos, int max, int *count) {
  if (!count || max < 0 || (max > 0 && !infos))
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_device_list needs a count pointer and room for "
                        "max entries.");
  gr_list_state s = {infos, max, 0};
  gr_status st = gr_for_each_device(gr_list_visit, &s);
  *count = s.count;
  return st;
}

/* Device choice: the request is "gpu", "cpu", "auto" or a name substring,
 * optionally with ":N", the N-th (from 0) device that the request matches in
 * the order clinfo -l lists them: several identical GPUs have one name, and
 * a process that drives them all (graupel-bench --devices, one MPI rank per
 * GPU) needs each by its place. */
typedef struct gr_pick_state {
  const char *want; /* normalised request */
  int nth;          /* the ":N" of the request; 0 without one */
  int gpus, cpus, matches, anys;
  cl_platform_id first_gpu_p, first_cpu_p, first_any_p, match_p;
  cl_device_id first_gpu, first_cpu, first_any, match;
} gr_pick_state;

static int gr_contains_nocase(const char *hay, const char *needle) {
  size_t n = strlen(needle);
  for (; *hay; ++hay) {
    size_t i = 0;
    while (i < n && hay[i] && tolower((unsigned char)hay[i]) == tolower((unsigned char)needle[i]))
      ++i;
    if (i == n)
      return 1;
  }
  return n == 0;
}

static int gr_pick_visit(void *user, cl_platform_id p, cl_device_id d) {
  gr_pick_state *s = user;
  gr_device_info info;
  gr_fill_device_info(p, d, &info);
  if (s->anys++ == s->nth) {
    s->first_any = d;
    s->first_any_p = p;
  }
  if (info.is_gpu && s->gpus++ == s->nth) {
    s->first_gpu = d;
    s->first_gpu_p = p;
  }
  if (info.is_cpu && s->cpus++ == s->nth) {
    s->first_cpu = d;
    s->first_cpu_p = p;
  }
  if (s->want[0] &&
      (gr_contains_nocase(info.name, s->want) || gr_contains_nocase(info.platform, s->want)) &&
      s->matches++ == s->nth) {
    s->match = d;
    s->match_p = p;
  }
  return 0;
}

/* Splits "spec:N" into spec (copied to base) and N; *nth = 0 and base =
 * the whole request when there is no ":digits" ending. */
static void gr_split_request(const char *req, char *base, size_t len, int *nth) {
  *nth = 0;
  snprintf(base, len, "%s", req);
  char *colon = strrchr(base, ':');
  if (!colon || !colon[1] || strlen(colon + 1) > 6)
    return;
  for (const char *c = colon + 1; *c; ++c)
    if (!isdigit((unsigned char)*c))
      return;
  *nth = atoi(colon + 1);
  *colon = '\0';
}

static const char *gr_effective_request(const gr_context_options *opt) {
  const char *req = opt ? opt->device : NULL;
  if (!req || !req[0] || strcmp(req, "auto") == 0) {
    req = getenv("GRAUPEL_DEVICE");
    if (!req || !req[0])
      req = "auto";
  }
  return req;
}

static gr_status gr_pick_device(const gr_context_options *opt, cl_platform_id *pp,
                                cl_device_id *pd) {
  const char *full = gr_effective_request(opt);
  char req[256];
  gr_pick_state s;
  memset(&s, 0, sizeof(s));
  gr_split_request(full, req, sizeof(req), &s.nth);
  s.want = "";
  int want_gpu = strcmp(req, "gpu") == 0 || strcmp(req, "GPU") == 0;
  int want_cpu = strcmp(req, "cpu") == 0 || strcmp(req, "CPU") == 0;
  int want_auto = strcmp(req, "auto") == 0 || req[0] == '\0';
  if (!want_gpu && !want_cpu && !want_auto)
    s.want = req;
  gr_status st = gr_for_each_device(gr_pick_visit, &s);
  if (st != GR_OK)
    return st;
  if (want_gpu) {
    *pd = s.first_gpu;
    *pp = s.first_gpu_p;
  } else if (want_cpu) {
    *pd = s.first_cpu;
    *pp = s.first_cpu_p;
  } else if (want_auto) {
    /* "auto:N": the N-th GPU where there are GPUs, else the N-th CPU device. */
    int gpus = s.gpus > 0, cpus = !gpus && s.cpus > 0;
    *pd = gpus ? s.first_gpu : cpus ? s.first_cpu : s.first_any;
    *pp = gpus ? s.first_gpu_p : cpus ? s.first_cpu_p : s.first_any_p;
  } else {
    *pd = s.match;
    *pp = s.match_p;
  }
  if (!*pd)
    return gr_set_error(NULL, GR_ERR_NO_DEVICE,
                        "No OpenCL device matches the request '%s' (from %s): use 'gpu', "
                        "'cpu', 'auto' or part of a device name that clinfo -l shows, with "
                        "':N' for the N-th such device from 0.",
                        full,
                        (opt && opt->device && opt->device[0] && strcmp(opt->device, "auto"))
                            ? "the device option"
                            : "GRAUPEL_DEVICE");
  return GR_OK;
}

/* ---------------------------------------------------------------- contexts */

void gr_context_options_init(gr_context_options *opt) {
  if (opt)
    memset(opt, 0, sizeof(*opt));
}

static void gr_context_free(gr_context *ctx) {
  for (int i = 0; i < GR_ARG_CACHE; ++i)
    free(ctx->args[i].names);
  for (int i = 0; i < ctx->nprograms; ++i) {
    clReleaseProgram(ctx->programs[i].program);
    free(ctx->programs[i].key);
  }
  free(ctx->programs);
  if (ctx->queue)
    clReleaseCommandQueue(ctx->queue);
  if (ctx->cl)
    clReleaseContext(ctx->cl);
  pthread_mutex_destroy(&ctx->lock);
  free(ctx);
}

static gr_status gr_context_open(const gr_context_options *opt, cl_platform_id p, cl_device_id d,
                                 gr_context **out) {
  cl_int err = CL_SUCCESS;
  gr_context *ctx = calloc(1, sizeof(*ctx));
  if (!ctx)
    return gr_set_error(NULL, GR_ERR_OUT_OF_MEMORY, "Out of host memory while creating a context.");
  pthread_mutex_init(&ctx->lock, NULL);
  ctx->refcount = 1;
  ctx->platform = p;
  ctx->device = d;
  if (opt) {
    ctx->log = opt->log;
    ctx->log_user = opt->log_user;
  }
  gr_device_info info;
  gr_fill_device_info(p, d, &info);
  snprintf(ctx->device_name, sizeof(ctx->device_name), "%s", info.name);
  snprintf(ctx->platform_name, sizeof(ctx->platform_name), "%s", info.platform);
  ctx->is_gpu = info.is_gpu;
  ctx->host_memory = info.host_memory;
  ctx->max_alloc = info.max_alloc_bytes;
  /* A fixed work-group shape for every 2-D launch. Left to the driver, PoCL
   * picks one per global size and JIT-compiles and caches a work-group
   * function for each: slow, and memory that grows with every new grid size.
   * GPUs get square tiles, CPUs rows. */
  size_t max_wg = 0;
  clGetDeviceInfo(d, CL_DEVICE_MAX_WORK_GROUP_SIZE, sizeof(max_wg), &max_wg, NULL);
  ctx->local2d[0] = info.is_gpu ? 16 : 64;
  ctx->local2d[1] = info.is_gpu ? 16 : 1;
  while (max_wg > 0 && ctx->local2d[0] * ctx->local2d[1] > max_wg) {
    if (ctx->local2d[1] > 1)
      ctx->local2d[1] /= 2;
    else
      ctx->local2d[0] /= 2;
  }
  ctx->global_mem = info.global_mem_bytes;

  cl_context_properties props[] = {CL_CONTEXT_PLATFORM, (cl_context_properties)p, 0};
  ctx->cl = clCreateContext(props, 1, &d, NULL, NULL, &err);
  if (err != CL_SUCCESS) {
    gr_status st = gr_cl_check(NULL, err, "Creating the OpenCL context");
    gr_context_free(ctx);
    return st;
  }
  /* clCreateCommandQueue is deprecated in 2.0 but is what 1.2 devices have. */
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
#endif
  ctx->queue = clCreateCommandQueue(ctx->cl, d, 0, &err);
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
  if (err != CL_SUCCESS) {
    gr_status st = gr_cl_check(NULL, err, "Creating the OpenCL command queue");
    gr_context_free(ctx);
    return st;
  }
  char line[400];
  snprintf(line, sizeof(line), "Graupel uses OpenCL device '%s' (%s).", ctx->device_name,
           ctx->platform_name);
  gr_log(ctx, GR_LOG_INFO, line);
  *out = ctx;
  return GR_OK;
}

gr_status gr_context_create(const gr_context_options *opt, gr_context **out) {
  if (!out)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_context_create needs a place for the context.");
  *out = NULL;
  cl_platform_id p = NULL;
  cl_device_id d = NULL;
  gr_status st = gr_pick_device(opt, &p, &d);
  if (st != GR_OK)
    return st;
  return gr_context_open(opt, p, d, out);
}

gr_status gr_context_acquire(const gr_context_options *opt, gr_context **out) {
  if (!out)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_context_acquire needs a place for the context.");
  *out = NULL;
  cl_platform_id p = NULL;
  cl_device_id d = NULL;
  gr_status st = gr_pick_device(opt, &p, &d);
  if (st != GR_OK)
    return st;
  pthread_mutex_lock(&gr_shared_lock);
  for (int i = 0; i < GR_MAX_SHARED; ++i)
    if (gr_shared[i] && gr_shared[i]->device == d) {
      gr_shared[i]->refcount++;
      *out = gr_shared[i];
      pthread_mutex_unlock(&gr_shared_lock);
      return GR_OK;
    }
  int slot = -1;
  for (int i = 0; i < GR_MAX_SHARED && slot < 0; ++i)
    if (!gr_shared[i])
      slot = i;
  if (slot < 0) {
    pthread_mutex_unlock(&gr_shared_lock);
    return gr_set_error(NULL, GR_ERR_TOO_LARGE, "More than %d OpenCL devices are in use at once.",
                        GR_MAX_SHARED);
  }
  st = gr_context_open(opt, p, d, out);
  if (st == GR_OK) {
    (*out)->shared = 1;
    gr_shared[slot] = *out;
  }
  pthread_mutex_unlock(&gr_shared_lock);
  return st;
}

gr_context *gr_context_retain(gr_context *ctx) {
  if (ctx) {
    pthread_mutex_lock(&gr_shared_lock);
    ctx->refcount++;
    pthread_mutex_unlock(&gr_shared_lock);
  }
  return ctx;
}

void gr_context_release(gr_context *ctx) {
  if (!ctx)
    return;
  pthread_mutex_lock(&gr_shared_lock);
  int last = --ctx->refcount == 0;
  if (last && ctx->shared)
    for (int i = 0; i < GR_MAX_SHARED; ++i)
      if (gr_shared[i] == ctx)
        gr_shared[i] = NULL;
  pthread_mutex_unlock(&gr_shared_lock);
  if (last)
    gr_context_free(ctx);
}

int gr_context_refcount(const gr_context *ctx) {
  if (!ctx)
    return 0;
  pthread_mutex_lock(&gr_shared_lock);
  int n = ctx->refcount;
  pthread_mutex_unlock(&gr_shared_lock);
  return n;
}

const char *gr_context_device_name(const gr_context *ctx) {
  return ctx ? ctx->device_name : "";
}
const char *gr_context_platform_name(const gr_context *ctx) {
  return ctx ? ctx->platform_name : "";
}
int gr_context_is_gpu(const gr_context *ctx) {
  return ctx ? ctx->is_gpu : 0;
}
cl_context gr_context_cl(const gr_context *ctx) {
  return ctx ? ctx->cl : NULL;
}
cl_command_queue gr_context_queue(const gr_context *ctx) {
  return ctx ? ctx->queue : NULL;
}
cl_device_id gr_context_device(const gr_context *ctx) {
  return ctx ? ctx->device : NULL;
}

gr_status gr_context_device_info(const gr_context *ctx, gr_device_info *info) {
  if (!ctx || !info)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_context_device_info needs a context and an info.");
  gr_fill_device_info(ctx->platform, ctx->device, info);
  return GR_OK;
}

/* ---------------------------------------------------------------- programs */

/* GRAUPEL_CL_OPTIONS adds build options to every program (for instance
 * -cl-opt-disable while debugging a kernel); they are part of the program
 * cache key, so changing them rebuilds. */
static const char *gr_extra_build_options(void) {
  const char *extra = getenv("GRAUPEL_CL_OPTIONS");
  return extra ? extra : "";
}

static gr_status gr_build(gr_context *ctx, const char *label, const char *source,
                          const char *options, cl_program *out) {
  cl_int err = CL_SUCCESS;
  const char *src[1] = {source};
  cl_program prog = clCreateProgramWithSource(ctx->cl, 1, src, NULL, &err);
  if (err != CL_SUCCESS)
    return gr_cl_check(ctx, err, "Creating an OpenCL program");
  /* FP_CONTRACT stays off inside the sources; -cl-std pins the language. */
  char opts[4096];
  /* -cl-kernel-arg-info: gr_kernel_arg finds arguments by their names. */
  snprintf(opts, sizeof(opts), "-cl-std=CL1.2 -cl-kernel-arg-info %s %s", options ? options : "",
           gr_extra_build_options());
  err = clBuildProgram(prog, 1, &ctx->device, opts, NULL, NULL);
  if (err != CL_SUCCESS) {
    size_t len = 0;
    char *log = NULL;
    clGetProgramBuildInfo(prog, ctx->device, CL_PROGRAM_BUILD_LOG, 0, NULL, &len);
    if (len > 0 && (log = malloc(len + 1)) != NULL) {
      if (clGetProgramBuildInfo(prog, ctx->device, CL_PROGRAM_BUILD_LOG, len, log, NULL) !=
          CL_SUCCESS)
        log[0] = '\0';
      log[len] = '\0';
    }
    gr_status st = gr_set_error(
        ctx, GR_ERR_BUILD, "The OpenCL program '%s' failed to build on '%s' (%s). Build log:\n%s",
        label, ctx->device_name, gr_cl_error_name(err),
        log && log[0] ? log : "(the driver gave no log)");
    free(log);
    clReleaseProgram(prog);
    return st;
  }
  *out = prog;
  return GR_OK;
}

gr_status gr_program_build_source(gr_context *ctx, const char *source, const char *options,
                                  cl_program *out) {
  if (!ctx || !source || !out)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_program_build_source needs a context, a source "
                        "and a place for the program.");
  *out = NULL;
  return gr_build(ctx, "(user source)", source, options, out);
}

gr_status gr_program_get(gr_context *ctx, const char *name, const char *options, cl_program *out) {
  if (!ctx || !name || !out)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_program_get needs a context, a name and a place "
                        "for the program.");
  *out = NULL;
  const char *source = gr_kernel_source_find(name);
  if (!source)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "No kernel source named '%s' is built into Graupel.", name);
  if (!options)
    options = "";
  const char *extra = gr_extra_build_options();
  size_t klen = strlen(name) + strlen(options) + strlen(extra) + 3;
  char *key = malloc(klen);
  if (!key)
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  snprintf(key, klen, "%s\n%s\n%s", name, options, extra);

  /* Build under the lock so two filters don't build the same program. */
  pthread_mutex_lock(&ctx->lock);
  for (int i = 0; i < ctx->nprograms; ++i)
    if (strcmp(ctx->programs[i].key, key) == 0) {
      *out = ctx->programs[i].program;
      pthread_mutex_unlock(&ctx->lock);
      free(key);
      return GR_OK;
    }
  pthread_mutex_unlock(&ctx->lock);

  cl_program prog = NULL;
  gr_status st = gr_build(ctx, name, source, options, &prog);
  if (st != GR_OK) {
    free(key);
    return st;
  }
  pthread_mutex_lock(&ctx->lock);
  for (int i = 0; i < ctx->nprograms; ++i)
    if (strcmp(ctx->programs[i].key, key) == 0) { /* another thread won */
      *out = ctx->programs[i].program;
      pthread_mutex_unlock(&ctx->lock);
      clReleaseProgram(prog);
      free(key);
      return GR_OK;
    }
  if (ctx->nprograms == ctx->capacity) {
    int cap = ctx->capacity ? 2 * ctx->capacity : 16;
    gr_program_entry *grown = realloc(ctx->programs, (size_t)cap * sizeof(*grown));
    if (!grown) {
      pthread_mutex_unlock(&ctx->lock);
      clReleaseProgram(prog);
      free(key);
      return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
    }
    ctx->programs = grown;
    ctx->capacity = cap;
  }
  ctx->programs[ctx->nprograms].key = key;
  ctx->programs[ctx->nprograms].program = prog;
  ctx->nprograms++;
  pthread_mutex_unlock(&ctx->lock);
  *out = prog;
  return GR_OK;
}

gr_status gr_kernel_create(gr_context *ctx, cl_program prog, const char *name, cl_kernel *out) {
  cl_int err = CL_SUCCESS;
  if (!ctx || !prog || !name || !out)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_kernel_create needs a context, a program and a "
                        "kernel name.");
  *out = clCreateKernel(prog, name, &err);
  if (err != CL_SUCCESS) {
    *out = NULL;
    return gr_set_error(ctx, GR_ERR_OPENCL, "The kernel '%s' could not be created: %s.", name,
                        gr_cl_error_name(err));
  }
  return GR_OK;
}

static void gr_kernel_name(cl_kernel k, char *buf, size_t len) {
  buf[0] = '\0';
  if (clGetKernelInfo(k, CL_KERNEL_FUNCTION_NAME, len, buf, NULL) != CL_SUCCESS)
    snprintf(buf, len, "(unnamed)");
  buf[len - 1] = '\0';
}

gr_status gr_kernel_args(gr_context *ctx, cl_kernel k, ...) {
  va_list ap;
  va_start(ap, k);
  for (cl_uint i = 0;; ++i) {
    size_t size = va_arg(ap, size_t);
    if (size == 0)
      break;
    const void *value = va_arg(ap, const void *);
    cl_int err = clSetKernelArg(k, i, size, value);
    if (err != CL_SUCCESS) {
      va_end(ap);
      char kname[128];
      gr_kernel_name(k, kname, sizeof(kname));
      return gr_set_error(ctx, GR_ERR_OPENCL, "Setting argument %u of kernel '%s' failed: %s.", i,
                          kname, gr_cl_error_name(err));
    }
  }
  va_end(ap);
  return GR_OK;
}

/* The name of argument i of k into buf; a CL error code on failure. */
static cl_int gr_arg_name(cl_kernel k, cl_uint i, char *buf, size_t len) {
  size_t got = 0;
  buf[0] = '\0';
  cl_int err = clGetKernelArgInfo(k, i, CL_KERNEL_ARG_NAME, len, buf, &got);
  buf[len - 1] = '\0';
  return err;
}

/* Reads every argument name of k into a fresh entry (names NULL on failure). */
static cl_int gr_arg_entry_read(cl_kernel k, gr_arg_entry *e) {
  cl_uint n = 0;
  e->kernel = k;
  e->nargs = 0;
  e->names = NULL;
  cl_int err = clGetKernelInfo(k, CL_KERNEL_NUM_ARGS, sizeof(n), &n, NULL);
  if (err != CL_SUCCESS)
    return err;
  size_t total = 0;
  for (cl_uint i = 0; i < n; ++i) {
    size_t len = 0;
    err = clGetKernelArgInfo(k, i, CL_KERNEL_ARG_NAME, 0, NULL, &len);
    if (err != CL_SUCCESS)
      return err;
    total += len + 1;
  }
  char **names = malloc((size_t)n * sizeof(char *) + total + 1);
  if (!names)
    return CL_OUT_OF_HOST_MEMORY;
  char *p = (char *)(names + n);
  for (cl_uint i = 0; i < n; ++i) {
    size_t len = 0;
    err = clGetKernelArgInfo(k, i, CL_KERNEL_ARG_NAME, 0, NULL, &len);
    if (err == CL_SUCCESS)
      err = clGetKernelArgInfo(k, i, CL_KERNEL_ARG_NAME, len + 1, p, NULL);
    if (err != CL_SUCCESS) {
      free(names);
      return err;
    }
    p[len] = '\0';
    names[i] = p;
    p += len + 1;
  }
  e->nargs = n;
  e->names = names;
  return CL_SUCCESS;
}

static int gr_arg_entry_find(const gr_arg_entry *e, const char *name) {
  for (cl_uint i = 0; e->names && i < e->nargs; ++i)
    if (strcmp(e->names[i], name) == 0)
      return (int)i;
  return -1;
}

/* Index of the argument called name, or -1 (*err says why when it is an
 * OpenCL failure rather than an unknown name). */
static int gr_arg_index(gr_context *ctx, cl_kernel k, const char *name, cl_int *err) {
  char check[256];
  int index = -1;
  *err = CL_SUCCESS;
  pthread_mutex_lock(&ctx->lock);
  for (int i = 0; i < GR_ARG_CACHE; ++i)
    if (ctx->args[i].kernel == k && ctx->args[i].names) {
      index = gr_arg_entry_find(&ctx->args[i], name);
      break;
    }
  pthread_mutex_unlock(&ctx->lock);
  if (index >= 0 && gr_arg_name(k, (cl_uint)index, check, sizeof(check)) == CL_SUCCESS &&
      strcmp(check, name) == 0)
    return index;

  /* A miss, or a stale entry: read the kernel's names again. */
  gr_arg_entry fresh;
  *err = gr_arg_entry_read(k, &fresh);
  if (*err != CL_SUCCESS)
    return -1;
  index = gr_arg_entry_find(&fresh, name);
  pthread_mutex_lock(&ctx->lock);
  int slot = -1;
  for (int i = 0; i < GR_ARG_CACHE && slot < 0; ++i)
    if (ctx->args[i].kernel == k || !ctx->args[i].names)
      slot = i;
  if (slot < 0) {
    slot = ctx->next_arg;
    ctx->next_arg = (ctx->next_arg + 1) % GR_ARG_CACHE;
  }
  free(ctx->args[slot].names);
  ctx->args[slot] = fresh;
  pthread_mutex_unlock(&ctx->lock);
  return index;
}

gr_status gr_kernel_arg(gr_context *ctx, cl_kernel k, const char *name, size_t size,
                        const void *value) {
  if (!ctx || !k || !name)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_kernel_arg needs a context, a kernel and an argument name.");
  cl_int err = CL_SUCCESS;
  int index = gr_arg_index(ctx, k, name, &err);
  if (index >= 0) {
    err = clSetKernelArg(k, (cl_uint)index, size, value);
    if (err == CL_SUCCESS)
      return GR_OK;
  }
  char kname[128];
  gr_kernel_name(k, kname, sizeof(kname));
  if (err == CL_KERNEL_ARG_INFO_NOT_AVAILABLE)
    return gr_set_error(ctx, GR_ERR_OPENCL,
                        "The kernel '%s' has no argument names (argument '%s' was asked for): "
                        "build its program with -cl-kernel-arg-info, as gr_program_get does.",
                        kname, name);
  if (err != CL_SUCCESS)
    return gr_set_error(ctx, GR_ERR_OPENCL, "Setting argument '%s' of kernel '%s' failed: %s (%d).",
                        name, kname, gr_cl_error_name(err), (int)err);
  return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                      "The kernel '%s' has no argument named '%s': use a name from the kernel's "
                      "source.",
                      kname, name);
}

gr_status gr_enqueue_2d(gr_context *ctx, cl_kernel k, size_t x0, size_t y0, size_t nx, size_t ny,
                        const size_t *local) {
  size_t offset[2] = {x0, y0};
  size_t global[2] = {nx, ny};
  if (!local)
    local = ctx->local2d;
  if (local) {
    global[0] = (nx + local[0] - 1) / local[0] * local[0];
    global[1] = (ny + local[1] - 1) / local[1] * local[1];
  }
  cl_int err = clEnqueueNDRangeKernel(ctx->queue, k, 2, offset, global, local, 0, NULL, NULL);
  return gr_cl_check(ctx, err, "Enqueueing a kernel");
}

gr_status gr_enqueue_1d(gr_context *ctx, cl_kernel k, size_t n) {
  if (n == 0)
    return GR_OK;
  size_t local = 64, global = (n + local - 1) / local * local;
  cl_int err = clEnqueueNDRangeKernel(ctx->queue, k, 1, NULL, &global, &local, 0, NULL, NULL);
  return gr_cl_check(ctx, err, "Enqueueing a kernel");
}

gr_status gr_finish(gr_context *ctx) {
  return gr_cl_check(ctx, clFinish(ctx->queue), "Waiting for the device");
}

/* ------------------------------------------------------- embedded sources */

/* Generated at build time from the files in cl/ by EmbedKernels.cmake. */
extern const gr_kernel_source gr_embedded_kernels[];
extern const int gr_embedded_kernel_count;

int gr_kernel_source_count(void) {
  return gr_embedded_kernel_count;
}

const gr_kernel_source *gr_kernel_source_at(int i) {
  return (i >= 0 && i < gr_embedded_kernel_count) ? &gr_embedded_kernels[i] : NULL;
}

const char *gr_kernel_source_find(const char *name) {
  for (int i = 0; name && i < gr_embedded_kernel_count; ++i)
    if (strcmp(gr_embedded_kernels[i].name, name) == 0)
      return gr_embedded_kernels[i].text;
  return NULL;
}

/* ----------------------------------------------------------------- buffers */

gr_status gr_buffer_create(gr_context *ctx, cl_mem_flags flags, size_t size, const void *host,
                           cl_mem *out) {
  if (!ctx || !out || size == 0)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "A device buffer needs a context and a size above 0.");
  *out = NULL;
  if ((cl_ulong)size > ctx->max_alloc || (cl_ulong)size > ctx->global_mem)
    return gr_set_error(ctx, GR_ERR_TOO_LARGE,
                        "The grid needs a buffer of %.1f MiB but the device '%s' allows at "
                        "most %.1f MiB per buffer: use a smaller grid or another device.",
                        (double)size / 1048576.0, ctx->device_name,
                        (double)ctx->max_alloc / 1048576.0);
  if (ctx->host_memory && size >= GR_BUFFER_CHECKED) {
    /* The buffer is host memory: refuse what the process cannot get rather
     * than let the kernel's overcommit hand out pages that are not there. */
    gr_memory_info mem;
    if (gr_memory_query(NULL, &mem) == GR_OK && (double)size > (double)mem.host_available) {
      char need[32], have[32];
      gr_memory_format((double)size, need, sizeof(need));
      gr_memory_format((double)mem.host_available, have, sizeof(have));
      return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY,
                          "A device buffer of %s does not fit: the device '%s' keeps its "
                          "buffers in host memory and this process can use %s; use a smaller "
                          "grid.",
                          need, ctx->device_name, have);
    }
  }
  cl_int err = CL_SUCCESS;
  if (host)
    flags |= CL_MEM_COPY_HOST_PTR;
  /* Where buffers are host memory, allocate them now: PoCL otherwise
   * allocates at the buffer's first use and, when that fails, asserts
   * (pocl_create_migration_commands: p->mem_ptr != NULL) and aborts the
   * process; with CL_MEM_ALLOC_HOST_PTR clCreateBuffer itself fails with
   * CL_OUT_OF_HOST_MEMORY. The buffer is the same one allocation either
   * way (4 x 2 GB filled take 8.3 GB resident). */
  if (ctx->host_memory && !(flags & CL_MEM_USE_HOST_PTR))
    flags |= CL_MEM_ALLOC_HOST_PTR;
  *out = clCreateBuffer(ctx->cl, flags, size, (void *)host, &err);
  if (err != CL_SUCCESS) {
    *out = NULL;
    return gr_cl_check(ctx, err, "Allocating a device buffer");
  }
  return GR_OK;
}

gr_status gr_buffer_write(gr_context *ctx, cl_mem buf, size_t offset, size_t size,
                          const void *host) {
  cl_int err = clEnqueueWriteBuffer(ctx->queue, buf, CL_TRUE, offset, size, host, 0, NULL, NULL);
  return gr_cl_check(ctx, err, "Uploading a field to the device");
}

gr_status gr_buffer_read(gr_context *ctx, cl_mem buf, size_t offset, size_t size, void *host) {
  cl_int err = clEnqueueReadBuffer(ctx->queue, buf, CL_TRUE, offset, size, host, 0, NULL, NULL);
  return gr_cl_check(ctx, err, "Reading a field back from the device");
}

void gr_buffer_release(cl_mem *buf) {
  if (buf && *buf) {
    clReleaseMemObject(*buf);
    *buf = NULL;
  }
}
