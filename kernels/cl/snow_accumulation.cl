/* Snow accumulation from a direction (seed 002, with its stability
 * branch and per-frame noise corrected; README's Sources). The model is documented in
 * graupel/snow_accumulation.h.
 *
 * The exposure view is a scatter (each triangle writes the texels whose
 * centres it covers) made deterministic by an integer atomic_max on the
 * floats' ordered bits: the maximum does not depend on the order of the
 * writes. Everything else is a gather that writes only its own point. Depths,
 * fallen and shed snow are double-float pairs (hi, lo), so that a step's
 * growth is never lost to rounding however small dt is, and what fell minus
 * what was shed equals what is stored to about 2^-48. FP_CONTRACT is off
 * (common.h), which the pair arithmetic needs. */
#include "common.h"
#include "reduce.h"
#include "snow_accumulation_shared.h"

/* A float's ordered key: a < b exactly when key(a) < key(b). */
GR_INLINE int snac_key(float z) {
  int i = as_int(z);
  return i >= 0 ? i : i ^ 0x7fffffff;
}

/* hi + lo += x, renormalised: exact to about 2^-48 of the sum. */
GR_INLINE void snac_df_add(float *hi, float *lo, float x) {
  float s = *hi + x;
  float bb = s - *hi;
  float e = (*hi - (s - bb)) + (x - bb);
  float l = *lo + e;
  float h = s + l;
  *lo = l - (h - s);
  *hi = h;
}

/* Writes triangle (a, b, c) into the view: (u, v) in texels, z the height
 * on the ray; every texel whose centre it covers (edges widened by a
 * millionth of the area: a closed surface leaves no pin-hole) keeps the
 * highest z, in the view rows row_lo .. row_hi only (a texel's value does
 * not depend on the rows drawn). Triangles seen edge-on cover nothing. */
GR_INLINE void snac_raster(__global int *restrict view, int vw, int vh, int row_lo, int row_hi,
                           float3 a, float3 b, float3 c) {
  float area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  if (!(fabs(area) > 0.0f))
    return;
  float umin = fmin(a.x, fmin(b.x, c.x)), umax = fmax(a.x, fmax(b.x, c.x));
  float vmin = fmin(a.y, fmin(b.y, c.y)), vmax = fmax(a.y, fmax(b.y, c.y));
  if (!(umax >= 0.0f && vmax >= 0.0f && umin <= (float)vw && vmin <= (float)vh))
    return; /* outside the view, or not finite */
  int i0 = max(0, (int)ceil(fmax(umin, -1.0f) - 0.5f));
  int i1 = min(vw - 1, (int)floor(fmin(umax, (float)vw + 1.0f) - 0.5f));
  int j0 = max(row_lo, (int)ceil(fmax(vmin, -1.0f) - 0.5f));
  int j1 = min(row_hi, (int)floor(fmin(vmax, (float)vh + 1.0f) - 0.5f));
  float sg = area > 0.0f ? 1.0f : -1.0f, tol = -1.0e-6f * fabs(area);
  for (int j = j0; j <= j1; ++j) {
    float py = (float)j + 0.5f;
    for (int i = i0; i <= i1; ++i) {
      float px = (float)i + 0.5f;
      float w0 = (b.x - px) * (c.y - py) - (b.y - py) * (c.x - px);
      float w1 = (c.x - px) * (a.y - py) - (c.y - py) * (a.x - px);
      float w2 = (a.x - px) * (b.y - py) - (a.y - py) * (b.x - px);
      if (sg * w0 < tol || sg * w1 < tol || sg * w2 < tol)
        continue;
      float z = (w0 * a.z + w1 * b.z + w2 * c.z) / area;
      atomic_max(view + j * vw + i, snac_key(z));
    }
  }
}

/* A world point (relative to grid point (0, 0) and zref) in the view's
 * texel coordinates: its ray along d crosses z = 0 at q = xy + z tau. */
GR_INLINE float3 snac_project(float x, float y, float z, float tau_x, float tau_y, float qx0,
                              float qy0, float inv_texel) {
  return (float3)((x + z * tau_x - qx0) * inv_texel, (y + z * tau_y - qy0) * inv_texel, z);
}

/* The snow surface as two triangles per grid cell. */
__kernel void snow_accumulation_raster_terrain(__global const float *restrict ground,
                                               __global const float *restrict depth, int nx, int ny,
                                               int gi0, int gj0, float dx, float dy, float zref,
                                               float tau_x, float tau_y, float qx0, float qy0,
                                               float inv_texel, int vw, int vh,
                                               __global int *restrict view) {
  int i = get_global_id(0), j = get_global_id(1);
  if (i >= nx - 1 || j >= ny - 1)
    return;
  float3 p[4];
  for (int k = 0; k < 4; ++k) {
    int a = i + (k & 1), b = j + (k >> 1), c = gr_idx(a, b, nx);
    /* (gi0, gj0): the domain's index of local point (0, 0), so that a
     * piece's cells are the whole grid's floats. */
    p[k] = snac_project((float)(gi0 + a) * dx, (float)(gj0 + b) * dy, (ground[c] + depth[c]) - zref,
                        tau_x, tau_y, qx0, qy0, inv_texel);
  }
  snac_raster(view, vw, vh, 0, vh - 1, p[0], p[1], p[3]);
  snac_raster(view, vw, vh, 0, vh - 1, p[0], p[3], p[2]);
}

/* The steepest rise of the snow surface between neighbouring grid points,
 * along x and along y (two maxima, m/m). A triangle of the surface slopes
 * at most sqrt(gx^2 + gy^2) of them: where that is below the snow's
 * descent (|d_z| / |d_xy|), no surface point can stand above the ray from
 * another, and the terrain need not be drawn into the view. */
__kernel void snow_accumulation_slope_reduce(__global const float *restrict ground,
                                             __global const float *restrict depth, int nx, int ny,
                                             float dx, float dy, int n,
                                             __global float *restrict partial,
                                             __local float *restrict scratch) {
  int lid = get_local_id(0), wg = get_local_size(0), start, end;
  gr_reduce_block(n, &start, &end);
  float gx = 0.0f, gy = 0.0f;
  for (int c = start + lid; c < end; c += wg) {
    int i = c % nx, j = c / nx;
    float h = ground[c] + depth[c];
    if (i + 1 < nx)
      gx = fmax(gx, fabs((ground[c + 1] + depth[c + 1]) - h) / dx);
    if (j + 1 < ny)
      gy = fmax(gy, fabs((ground[c + nx] + depth[c + nx]) - h) / dy);
  }
  __local float *mine = gr_reduce_slots(scratch, 0, 2);
  mine[0] = gx;
  mine[1] = gy;
  gr_reduce_group(scratch, 0, 2, partial);
}

/* The objects' triangles at their poses (9 floats each, relative to grid
 * point (0, 0) and zref), into the view rows row_lo .. row_hi (a piece's
 * share: snow_accumulation_view.c, gr_snac_object_rows). */
__kernel void snow_accumulation_raster_objects(__global const float *restrict tri, int ntri,
                                               float tau_x, float tau_y, float qx0, float qy0,
                                               float inv_texel, int vw, int vh, int row_lo,
                                               int row_hi, __global int *restrict view) {
  int t = get_global_id(0);
  if (t >= ntri)
    return;
  __global const float *v = tri + 9 * t;
  float3 a = snac_project(v[0], v[1], v[2], tau_x, tau_y, qx0, qy0, inv_texel);
  float3 b = snac_project(v[3], v[4], v[5], tau_x, tau_y, qx0, qy0, inv_texel);
  float3 c = snac_project(v[6], v[7], v[8], tau_x, tau_y, qx0, qy0, inv_texel);
  snac_raster(view, vw, vh, max(row_lo, 0), min(row_hi, vh - 1), a, b, c);
}

/* 1 when the point (x, y, z) with unit normal n is exposed: nothing on its
 * ray in the view lies above it by more than the bias. */
GR_INLINE float snac_exposed(__global const int *restrict view, int vw, int vh, float x, float y,
                             float z, float3 n, float3 d, float tau_x, float tau_y, float qx0,
                             float qy0, float inv_texel, float texel) {
  float3 q = snac_project(x, y, z, tau_x, tau_y, qx0, qy0, inv_texel);
  if (!(q.x >= 0.0f && q.y >= 0.0f && q.x < (float)vw && q.y < (float)vh))
    return 1.0f; /* beyond the view: nothing was drawn there */
  /* The surface's height changes by |n_xy| |d_z| / (n . -d) per unit of
   * the view's coordinate: its own triangles at the texel's centre may
   * stand that much above the point. */
  float facing = fmax(-dot(n, d), 1.0f / GR_SNAC_MAX_VIEW_SLOPE);
  float slope = fmin(length(n.xy) * fabs(d.z) / facing, GR_SNAC_MAX_VIEW_SLOPE);
  float bias =
      texel * (GR_SNAC_BIAS_TEXELS + GR_SNAC_BIAS_SLOPE * slope) + 4.0e-6f * (fabs(z) + 1.0f);
  int t = (int)q.y * vw + (int)q.x;
  return snac_key(z + bias) >= view[t] ? 1.0f : 0.0f;
}

/* Value noise in [-1, 1): a hashed value per lattice point, blended with a
 * smooth fade; the same seed gives the same pattern on every device. */
GR_INLINE float snac_lattice(int x, int y, int z, uint seed) {
  uint h = gr_hash3(x, y, seed ^ gr_hash_u32((uint)z * 0x27d4eb2dU));
  return (float)(h >> 8) * (2.0f / 16777216.0f) - 1.0f;
}

GR_INLINE float snac_fade(float t) {
  return t * t * (3.0f - 2.0f * t);
}

GR_INLINE float snac_noise(float x, float y, float z, uint seed) {
  float fx = floor(x), fy = floor(y), fz = floor(z);
  int ix = (int)fx, iy = (int)fy, iz = (int)fz;
  float tx = snac_fade(x - fx), ty = snac_fade(y - fy), tz = snac_fade(z - fz);
  float c[2];
  for (int k = 0; k < 2; ++k) {
    float a0 = mix(snac_lattice(ix, iy, iz + k, seed), snac_lattice(ix + 1, iy, iz + k, seed), tx);
    float a1 =
        mix(snac_lattice(ix, iy + 1, iz + k, seed), snac_lattice(ix + 1, iy + 1, iz + k, seed), tx);
    c[k] = mix(a0, a1, ty);
  }
  return clamp(mix(c[0], c[1], tz), -1.0f, 1.0f);
}

/* The unit normal of a height field at (i, j): central differences, one
 * sided at the grid's edge. */
GR_INLINE float3 snac_normal(__global const float *restrict b, __global const float *restrict s,
                             int i, int j, int nx, int ny, float dx, float dy) {
  int il = max(i - 1, 0), ir = min(i + 1, nx - 1), jd = max(j - 1, 0), ju = min(j + 1, ny - 1);
  float hl = b[gr_idx(il, j, nx)], hr = b[gr_idx(ir, j, nx)];
  float hd = b[gr_idx(i, jd, nx)], hu = b[gr_idx(i, ju, nx)];
  if (s) {
    hl += s[gr_idx(il, j, nx)], hr += s[gr_idx(ir, j, nx)];
    hd += s[gr_idx(i, jd, nx)], hu += s[gr_idx(i, ju, nx)];
  }
  float gx = ir > il ? (hr - hl) / ((float)(ir - il) * dx) : 0.0f;
  float gy = ju > jd ? (hu - hd) / ((float)(ju - jd) * dy) : 0.0f;
  return normalize((float3)(-gx, -gy, 1.0f));
}

/* Exposure and growth of every grid point: the snow surface's point is
 * tested against the view; the growth faces the ground's normal. */
/* The noise of every grid point, fixed in space: computed once per seed and
 * scale (snow_accumulation_noise), read every step. */
__kernel void snow_accumulation_noise(int nx, int ny, int gi0, int gj0, float noise_x0,
                                      float noise_y0, float noise_dx, float noise_dy, uint seed,
                                      __global float *restrict noise) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny))
    return;
  noise[gr_idx(i, j, nx)] = snac_noise(noise_x0 + (float)(gi0 + i) * noise_dx,
                                       noise_y0 + (float)(gj0 + j) * noise_dy, 0.0f, seed);
}

__kernel void
snow_accumulation_exposure(__global const float *restrict ground,
                           __global const float *restrict depth, int nx, int ny, int gi0, int gj0,
                           float dx, float dy, float zref, float dir_x, float dir_y, float dir_z,
                           float tau_x, float tau_y, float qx0, float qy0, float inv_texel,
                           float texel, int vw, int vh, __global const int *restrict view,
                           float rate_dt, float amplitude, __global const float *restrict noise,
                           __global float *restrict exposure, __global float *restrict growth) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny))
    return;
  int c = gr_idx(i, j, nx);
  float3 d = (float3)(dir_x, dir_y, dir_z);
  float3 nh = snac_normal(ground, depth, i, j, nx, ny, dx, dy);
  float e =
      snac_exposed(view, vw, vh, (float)(gi0 + i) * dx, (float)(gj0 + j) * dy,
                   (ground[c] + depth[c]) - zref, nh, d, tau_x, tau_y, qx0, qy0, inv_texel, texel);
  float3 nb = snac_normal(ground, (__global const float *)0, i, j, nx, ny, dx, dy);
  exposure[c] = e;
  growth[c] = rate_dt * e * fmax(0.0f, -dot(nb, d)) * (1.0f + amplitude * noise[c]);
}

/* One pass of the separable blur along axis 0 (x) or 1 (y): weights w[|k|]
 * for k = -radius .. radius, renormalised over the points on the grid. */
__kernel void snow_accumulation_blur(__global const float *restrict in, int nx, int ny, int radius,
                                     int axis, __global const float *restrict w,
                                     __global float *restrict out) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny))
    return;
  float sum = 0.0f, wsum = 0.0f;
  for (int k = -radius; k <= radius; ++k) {
    int a = axis == 0 ? i + k : i, b = axis == 0 ? j : j + k;
    if (a < 0 || b < 0 || a >= nx || b >= ny)
      continue;
    float wk = w[abs(k)];
    sum += wk * in[gr_idx(a, b, nx)];
    wsum += wk;
  }
  out[gr_idx(i, j, nx)] = sum / wsum;
}

/* The thesis' dilation: the largest growth of the 3 x 3 neighbourhood. */
__kernel void snow_accumulation_dilate(__global const float *restrict in, int nx, int ny,
                                       __global float *restrict out) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny))
    return;
  float m = 0.0f;
  for (int b = max(j - 1, 0); b <= min(j + 1, ny - 1); ++b)
    for (int a = max(i - 1, 0); a <= min(i + 1, nx - 1); ++a)
      m = fmax(m, in[gr_idx(a, b, nx)]);
  out[gr_idx(i, j, nx)] = m;
}

/* phi(z) = (1 - e^-z) / z: the share of a step's growth that a point
 * above capacity keeps at the step's end (z = k dt); 1 - z / 2 + z^2 / 6
 * for small z, 1 / z for large. */
GR_INLINE float snac_phi(float z) {
  if (z < 1.0e-3f)
    return 1.0f - z * (0.5f - z * (1.0f / 6.0f));
  return -expm1(-z) / z;
}

/* Increment and stability of one point over a step, integrated together
 * (graupel/snow_accumulation.h, step 5): the growth g arrives at a
 * constant rate through the step while the excess over the capacity c
 * relaxes at rate k, and the excess at the step's end is the exact
 * solution's: from x0 >= 0 at the start, x0 e^-kdt + g phi(kdt); from
 * below capacity (reaching it within the step, with an excess E at the
 * end had nothing been shed), E phi(kdt E / g). keep = e^-kdt; kdt >=
 * 1e30 (StabilityFactor 1) sheds all the excess. Depth, fallen and shed
 * snow are pairs, and what is shed leaves the depth's pair exactly as it
 * joins the shed pair, so depth - fallen + shed stays what it was. */
GR_INLINE void snac_settle(float g, float c, float keep, float kdt, __global float *restrict d,
                           __global float *restrict dl, __global float *restrict f,
                           __global float *restrict fl, __global float *restrict sh,
                           __global float *restrict sl, int k) {
  float dh = d[k], dlo = dl[k];
  /* The excess before the growth (negative below capacity). */
  float x0 = (dh - c) + dlo;
  if (g > 0.0f) {
    float fh = f[k], flo = fl[k];
    snac_df_add(&dh, &dlo, g);
    snac_df_add(&fh, &flo, g);
    f[k] = fh, fl[k] = flo;
  }
  if ((dh - c) + dlo > 0.0f && kdt > 0.0f) {
    /* The excess as a pair: (dh - c) exactly by TwoSum, plus dlo; what is
     * shed is that less the excess kept, x1. */
    float s = dh - c, bb = s - dh;
    float err = (dh - (s - bb)) + (-c - bb);
    float rh = s, rl = err + dlo;
    if (kdt < 1.0e30f) {
      float e = rh + rl;
      float x1 = x0 >= 0.0f ? x0 * keep + g * snac_phi(kdt) : e * snac_phi(kdt * fmin(e / g, 1.0f));
      x1 = fmin(fmax(x1, 0.0f), e);
      snac_df_add(&rh, &rl, -x1);
    }
    float shh = sh[k], shl = sl[k];
    snac_df_add(&dh, &dlo, -rh);
    snac_df_add(&dh, &dlo, -rl);
    snac_df_add(&shh, &shl, rh);
    snac_df_add(&shh, &shl, rl);
    sh[k] = shh, sl[k] = shl;
  }
  d[k] = dh, dl[k] = dlo;
}

__kernel void
snow_accumulation_apply(__global const float *restrict ground, int nx, int ny, float dx, float dy,
                        __global const float *restrict growth, float max_depth, float keep,
                        float kdt, __global float *restrict depth,
                        __global float *restrict depth_lo, __global float *restrict fall,
                        __global float *restrict fall_lo, __global float *restrict shed,
                        __global float *restrict shed_lo) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny))
    return;
  int c = gr_idx(i, j, nx);
  float3 nb = snac_normal(ground, (__global const float *)0, i, j, nx, ny, dx, dy);
  snac_settle(growth[c], max_depth * fmax(0.0f, nb.z), keep, kdt, depth, depth_lo, fall, fall_lo,
              shed, shed_lo, c);
}

/* An object's sample point (a face's centroid with the face's normal, or
 * a texel's sample): its test position half a texel out along its normal. One
 * expression for snow_accumulation_objects and
 * snow_accumulation_object_surface, so both see the same floats. */
GR_INLINE float3 snac_mesh_point(__global const float *restrict pos, float3 n, int v, float texel) {
  return (float3)(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]) + n * (GR_SNAC_NORMAL_OFFSET * texel);
}

/* The grid cell under (x, y) (the domain's indices, clamped to it): its
 * lower-left point's row. */
GR_INLINE int snac_cell_row(float y, int gny, float gdy) {
  float fy = clamp(y / gdy, 0.0f, (float)(gny - 1));
  return min((int)fy, gny - 2 >= 0 ? gny - 2 : 0);
}

/* The snow surface at (x, y), relative to zref: bilinear between the grid
 * points of the cell under it (the domain's gnx x gny points; the local
 * arrays hold the domain's rows from row0 on, nx a row). */
GR_INLINE float snac_surface_at(__global const float *restrict ground,
                                __global const float *restrict gdepth, int gnx, int gny, int row0,
                                float gdx, float gdy, float zref, float x, float y) {
  float fx = clamp(x / gdx, 0.0f, (float)(gnx - 1)), fy = clamp(y / gdy, 0.0f, (float)(gny - 1));
  int i0 = min((int)fx, gnx - 2 >= 0 ? gnx - 2 : 0), j0 = min((int)fy, gny - 2 >= 0 ? gny - 2 : 0);
  int i1 = min(i0 + 1, gnx - 1), j1 = min(j0 + 1, gny - 1);
  float tx = fx - (float)i0, ty = fy - (float)j0;
  int a0 = j0 - row0, a1 = j1 - row0;
  float h00 = ground[gr_idx(i0, a0, gnx)] + gdepth[gr_idx(i0, a0, gnx)];
  float h10 = ground[gr_idx(i1, a0, gnx)] + gdepth[gr_idx(i1, a0, gnx)];
  float h01 = ground[gr_idx(i0, a1, gnx)] + gdepth[gr_idx(i0, a1, gnx)];
  float h11 = ground[gr_idx(i1, a1, gnx)] + gdepth[gr_idx(i1, a1, gnx)];
  return mix(mix(h00, h10, tx), mix(h01, h11, tx), ty) - zref;
}

/* A piece's share of the surface under the mesh points: the surface where
 * this piece owns the cell's lower row (own_lo .. own_hi, the domain's
 * rows; the row above is then in its arrays, ring included), else -inf;
 * the maximum over the pieces is the surface. */
__kernel void snow_accumulation_object_surface(__global const float *restrict pos,
                                               __global const float *restrict nrm, int nv,
                                               float texel, __global const float *restrict ground,
                                               __global const float *restrict gdepth, int gnx,
                                               int gny, int row0, int own_lo, int own_hi, float gdx,
                                               float gdy, float zref,
                                               __global float *restrict surface) {
  int v = get_global_id(0);
  if (v >= nv)
    return;
  float3 n = (float3)(nrm[3 * v], nrm[3 * v + 1], nrm[3 * v + 2]);
  float3 p = snac_mesh_point(pos, n, v, texel);
  int r = snac_cell_row(p.y, gny, gdy);
  surface[v] = r >= own_lo && r <= own_hi
                   ? snac_surface_at(ground, gdepth, gnx, gny, row0, gdx, gdy, zref, p.x, p.y)
                   : -INFINITY;
}

/* A piece's exposure of the mesh points (or samples) from its own view,
 * for the steps with the terrain in the view, into exposure[first + v]: a
 * point is exposed when no texel value above it on its ray exceeds its
 * key, and the pieces' views combine by a maximum, so a point is exposed
 * in the combined view exactly when it is exposed in every piece's: the
 * minimum over the pieces of this (through a GR_REDUCE_MAX of its
 * negation) is snow_accumulation_objects' exposure, bit for bit, without
 * combining the view's texels under the objects. */
__kernel void snow_accumulation_object_exposure(__global const float *restrict pos,
                                                __global const float *restrict nrm, int nv,
                                                float dir_x, float dir_y, float dir_z, float tau_x,
                                                float tau_y, float qx0, float qy0, float inv_texel,
                                                float texel, int vw, int vh,
                                                __global const int *restrict view, int first,
                                                __global float *restrict exposure) {
  int v = get_global_id(0);
  if (v >= nv)
    return;
  float3 d = (float3)(dir_x, dir_y, dir_z);
  float3 n = (float3)(nrm[3 * v], nrm[3 * v + 1], nrm[3 * v + 2]);
  float3 p = snac_mesh_point(pos, n, v, texel);
  exposure[first + v] =
      snac_exposed(view, vw, vh, p.x, p.y, p.z, n, d, tau_x, tau_y, qx0, qy0, inv_texel, texel);
}

/* The objects' faces (pos the centroid, nrm the face's normal) or the
 * textures' samples: exposure (half a texel out along the normal), growth,
 * increment and stability, like the grid's but without blur. pos and nrm
 * are world (pos relative to grid point (0, 0) and zref), lattice the
 * object's own frame in noise lattice units. */
__kernel void snow_accumulation_objects(
    __global const float *restrict pos, __global const float *restrict nrm,
    __global const float *restrict lattice, int nv, float dir_x, float dir_y, float dir_z,
    float tau_x, float tau_y, float qx0, float qy0, float inv_texel, float texel, int vw, int vh,
    __global const int *restrict view, float rate_dt, float amplitude, uint seed, float max_depth,
    float keep, float kdt, int terrain_drawn, __global const float *restrict ground,
    __global const float *restrict gdepth, int gnx, int gny, float gdx, float gdy, float zref,
    int have_surface, int have_exposure, int surface_first, __global const float *restrict surface,
    __global float *restrict exposure, __global float *restrict depth,
    __global float *restrict depth_lo, __global float *restrict fall,
    __global float *restrict fall_lo, __global float *restrict shed,
    __global float *restrict shed_lo) {
  int v = get_global_id(0);
  if (v >= nv)
    return;
  float3 d = (float3)(dir_x, dir_y, dir_z);
  float3 n = (float3)(nrm[3 * v], nrm[3 * v + 1], nrm[3 * v + 2]);
  float3 p = snac_mesh_point(pos, n, v, texel);
  /* have_exposure: surface from surface_first holds the pieces' combined
   * exposure of the points (snow_accumulation_object_exposure), the view
   * only this piece's. */
  float e = have_exposure ? surface[surface_first + v]
                          : snac_exposed(view, vw, vh, p.x, p.y, p.z, n, d, tau_x, tau_y, qx0, qy0,
                                         inv_texel, texel);
  /* Without the terrain in the view, a point under the snow surface (an
   * object sunk into the ground) is hidden by it: the surface at its
   * place, bilinear between the grid points (on a piece: the pieces'
   * reduced snow_accumulation_object_surface, the same floats). */
  if (!terrain_drawn && e > 0.0f) {
    float hs = have_surface
                   ? surface[surface_first + v]
                   : snac_surface_at(ground, gdepth, gnx, gny, 0, gdx, gdy, zref, p.x, p.y);
    if (p.z < hs)
      e = 0.0f;
  }
  float noise = snac_noise(lattice[3 * v], lattice[3 * v + 1], lattice[3 * v + 2], seed);
  float g = rate_dt * e * fmax(0.0f, -dot(n, d)) * (1.0f + amplitude * noise);
  exposure[v] = e;
  snac_settle(g, max_depth * fmax(0.0f, n.z), keep, kdt, depth, depth_lo, fall, fall_lo, shed,
              shed_lo, v);
}

/* x w as a pair (TwoProduct), added to the sum hi + lo. */
GR_INLINE void snac_add_product(float *hi, float *lo, float x, float w) {
  float p = x * w;
  gr_df_add(hi, lo, p);
  gr_df_add(hi, lo, fma(x, w, -p));
}

/* The ledger: stored, fallen and shed snow over the points first ..
 * first + n - 1, each weighted by area[] when weighted (faces), else
 * 1 (grid points: the host multiplies by dx dy). */
__kernel void snow_accumulation_reduce(
    __global const float *restrict depth, __global const float *restrict depth_lo,
    __global const float *restrict fall, __global const float *restrict fall_lo,
    __global const float *restrict shed, __global const float *restrict shed_lo,
    __global const float *restrict area, int weighted, int first, int n,
    __global float *restrict partial, __local float *restrict scratch) {
  int lid = get_local_id(0), wg = get_local_size(0), start, end;
  gr_reduce_block(n, &start, &end);
  float hi[GR_SNAC_SUMS], lo[GR_SNAC_SUMS];
  for (int q = 0; q < GR_SNAC_SUMS; ++q)
    hi[q] = lo[q] = 0.0f;
  for (int q = start + lid; q < end; q += wg) {
    int c = first + q;
    float w = weighted ? area[c] : 1.0f;
    snac_add_product(&hi[0], &lo[0], depth[c], w);
    snac_add_product(&hi[0], &lo[0], depth_lo[c], w);
    snac_add_product(&hi[1], &lo[1], fall[c], w);
    snac_add_product(&hi[1], &lo[1], fall_lo[c], w);
    snac_add_product(&hi[2], &lo[2], shed[c], w);
    snac_add_product(&hi[2], &lo[2], shed_lo[c], w);
  }
  __local float *mine = gr_reduce_slots(scratch, GR_SNAC_SUMS, 0);
  for (int q = 0; q < GR_SNAC_SUMS; ++q) {
    mine[2 * q] = hi[q];
    mine[2 * q + 1] = lo[q];
  }
  gr_reduce_group(scratch, GR_SNAC_SUMS, 0, partial);
}

/* The ledger's sums per row: stored, fallen and shed snow of rows first ..
 * first + rows - 1 (nx points each, in order along the row, as double-float
 * pairs): 6 floats per row (hi, lo of each). One work-item per row, so a
 * row's sum is the same bits whichever piece holds it. */
__kernel void snow_accumulation_row_sums(__global const float *restrict depth,
                                         __global const float *restrict depth_lo,
                                         __global const float *restrict fall,
                                         __global const float *restrict fall_lo,
                                         __global const float *restrict shed,
                                         __global const float *restrict shed_lo, int nx, int first,
                                         int rows, __global float *restrict out) {
  int r = get_global_id(0);
  if (r >= rows)
    return;
  float hi[GR_SNAC_SUMS], lo[GR_SNAC_SUMS];
  for (int q = 0; q < GR_SNAC_SUMS; ++q)
    hi[q] = lo[q] = 0.0f;
  int c0 = (first + r) * nx;
  for (int i = 0; i < nx; ++i) {
    int c = c0 + i;
    gr_df_add(&hi[0], &lo[0], depth[c]);
    gr_df_add(&hi[0], &lo[0], depth_lo[c]);
    gr_df_add(&hi[1], &lo[1], fall[c]);
    gr_df_add(&hi[1], &lo[1], fall_lo[c]);
    gr_df_add(&hi[2], &lo[2], shed[c]);
    gr_df_add(&hi[2], &lo[2], shed_lo[c]);
  }
  for (int q = 0; q < GR_SNAC_SUMS; ++q) {
    out[2 * GR_SNAC_SUMS * r + 2 * q] = hi[q];
    out[2 * GR_SNAC_SUMS * r + 2 * q + 1] = lo[q];
  }
}

__kernel void snow_accumulation_surface(__global const float *restrict ground,
                                        __global const float *restrict depth, int n,
                                        __global float *restrict out) {
  int c = get_global_id(0);
  if (c < n)
    out[c] = ground[c] + depth[c];
}
