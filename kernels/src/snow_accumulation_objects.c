/* Snow accumulation core, host side: the objects
 * (snow_accumulation_internal.h): their world geometry and sample points,
 * the accumulation textures, set_objects, and each object's fields, offsets,
 * snow and texture read and written. */
#include "snow_accumulation_internal.h"

/* The new objects' geometry on the host: world vertices, triangles with
 * global indices, and per face its world normal, noise coordinates (its
 * centroid in the object's own frame) and area (in the object's own
 * frame); hlocal: the mesh points in their objects' frames. */
typedef struct gr_snac_geometry {
  double *hv;
  int *ht;
  float *nrm, *local, *area, *hlocal;
  double lo[3], hi[3];
} gr_snac_geometry;

static void gr_snac_geometry_free(gr_snac_geometry *g) {
  free(g->hv), free(g->ht), free(g->nrm), free(g->local), free(g->area), free(g->hlocal);
}

static gr_status gr_snac_build_geometry(gr_snow_accumulation *s, const gr_mesh *meshes, int n,
                                        const int *first, int nv, int nt, gr_snac_geometry *g) {
  size_t V = nv ? (size_t)nv : 1, T = nt ? (size_t)nt : 1;
  g->hv = malloc(V * 3 * sizeof(double));
  g->ht = malloc(T * 3 * sizeof(int));
  g->nrm = calloc(T * 3, sizeof(float));
  g->local = malloc(T * 3 * sizeof(float));
  g->area = calloc(T, sizeof(float));
  g->hlocal = malloc(V * 3 * sizeof(float));
  if (!g->hv || !g->ht || !g->nrm || !g->local || !g->area || !g->hlocal)
    return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  for (int a = 0; a < 3; ++a)
    g->lo[a] = HUGE_VAL, g->hi[a] = -HUGE_VAL;
  double inv_scale = 1.0 / s->params.noise_scale;
  size_t at = 0;
  for (int o = 0; o < n; ++o) {
    const gr_mesh *m = &meshes[o];
    const double *T4 = m->transform;
    for (int v = 0; v < m->nvertices; ++v) {
      const float *p = m->vertices + 3 * v;
      size_t k = (size_t)(first[o] + v);
      memcpy(g->hlocal + 3 * k, p, 3 * sizeof(float));
      for (int a = 0; a < 3; ++a) {
        double w = T4[a] * p[0] + T4[4 + a] * p[1] + T4[8 + a] * p[2] + T4[12 + a];
        g->hv[3 * k + a] = w;
        g->lo[a] = fmin(g->lo[a], w);
        g->hi[a] = fmax(g->hi[a], w);
      }
    }
    for (int t = 0; t < m->ntriangles; ++t, ++at) {
      int idx[3];
      for (int q = 0; q < 3; ++q) {
        idx[q] = first[o] + m->triangles[3 * t + q];
        g->ht[3 * at + q] = idx[q];
      }
      const double *A = g->hv + 3 * (size_t)idx[0], *B = g->hv + 3 * (size_t)idx[1],
                   *C = g->hv + 3 * (size_t)idx[2];
      double u[3] = {B[0] - A[0], B[1] - A[1], B[2] - A[2]};
      double w[3] = {C[0] - A[0], C[1] - A[1], C[2] - A[2]};
      double cr[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                      u[0] * w[1] - u[1] * w[0]};
      double len = sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
      const float *a = m->vertices + 3 * m->triangles[3 * t],
                  *b = m->vertices + 3 * m->triangles[3 * t + 1],
                  *c = m->vertices + 3 * m->triangles[3 * t + 2];
      double lu[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
      double lw[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      double lc[3] = {lu[1] * lw[2] - lu[2] * lw[1], lu[2] * lw[0] - lu[0] * lw[2],
                      lu[0] * lw[1] - lu[1] * lw[0]};
      g->area[at] = (float)(0.5 * sqrt(lc[0] * lc[0] + lc[1] * lc[1] + lc[2] * lc[2]));
      for (int e = 0; e < 3; ++e) {
        g->nrm[3 * at + e] = len > 0.0 ? (float)(cr[e] / len) : 0.0f;
        /* Per object a different stretch of the noise lattice. */
        double cen = ((double)a[e] + b[e] + c[e]) / 3.0;
        g->local[3 * at + e] =
            (float)fmod(cen * inv_scale + 97.0 * (double)o, GR_SNAC_NOISE_PERIOD);
      }
    }
  }
  return GR_OK;
}

/* What object o's mesh points show of its faces' snow (the state lives on
 * the faces): per point the mean of its faces' values (which = 0 the
 * depth, 6 the exposure) weighted by the area each turns to the sky, A
 * max(0, n . up), so that an edge between a roof and a wall or a cone's
 * side and its base shows the snow of the face that holds it; a point
 * whose faces all face sideways or down takes their plain area-weighted
 * mean. With offsets (3 floats a point), the same mean of the faces' unit
 * normals, made unit, times the depth. Waits. */
static gr_status gr_snac_points(gr_snow_accumulation *s, int o, int which, float *host, int n,
                                float *offsets) {
  int t0 = s->trifirst[o], nt = s->trifirst[o + 1] - t0, v0 = s->first[o];
  size_t N = n > 0 ? (size_t)n : 1;
  float *f = malloc((nt > 0 ? (size_t)nt : 1) * sizeof(float));
  double *acc = calloc(N * 10, sizeof(double));
  gr_status st = GR_OK;
  if (!f || !acc)
    st = gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  if (st == GR_OK && nt > 0)
    st = gr_buffer_read(s->ctx, s->o_arr[which], (size_t)t0 * sizeof(float),
                        (size_t)nt * sizeof(float), f);
  /* Per point: the sky-weighted sums (weight, value, normal) and the plain
   * ones (weight, value, normal). */
  for (int t = 0; st == GR_OK && t < nt; ++t) {
    const float *nr = s->hnrm + 3 * (size_t)(t0 + t);
    double area = s->harea[t0 + t], sky = area * fmax(0.0, (double)nr[2]);
    for (int q = 0; q < 3; ++q) {
      double *a = acc + 10 * (size_t)(s->ht[3 * (size_t)(t0 + t) + q] - v0);
      a[0] += sky, a[1] += sky * f[t];
      a[5] += area, a[6] += area * f[t];
      for (int e = 0; e < 3; ++e)
        a[2 + e] += sky * nr[e], a[7 + e] += area * nr[e];
    }
  }
  for (int v = 0; st == GR_OK && v < n; ++v) {
    const double *a = acc + 10 * (size_t)v;
    int k = a[0] > 0.0 ? 0 : 5;
    double value = a[k] > 0.0 ? a[k + 1] / a[k] : 0.0;
    host[v] = (float)value;
    if (offsets) {
      double len = sqrt(a[k + 2] * a[k + 2] + a[k + 3] * a[k + 3] + a[k + 4] * a[k + 4]);
      for (int e = 0; e < 3; ++e)
        offsets[3 * v + e] = len > 0.0 ? (float)(a[k + 2 + e] / len * value) : 0.0f;
    }
  }
  free(f), free(acc);
  return st;
}

/* ------------------------------------------------- accumulation textures */

void gr_snac_release_textures(cl_mem *pos, cl_mem *nrm, cl_mem *local, cl_mem *arr) {
  gr_buffer_release(pos);
  gr_buffer_release(nrm);
  gr_buffer_release(local);
  for (int a = 0; a < GR_SNAC_ARRAYS; ++a)
    gr_buffer_release(&arr[a]);
}

/* The samples being built: per sample its texel, triangle and barycentric
 * weights. */
typedef struct gr_snac_samples {
  size_t n, cap;
  int *texel, *tri;
  float *bar;
} gr_snac_samples;

static int gr_snac_push(gr_snac_samples *q, int texel, int tri, double l0, double l1, double l2) {
  if (q->n == q->cap) {
    size_t cap = q->cap ? 2 * q->cap : 1024;
    int *a = realloc(q->texel, cap * sizeof(int));
    if (a)
      q->texel = a;
    int *b = a ? realloc(q->tri, cap * sizeof(int)) : NULL;
    if (b)
      q->tri = b;
    float *c = b ? realloc(q->bar, cap * 3 * sizeof(float)) : NULL;
    if (!c)
      return 0;
    q->bar = c;
    q->cap = cap;
  }
  q->texel[q->n] = texel;
  q->tri[q->n] = tri;
  q->bar[3 * q->n] = (float)l0, q->bar[3 * q->n + 1] = (float)l1, q->bar[3 * q->n + 2] = (float)l2;
  q->n++;
  return 1;
}

/* Object o's samples: one per texel whose centre falls in one of its
 * triangles' UV triangles (the first such triangle; texels on no triangle
 * get none). */
static int gr_snac_object_samples(const gr_snow_accumulation *s, int o, gr_snac_samples *q) {
  int R = s->tsize[o];
  unsigned char *cov = calloc((size_t)R * (size_t)R, 1);
  if (!cov)
    return 0;
  const float *uv = s->tuv[o];
  const double eps = 1e-9;
  for (int t = s->trifirst[o]; t < s->trifirst[o + 1]; ++t) {
    const float *a = uv + 2 * (size_t)(s->ht[3 * t] - s->first[o]),
                *b = uv + 2 * (size_t)(s->ht[3 * t + 1] - s->first[o]),
                *c = uv + 2 * (size_t)(s->ht[3 * t + 2] - s->first[o]);
    double e1u = (double)b[0] - a[0], e1v = (double)b[1] - a[1];
    double e2u = (double)c[0] - a[0], e2v = (double)c[1] - a[1];
    double det = e1u * e2v - e1v * e2u;
    if (fabs(det) < 1e-20)
      continue;
    double umin = fmin(a[0], fmin(b[0], c[0])), umax = fmax(a[0], fmax(b[0], c[0]));
    double vmin = fmin(a[1], fmin(b[1], c[1])), vmax = fmax(a[1], fmax(b[1], c[1]));
    int i0 = (int)fmax(0.0, ceil(umin * R - 0.5)), i1 = (int)fmin(R - 1.0, floor(umax * R - 0.5));
    int j0 = (int)fmax(0.0, ceil(vmin * R - 0.5)), j1 = (int)fmin(R - 1.0, floor(vmax * R - 0.5));
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        int texel = j * R + i;
        if (cov[texel])
          continue;
        double du = (i + 0.5) / R - a[0], dv = (j + 0.5) / R - a[1];
        double l1 = (du * e2v - dv * e2u) / det, l2 = (e1u * dv - e1v * du) / det;
        double l0 = 1.0 - l1 - l2;
        if (l0 < -eps || l1 < -eps || l2 < -eps)
          continue;
        cov[texel] = 1;
        if (!gr_snac_push(q, texel, t, l0, l1, l2)) {
          free(cov);
          return 0;
        }
      }
  }
  free(cov);
  return 1;
}

/* Rebuilds the samples of every textured object from the objects set now;
 * object o's samples keep their snow when kept[o] and it has as many as
 * before, else start at 0. All or nothing: a failure leaves the textures
 * as they were. The positions go up with gr_snac_upload_geometry. */
static gr_status gr_snac_textures(gr_snow_accumulation *s, const unsigned char *kept) {
  gr_snac_samples q;
  memset(&q, 0, sizeof(q));
  int tfirst[GR_SNOW_ACCUMULATION_MAX_OBJECTS + 1];
  for (int o = 0; o < s->nobjects; ++o) {
    tfirst[o] = (int)q.n;
    if (s->tsize[o] > 0 && !gr_snac_object_samples(s, o, &q)) {
      free(q.texel), free(q.tri), free(q.bar);
      return gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
    }
    if (q.n > (size_t)(INT_MAX / 4)) {
      free(q.texel), free(q.tri), free(q.bar);
      return gr_set_error(s->ctx, GR_ERR_TOO_LARGE,
                          "The accumulation textures have more than %d covered texels, more "
                          "than the core addresses; lower AccumulationTextureSize.",
                          INT_MAX / 4);
    }
  }
  tfirst[s->nobjects] = (int)q.n;
  size_t ns = q.n, S = ns ? ns : 1;
  double *sv = malloc(S * 3 * sizeof(double));
  float *nrm = calloc(S * 3, sizeof(float)), *lat = malloc(S * 3 * sizeof(float));
  gr_status st = GR_OK;
  if (!sv || !nrm || !lat)
    st = gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  double inv_scale = 1.0 / s->params.noise_scale;
  for (int o = 0; st == GR_OK && o < s->nobjects; ++o)
    for (int k = tfirst[o]; k < tfirst[o + 1]; ++k) {
      const int *ix = s->ht + 3 * (size_t)q.tri[k];
      const float *b = q.bar + 3 * (size_t)k;
      /* The triangle's own normal: a texel lies on one face (the mesh
       * points' normals average their faces). */
      const double *A = s->hv + 3 * (size_t)ix[0], *B = s->hv + 3 * (size_t)ix[1],
                   *C = s->hv + 3 * (size_t)ix[2];
      double u[3] = {B[0] - A[0], B[1] - A[1], B[2] - A[2]};
      double w[3] = {C[0] - A[0], C[1] - A[1], C[2] - A[2]};
      double cr[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                      u[0] * w[1] - u[1] * w[0]};
      double len = sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
      for (int a = 0; a < 3; ++a) {
        sv[3 * (size_t)k + a] = b[0] * A[a] + b[1] * B[a] + b[2] * C[a];
        nrm[3 * (size_t)k + a] = len > 0.0 ? (float)(cr[a] / len) : 0.0f;
        double p = b[0] * (double)s->hlocal[3 * (size_t)ix[0] + a] +
                   b[1] * (double)s->hlocal[3 * (size_t)ix[1] + a] +
                   b[2] * (double)s->hlocal[3 * (size_t)ix[2] + a];
        lat[3 * (size_t)k + a] =
            (float)fmod(p * inv_scale + 97.0 * (double)o, GR_SNAC_NOISE_PERIOD);
      }
    }
  /* The same layout keeps the buffers; otherwise new ones, the kept
   * objects' snow copied over. */
  int same = (int)ns == s->ns && s->t_arr[0] != NULL;
  for (int o = 0; same && o < s->nobjects; ++o)
    same = kept[o] && o < s->tobjects && tfirst[o] == s->tfirst[o] &&
           tfirst[o + 1] == s->tfirst[o + 1];
  cl_mem tp = NULL, tn = NULL, tl = NULL, ta[GR_SNAC_ARRAYS];
  memset(ta, 0, sizeof(ta));
  if (st == GR_OK && !same && ns > 0) {
    st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, S * 3 * sizeof(float), NULL, &tp);
    if (st == GR_OK)
      st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, S * 3 * sizeof(float), NULL, &tn);
    if (st == GR_OK)
      st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, S * 3 * sizeof(float), NULL, &tl);
    for (int a = 0; st == GR_OK && a < GR_SNAC_ARRAYS; ++a) {
      st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, S * sizeof(float), NULL, &ta[a]);
      if (st == GR_OK)
        st = gr_snac_fill(s, ta[a], S, 0.0f);
    }
    for (int o = 0; st == GR_OK && o < s->nobjects && o < s->tobjects; ++o) {
      int cnt = tfirst[o + 1] - tfirst[o];
      if (!kept[o] || cnt == 0 || cnt != s->tfirst[o + 1] - s->tfirst[o] || !s->t_arr[0])
        continue;
      for (int a = 0; st == GR_OK && a < GR_SNAC_ARRAYS; ++a)
        st = gr_cl_check(s->ctx,
                         clEnqueueCopyBuffer(gr_context_queue(s->ctx), s->t_arr[a], ta[a],
                                             (size_t)s->tfirst[o] * sizeof(float),
                                             (size_t)tfirst[o] * sizeof(float),
                                             (size_t)cnt * sizeof(float), 0, NULL, NULL),
                         "Copying an object's accumulation texture");
    }
  }
  if (st == GR_OK && ns > 0) {
    st = gr_buffer_write(s->ctx, same ? s->t_nrm : tn, 0, ns * 3 * sizeof(float), nrm);
    if (st == GR_OK)
      st = gr_buffer_write(s->ctx, same ? s->t_local : tl, 0, ns * 3 * sizeof(float), lat);
  }
  free(nrm), free(lat);
  if (st != GR_OK) {
    gr_snac_release_textures(&tp, &tn, &tl, ta);
    free(sv), free(q.texel), free(q.tri), free(q.bar);
    return st;
  }
  if (!same) {
    gr_snac_release_textures(&s->t_pos, &s->t_nrm, &s->t_local, s->t_arr);
    s->t_pos = tp, s->t_nrm = tn, s->t_local = tl;
    memcpy(s->t_arr, ta, sizeof(ta));
  }
  free(s->sv), free(s->stexel), free(s->stri), free(s->sbar);
  s->sv = sv, s->stexel = q.texel, s->stri = q.tri, s->sbar = q.bar;
  s->ns = (int)ns;
  s->tobjects = s->nobjects;
  memcpy(s->tfirst, tfirst, (size_t)(s->nobjects + 1) * sizeof(int));
  return GR_OK;
}

/* The layout of a new set of objects: where each object's points and
 * faces start, which objects keep their snow, and whether all do. */
typedef struct gr_snac_object_set {
  int n;
  int first[GR_SNOW_ACCUMULATION_MAX_OBJECTS + 1], trifirst[GR_SNOW_ACCUMULATION_MAX_OBJECTS + 1];
  unsigned char kept[GR_SNOW_ACCUMULATION_MAX_OBJECTS];
  long long nv, nt;
  int same;
} gr_snac_object_set;

/* Checks the meshes (remembered in s->memo) and counts their points and
 * faces into set. */
static gr_status gr_snac_object_counts(gr_snow_accumulation *s, const gr_mesh *meshes, int n,
                                       gr_snac_object_set *set) {
  char msg[320];
  if (n < 0 || n > GR_SNOW_ACCUMULATION_MAX_OBJECTS || (n > 0 && !meshes))
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_set_objects takes 0 to %d objects with their meshes "
                        "(got %d%s).",
                        GR_SNOW_ACCUMULATION_MAX_OBJECTS, n,
                        n > 0 && !meshes ? " and no meshes" : "");
  set->n = n;
  set->nv = set->nt = 0;
  for (int o = 0; o < n; ++o) {
    if (gr_mesh_check(&s->memo[o], &meshes[o], 0, msg, sizeof(msg)) != GR_OK)
      return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT, "Object %d: %s", o, msg);
    set->first[o] = (int)set->nv;
    set->nv += meshes[o].nvertices;
    set->nt += meshes[o].ntriangles;
    if (set->nv > INT_MAX / 4 || set->nt > INT_MAX / 16)
      return gr_set_error(s->ctx, GR_ERR_TOO_LARGE,
                          "The objects have more than %d mesh points or %d triangles, more than "
                          "the core addresses; simplify the meshes.",
                          INT_MAX / 4, INT_MAX / 16);
  }
  set->first[n] = (int)set->nv;
  return GR_OK;
}

/* Which objects keep their snow: the same index with as many points and
 * faces (the snow lives on the faces). */
static void gr_snac_object_kept(const gr_snow_accumulation *s, const gr_mesh *meshes,
                                gr_snac_object_set *set) {
  int n = set->n;
  set->trifirst[0] = 0;
  for (int o = 0; o < n; ++o) {
    set->kept[o] = (unsigned char)(o < s->nobjects && meshes[o].nvertices == s->nverts[o] &&
                                   meshes[o].ntriangles == s->trifirst[o + 1] - s->trifirst[o]);
    set->trifirst[o + 1] = set->trifirst[o] + meshes[o].ntriangles;
  }
  set->same = n == s->nobjects;
  for (int o = 0; set->same && o < n; ++o)
    set->same = set->kept[o];
}

/* The device buffers of another set of faces (nb: triangles, positions,
 * normals, lattice, area; na: the snow's arrays), the snow cleared. */
static gr_status gr_snac_object_buffers(gr_snow_accumulation *s, const gr_snac_object_set *set,
                                        cl_mem nb[5], cl_mem na[GR_SNAC_ARRAYS]) {
  gr_status st = GR_OK;
  size_t T = set->nt ? (size_t)set->nt : 1;
  size_t sizes[5] = {T * 9, T * 3, T * 3, T * 3, T};
  for (int b = 0; st == GR_OK && b < 5; ++b)
    st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, sizes[b] * sizeof(float), NULL, &nb[b]);
  for (int a = 0; st == GR_OK && a < GR_SNAC_ARRAYS; ++a)
    st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE, T * sizeof(float), NULL, &na[a]);
  for (int a = 0; st == GR_OK && a < GR_SNAC_ARRAYS; ++a) {
    float zero = 0.0f;
    st = gr_cl_check(s->ctx,
                     clEnqueueFillBuffer(gr_context_queue(s->ctx), na[a], &zero, sizeof(zero), 0,
                                         T * sizeof(float), 0, NULL, NULL),
                     "Clearing the objects' snow");
  }
  return st;
}

/* Kept objects' state to their new place in na, the rest zero; the snow of
 * objects that go is dropped (counted in the ledger). */
static gr_status gr_snac_object_snow_move(gr_snow_accumulation *s, const gr_snac_object_set *set,
                                          cl_mem na[GR_SNAC_ARRAYS]) {
  gr_status st = GR_OK;
  double fall = 0.0, shed = 0.0, stored = 0.0;
  for (int o = 0; st == GR_OK && o < s->nobjects; ++o) {
    int keep = o < set->n && set->kept[o], faces = s->trifirst[o + 1] - s->trifirst[o];
    if (keep && faces > 0) {
      for (int a = 0; st == GR_OK && a < GR_SNAC_ARRAYS; ++a)
        st = gr_cl_check(s->ctx,
                         clEnqueueCopyBuffer(gr_context_queue(s->ctx), s->o_arr[a], na[a],
                                             (size_t)s->trifirst[o] * sizeof(float),
                                             (size_t)set->trifirst[o] * sizeof(float),
                                             (size_t)faces * sizeof(float), 0, NULL, NULL),
                         "Copying an object's snow");
    } else if (!keep) {
      double sums[GR_SNAC_SUMS];
      st = gr_snac_sums(s, 1, s->trifirst[o], faces, sums);
      stored += sums[0], fall += sums[1], shed += sums[2];
    }
  }
  if (st == GR_OK) {
    s->retired_fall += fall;
    s->retired_shed += shed;
    s->dropped += stored;
  }
  return st;
}

/* The new set becomes the handle's: its buffers (when it brought new ones),
 * host geometry, counts and boxes; a texture goes with its object, a kept
 * object keeps its texture (its samples move with it). */
static void gr_snac_object_adopt(gr_snow_accumulation *s, const gr_mesh *meshes,
                                 const gr_snac_object_set *set, const gr_snac_geometry *g,
                                 cl_mem nb[5], cl_mem na[GR_SNAC_ARRAYS]) {
  int n = set->n;
  if (!set->same) {
    gr_snac_release_objects(s);
    s->o_tri = nb[0], s->o_pos = nb[1], s->o_nrm = nb[2], s->o_local = nb[3], s->o_area = nb[4];
    memcpy(s->o_arr, na, GR_SNAC_ARRAYS * sizeof(cl_mem));
  }
  free(s->hv), free(s->ht), free(s->hnrm), free(s->harea), free(s->hlocal);
  s->hv = g->hv, s->ht = g->ht, s->hnrm = g->nrm, s->harea = g->area, s->hlocal = g->hlocal;
  s->nobjects = n;
  s->nv = (int)set->nv;
  s->ntri = (int)set->nt;
  for (int o = 0; o < n; ++o)
    s->nverts[o] = meshes[o].nvertices;
  memcpy(s->first, set->first, (size_t)(n + 1) * sizeof(int));
  memcpy(s->ob_lo, g->lo, sizeof(g->lo));
  memcpy(s->ob_hi, g->hi, sizeof(g->hi));
  memcpy(s->trifirst, set->trifirst, (size_t)(n + 1) * sizeof(int));
  for (int o = 0; o < GR_SNOW_ACCUMULATION_MAX_OBJECTS; ++o)
    if (s->tsize[o] > 0 && (o >= n || !set->kept[o])) {
      free(s->tuv[o]);
      s->tuv[o] = NULL;
      s->tsize[o] = 0;
    }
}

static gr_status gr_snac_set_objects_impl(gr_snow_accumulation *s, const gr_mesh *meshes, int n) {
  gr_snac_object_set set;
  gr_status st = gr_snac_object_counts(s, meshes, n, &set);
  if (st != GR_OK)
    return st;
  gr_snac_object_kept(s, meshes, &set);
  gr_snac_geometry g;
  memset(&g, 0, sizeof(g));
  st = gr_snac_build_geometry(s, meshes, n, set.first, (int)set.nv, (int)set.nt, &g);
  cl_mem nb[5] = {NULL, NULL, NULL, NULL, NULL}, na[GR_SNAC_ARRAYS];
  memset(na, 0, sizeof(na));
  if (!set.same && st == GR_OK)
    st = gr_snac_object_buffers(s, &set, nb, na);
  if (!set.same && st == GR_OK)
    st = gr_snac_object_snow_move(s, &set, na);
  if (st != GR_OK) {
    for (int b = 0; b < 5; ++b)
      gr_buffer_release(&nb[b]);
    for (int a = 0; a < GR_SNAC_ARRAYS; ++a)
      gr_buffer_release(&na[a]);
    gr_snac_geometry_free(&g);
    return st;
  }
  gr_snac_object_adopt(s, meshes, &set, &g, nb, na);
  st = gr_snac_textures(s, set.kept);
  if (st == GR_OK && set.nt > 0) {
    st = gr_buffer_write(s->ctx, s->o_nrm, 0, (size_t)set.nt * 3 * sizeof(float), g.nrm);
    if (st == GR_OK)
      st = gr_buffer_write(s->ctx, s->o_local, 0, (size_t)set.nt * 3 * sizeof(float), g.local);
    if (st == GR_OK)
      st = gr_buffer_write(s->ctx, s->o_area, 0, (size_t)set.nt * sizeof(float), g.area);
    if (st == GR_OK)
      st = gr_snac_upload_geometry(s);
  }
  free(g.local);
  return st;
}

gr_status gr_snow_accumulation_set_objects(gr_snow_accumulation *s, const gr_mesh *meshes, int n) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_set_objects needs a simulation.");
  return GR_SNAC_KEEP_ERROR(s, gr_snac_set_objects_impl(s, meshes, n));
}

static gr_status gr_snac_check_object(gr_snow_accumulation *s, const char *what, int o, int n,
                                      const void *host) {
  if (o < 0 || o >= s->nobjects)
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "%s: there is no object %d (%d are set); pass an index from 0 to %d.", what,
                        o, s->nobjects, s->nobjects - 1);
  if (!host || n != s->nverts[o])
    return gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "%s: object %d has %d mesh points but %d were given%s; pass one value per "
                        "mesh point.",
                        what, o, s->nverts[o], n, host ? "" : " (and no array)");
  return GR_OK;
}

gr_status gr_snow_accumulation_get_object_field(gr_snow_accumulation *s, int o, gr_field f,
                                                float *host, int n) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_get_object_field needs a simulation.");
  gr_status st = gr_snac_check_object(s, "gr_snow_accumulation_get_object_field", o, n, host);
  if (st == GR_OK && f != GR_FIELD_SNOW_DEPTH && f != GR_FIELD_EXPOSURE) {
    const char *name = gr_field_name(f);
    st = gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                      "The objects of the snow accumulation have no field '%s'; they give "
                      "snow_depth and exposure.",
                      name ? name : "(unknown field)");
  }
  if (st == GR_OK && n > 0)
    st = gr_snac_points(s, o, f == GR_FIELD_SNOW_DEPTH ? 0 : 6, host, n, NULL);
  return st == GR_OK ? GR_OK : GR_SNAC_KEEP_ERROR(s, st);
}

gr_status gr_snow_accumulation_get_object_offsets(gr_snow_accumulation *s, int o, float *xyz,
                                                  int n) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_get_object_offsets needs a simulation.");
  gr_status st = gr_snac_check_object(s, "gr_snow_accumulation_get_object_offsets", o, n, xyz);
  float *depth = st == GR_OK && n > 0 ? malloc((size_t)n * sizeof(float)) : NULL;
  if (st == GR_OK && n > 0 && !depth)
    st = gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  if (st == GR_OK && n > 0)
    st = gr_snac_points(s, o, 0, depth, n, xyz);
  free(depth);
  return st == GR_OK ? GR_OK : GR_SNAC_KEEP_ERROR(s, st);
}

gr_status gr_snow_accumulation_set_object_snow(gr_snow_accumulation *s, int o, const float *depth,
                                               int n) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_set_object_snow needs a simulation.");
  gr_status st = gr_snac_check_object(s, "gr_snow_accumulation_set_object_snow", o, n, depth);
  char msg[400];
  if (st == GR_OK && gr_snow_accumulation_field_validate(GR_FIELD_SNOW_DEPTH, depth, (size_t)n, 0,
                                                         msg, sizeof(msg)) != GR_OK)
    st = gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT, "Object %d: %s", o, msg);
  if (st != GR_OK || n == 0)
    return st == GR_OK ? GR_OK : GR_SNAC_KEEP_ERROR(s, st);
  /* The snow lives on the faces: each gets the mean of its corners'. */
  int t0 = s->trifirst[o], nt = s->trifirst[o + 1] - t0;
  if (nt == 0)
    return GR_OK;
  float *faces = malloc((size_t)nt * sizeof(float));
  if (!faces)
    return GR_SNAC_KEEP_ERROR(s, gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory."));
  for (int t = 0; t < nt; ++t) {
    const int *ix = s->ht + 3 * (size_t)(t0 + t);
    faces[t] = (float)(((double)depth[ix[0] - s->first[o]] + depth[ix[1] - s->first[o]] +
                        depth[ix[2] - s->first[o]]) /
                       3.0);
  }
  double before[GR_SNAC_SUMS], after[GR_SNAC_SUMS];
  size_t off = (size_t)t0 * sizeof(float), bytes = (size_t)nt * sizeof(float);
  float zero = 0.0f;
  st = gr_snac_sums(s, 1, t0, nt, before);
  if (st == GR_OK)
    st = gr_buffer_write(s->ctx, s->o_arr[0], off, bytes, faces);
  if (st == GR_OK)
    st = gr_cl_check(s->ctx,
                     clEnqueueFillBuffer(gr_context_queue(s->ctx), s->o_arr[1], &zero, sizeof(zero),
                                         off, bytes, 0, NULL, NULL),
                     "Clearing an object's snow");
  if (st == GR_OK)
    st = gr_snac_sums(s, 1, t0, nt, after);
  free(faces);
  if (st == GR_OK)
    s->initial_objects += after[0] - before[0];
  return st == GR_OK ? GR_OK : GR_SNAC_KEEP_ERROR(s, st);
}

gr_status gr_snow_accumulation_set_object_texture(gr_snow_accumulation *s, int o, const float *uv,
                                                  int size) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_set_object_texture needs a simulation.");
  const char *what = "gr_snow_accumulation_set_object_texture";
  gr_status st = GR_OK;
  char msg[400];
  if (o < 0 || o >= s->nobjects)
    st = gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                      "%s: there is no object %d (%d are set); pass an index from 0 to %d.", what,
                      o, s->nobjects, s->nobjects - 1);
  else if (!gr_param_accepts(&gr_snac_bounds[GR_SNAC_P_TEXTURE], (double)size)) {
    gr_param_explain(&gr_snac_bounds[GR_SNAC_P_TEXTURE], (double)size,
                     "Invalid accumulation texture", msg, sizeof(msg));
    st = gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT, "Object %d: %s", o, msg);
  } else if (size > 0 && !uv && s->nverts[o] > 0)
    st = gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                      "%s: object %d needs texture coordinates, 2 per mesh point (%d); pass "
                      "them or size 0 for no texture.",
                      what, o, s->nverts[o]);
  for (int k = 0; st == GR_OK && size > 0 && k < 2 * s->nverts[o]; ++k)
    if (!isfinite(uv[k]))
      st = gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                        "Object %d: texture coordinate %d of mesh point %d is %g; give finite "
                        "texture coordinates.",
                        o, k % 2, k / 2, (double)uv[k]);
  if (st != GR_OK)
    return GR_SNAC_KEEP_ERROR(s, st);
  size_t bytes = (size_t)s->nverts[o] * 2 * sizeof(float);
  /* The same texture again keeps its snow. */
  if (size == s->tsize[o] && (size == 0 || bytes == 0 || memcmp(uv, s->tuv[o], bytes) == 0))
    return GR_OK;
  float *copy = NULL;
  if (size > 0) {
    copy = malloc(bytes ? bytes : 1);
    if (!copy)
      return GR_SNAC_KEEP_ERROR(s,
                                gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory."));
    if (bytes)
      memcpy(copy, uv, bytes);
  }
  float *old_uv = s->tuv[o];
  int old_size = s->tsize[o];
  unsigned char kept[GR_SNOW_ACCUMULATION_MAX_OBJECTS];
  memset(kept, 1, sizeof(kept));
  kept[o] = 0;
  s->tuv[o] = copy, s->tsize[o] = size;
  st = gr_snac_textures(s, kept);
  if (st == GR_OK)
    st = gr_snac_upload_geometry(s);
  if (st != GR_OK) {
    s->tuv[o] = old_uv, s->tsize[o] = old_size;
    free(copy);
    return GR_SNAC_KEEP_ERROR(s, st);
  }
  free(old_uv);
  return GR_OK;
}

gr_status gr_snow_accumulation_get_object_texture(gr_snow_accumulation *s, int o, float *texels,
                                                  int size) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_snow_accumulation_get_object_texture needs a simulation.");
  gr_status st = GR_OK;
  if (o < 0 || o >= s->nobjects)
    st = gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                      "gr_snow_accumulation_get_object_texture: there is no object %d (%d are "
                      "set); pass an index from 0 to %d.",
                      o, s->nobjects, s->nobjects - 1);
  else if (s->tsize[o] == 0 || size != s->tsize[o] || !texels)
    st = gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                      "gr_snow_accumulation_get_object_texture: object %d has %s%d texels "
                      "across but %d were asked for%s; pass its size and size x size floats.",
                      o, s->tsize[o] ? "" : "no texture, ", s->tsize[o], size,
                      texels ? "" : " (and no array)");
  if (st != GR_OK)
    return GR_SNAC_KEEP_ERROR(s, st);
  size_t R = (size_t)size;
  memset(texels, 0, R * R * sizeof(float));
  int first = s->tfirst[o], cnt = s->tfirst[o + 1] - first;
  if (cnt == 0)
    return GR_OK;
  float *d = malloc((size_t)cnt * sizeof(float));
  if (!d)
    return GR_SNAC_KEEP_ERROR(s, gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory."));
  st = gr_buffer_read(s->ctx, s->t_arr[0], (size_t)first * sizeof(float),
                      (size_t)cnt * sizeof(float), d);
  for (int k = 0; st == GR_OK && k < cnt; ++k)
    texels[s->stexel[first + k]] = d[k];
  free(d);
  return st == GR_OK ? GR_OK : GR_SNAC_KEEP_ERROR(s, st);
}
