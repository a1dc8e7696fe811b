/* Water surface (seed 003's height-field water, seed 004's ripples): the
 * damped linear wave equation on the wet points of a grid, raindrop dimples,
 * and the fields derived from the wave for rendering. The model and its
 * discretisation are documented in graupel/water_surface.h. */
#include "common.h"
#include "reduce.h"
#include "water_surface_shared.h"

/* The key of step (step_hi, step_lo) of the simulation with this seed, and
 * the hash of it that decides whether a raindrop falls at point (a, b)
 * during that step: a pure function, so a step computes the same drops
 * whenever it is taken. */
GR_INLINE uint gr_ws_step_key(uint step_lo, uint step_hi, uint seed) {
  return gr_hash_u32(step_lo ^ gr_hash_u32(step_hi ^ (seed * 0x27d4eb2dU)));
}
GR_INLINE uint gr_ws_drop_hash(int a, int b, uint key) {
  return gr_hash3(a, b, key);
}

/* A uniform number in (-0.5, 0.5) from the top 24 bits of a hash. */
GR_INLINE float gr_ws_offset(uint h) {
  return ((float)(h >> 8) + 0.5f) * (1.0f / 16777216.0f) - 0.5f;
}

/* The work-group of the step: a tile of GR_WS_TILE_X x GR_WS_TILE_Y points
 * (the host asks the kernel for it, so -D can change it). */
#ifndef GR_WS_TILE_X
#define GR_WS_TILE_X 32
#endif
#ifndef GR_WS_TILE_Y
#define GR_WS_TILE_Y 16
#endif

/* One step of the wave equation h_tt = c^2 lap(h) - gamma h_t on the wet
 * points, symplectic Euler (the leapfrog scheme with v = h_t at half steps):
 *   v' = (v + dt c^2 lap(h)) exp(-gamma dt),   h' = h + dt v' + drop
 * lap sums (h_nb - h) / d^2 over the wet neighbours only: a face to a dry
 * point or beyond the grid carries nothing (a reflecting shore), and each
 * face's difference is the exact negative of its neighbour's, so the sum of
 * h over the wet points stays constant to rounding. The drops add
 * drop_coef * lap(g), the same masked Laplacian of this step's Gaussians:
 * a dimple of depth DropAmplitude with a ring around it, whose sum is zero
 * in the same way. Dry points hold no wave. Rows j_lo .. j_hi - 1 of the
 * local arrays, whose row 0 is the domain's row gj0: a piece's own rows
 * (its ring's first row is the neighbour's, exchanged after the step).
 *
 * g = the sum of the unit Gaussians exp(-r^2 / (2 sigma^2)) of this step's
 * drops within reach_x, reach_y points of each wet point (0 on dry points).
 * A drop falls at wet point (a, b) when the top 24 bits of its hash are below
 * threshold (the chance rate dx dy dt times 2^24), at a position hashed
 * uniformly within the point's cell. g lives in local memory only: each
 * work-group first decides the drops of its tile and of the points within
 * 1 + reach of it (one hash per point, not one per point and neighbour
 * within reach: drop_at holds a drop's offsets, drop_mask a bit per point
 * of each row), then sums g over its tile and the ring of one point the
 * Laplacian reads (g_tile), each point's drops in the order of rows, then
 * columns, whichever tile computes it: g is a pure function of
 * the point, so the step's Laplacian of g takes the same value from both
 * sides of a face, and a piece of a split domain, which hashes the domain's
 * indices, makes the whole grid's drops and bits (the ring's further rows
 * giving the wet points within reach). */
__kernel __attribute__((reqd_work_group_size(GR_WS_TILE_X, GR_WS_TILE_Y, 1))) void
water_surface_step(__global const float *restrict h_in, __global float *restrict h_out,
                   __global float *restrict v, __global const uchar *restrict wet, int nx, int ny,
                   float inv_dx2, float inv_dy2, float c2dt, float dt, float damp, int drops,
                   float drop_coef, int j_lo, int j_hi, float dx, float dy, float inv_2sig2,
                   int reach_x, int reach_y, uint threshold, uint seed, uint step_lo, uint step_hi,
                   int gj0, __local float2 *restrict drop_at, __local uint *restrict drop_mask,
                   __local float *restrict g_tile) {
  const int lx = get_local_id(0), ly = get_local_id(1);
  const int lid = lx + GR_WS_TILE_X * ly, wg = GR_WS_TILE_X * GR_WS_TILE_Y;
  const int i = get_global_id(0), j = get_global_id(1);
  const int gw = GR_WS_TILE_X + 2, gh = GR_WS_TILE_Y + 2;
  if (drops) {
    /* The drops window's first point (the tile's, less 1 + reach), its size,
     * and the words of a row's bit mask (one spare: two-word reads). */
    const int di0 = i - lx - 1 - reach_x, dj0 = j - ly - 1 - reach_y;
    const int dw = gw + 2 * reach_x, dh = gh + 2 * reach_y, mw = (dw + 31) / 32 + 1;
    const float inv_dw = 1.0f / (float)dw;
    const uint key = gr_ws_step_key(step_lo, step_hi, seed);
    for (int q = lid; q < dh * mw; q += wg)
      drop_mask[q] = 0u;
    barrier(CLK_LOCAL_MEM_FENCE);
    for (int q = lid; q < dw * dh; q += wg) {
      /* q / dw: (q + 1/2) / dw is at least 1 / (2 dw) from an integer,
       * far more than the float's error at these sizes. */
      int qj = (int)(((float)q + 0.5f) * inv_dw), qi = q - qj * dw;
      int a = di0 + qi, b = dj0 + qj;
      if (a >= 0 && a < nx && b >= 0 && b < ny && wet[gr_idx(a, b, nx)]) {
        uint h = gr_ws_drop_hash(a, b + gj0, key);
        if ((h >> 8) < threshold) {
          drop_at[q] = (float2)(gr_ws_offset(gr_hash_u32(h ^ 0x68e31da4U)),
                                gr_ws_offset(gr_hash_u32(h ^ 0xb5297a4dU)));
          atomic_or(&drop_mask[qj * mw + (qi >> 5)], 1u << (qi & 31));
        }
      }
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    /* g over the tile and its ring of one point, row by row of the window,
     * each row's drops in the order of their columns (the set bits of the
     * row's mask); a window reaching beyond the local arrays meets no drop
     * there. */
    const uint wmask = (1u << (2 * reach_x + 1)) - 1u;
    for (int q = lid; q < gw * gh; q += wg) {
      int qi = q % gw, qj = q / gw, gi = di0 + reach_x + qi, gj = dj0 + reach_y + qj;
      float sum = 0.0f;
      if (gi >= 0 && gi < nx && gj >= 0 && gj < ny && wet[gr_idx(gi, gj, nx)])
        for (int b = 0; b <= 2 * reach_y; ++b) {
          int row = (qj + b) * mw + (qi >> 5);
          ulong m = ((ulong)drop_mask[row + 1] << 32) | (ulong)drop_mask[row];
          uint bits = (uint)(m >> (qi & 31)) & wmask;
          while (bits) {
            int a = 31 - (int)clz(bits & (0u - bits));
            bits &= bits - 1u;
            float2 d = drop_at[(qi + a) + (qj + b) * dw];
            float rx = ((float)(reach_x - a) - d.x) * dx, ry = ((float)(reach_y - b) - d.y) * dy;
            sum += exp(-(rx * rx + ry * ry) * inv_2sig2);
          }
        }
      g_tile[q] = sum;
    }
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  if (i >= nx || j < j_lo || j >= j_hi)
    return;
  int c = gr_idx(i, j, nx);
  if (!wet[c]) {
    h_out[c] = 0.0f;
    v[c] = 0.0f;
    return;
  }
  const int t = (lx + 1) + (ly + 1) * gw; /* this point in g_tile */
  float hc = h_in[c], lap = 0.0f, dlap = 0.0f;
  float gc = drops ? g_tile[t] : 0.0f;
  if (i > 0 && wet[c - 1]) {
    lap += (h_in[c - 1] - hc) * inv_dx2;
    if (drops)
      dlap += (g_tile[t - 1] - gc) * inv_dx2;
  }
  if (i < nx - 1 && wet[c + 1]) {
    lap += (h_in[c + 1] - hc) * inv_dx2;
    if (drops)
      dlap += (g_tile[t + 1] - gc) * inv_dx2;
  }
  if (j > 0 && wet[c - nx]) {
    lap += (h_in[c - nx] - hc) * inv_dy2;
    if (drops)
      dlap += (g_tile[t - gw] - gc) * inv_dy2;
  }
  if (j < ny - 1 && wet[c + nx]) {
    lap += (h_in[c + nx] - hc) * inv_dy2;
    if (drops)
      dlap += (g_tile[t + gw] - gc) * inv_dy2;
  }
  float vn = (v[c] + c2dt * lap) * damp;
  float hn = hc + dt * vn;
  if (drops)
    hn += drop_coef * dlap;
  v[c] = vn;
  h_out[c] = hn;
}

/* The ledger's sums over the wet points of the own rows own_y0 .. own_y1 - 1
 * of the local arrays (nx x ny; a piece's ring belongs to its neighbour):
 * the wave height and the energy that the scheme conserves without damping,
 *   1/2 v^2 + 1/2 c^2 |grad h|^2 + 1/2 dt c^2 v L(h)
 * (the last term is symplectic Euler's correction for v being half a step
 * ahead of h; |grad h|^2 takes each wet-wet face once, on the point west or
 * south of it; m^2/s^2, the host multiplies by dx dy), with half_dt_c2 =
 * dt c^2 / 2 of the last step, each in fixed point (reduce.h's gr_fixed_add:
 * integer sums, so the totals are the same bits however the cells are
 * split among work-groups or the pieces of a domain); the wet count; and
 * the largest |h| (its float's bits). */
__kernel void water_surface_reduce(__global const float *restrict h,
                                   __global const float *restrict v,
                                   __global const uchar *restrict wet,
                                   __global long *restrict partial, __local long *restrict scratch,
                                   int n, int nx, int ny, int own_y0, int own_y1, float c2,
                                   float half_dt_c2, float inv_dx2, float inv_dy2) {
  int lid = get_local_id(0), wg = get_local_size(0), start, end;
  gr_reduce_block(n, &start, &end);
  long w[GR_WATER_SURFACE_WORDS];
  for (int q = 0; q < GR_WATER_SURFACE_WORDS; ++q)
    w[q] = 0;
  float hmax = 0.0f;
  for (int c = start + lid; c < end; c += wg) {
    int i = c % nx, j = c / nx;
    if (j < own_y0 || j >= own_y1 || !wet[c])
      continue;
    float hc = h[c], vc = v[c];
    float grad = 0.0f, lap = 0.0f;
    if (i < nx - 1 && wet[c + 1]) {
      float d = h[c + 1] - hc;
      grad += d * d * inv_dx2;
      lap += d * inv_dx2;
    }
    if (j < ny - 1 && wet[c + nx]) {
      float d = h[c + nx] - hc;
      grad += d * d * inv_dy2;
      lap += d * inv_dy2;
    }
    if (i > 0 && wet[c - 1])
      lap += (h[c - 1] - hc) * inv_dx2;
    if (j > 0 && wet[c - nx])
      lap += (h[c - nx] - hc) * inv_dy2;
    gr_fixed_add(&w[0], &w[1], hc);
    gr_fixed_add(&w[2], &w[3], 0.5f * vc * vc + 0.5f * c2 * grad + half_dt_c2 * vc * lap);
    w[4] += 1;
    hmax = fmax(hmax, fabs(hc));
  }
  const int slots = GR_WATER_SURFACE_WORDS + GR_WATER_SURFACE_MAXES;
  __local long *mine = gr_reduce_slots_long(scratch, slots);
  for (int q = 0; q < GR_WATER_SURFACE_WORDS; ++q)
    mine[q] = w[q];
  mine[GR_WATER_SURFACE_WORDS] = as_int(hmax); /* >= +0: its bits order as the heights */
  gr_reduce_group_long_max(scratch, GR_WATER_SURFACE_WORDS, GR_WATER_SURFACE_MAXES, partial);
}

/* One derivative of the water surface base + h along an axis at a wet point:
 * central where both neighbours are wet, one-sided where one is, 0 where
 * none is (the still surface's and the wave's differences are taken apart,
 * so a small wave on high ground keeps its precision). */
GR_INLINE float gr_ws_slope(__global const float *restrict base, __global const float *restrict h,
                            int c, int step, bool lo, bool hi, float inv_d) {
  if (lo && hi)
    return ((base[c + step] - base[c - step]) + (h[c + step] - h[c - step])) * (0.5f * inv_d);
  if (hi)
    return ((base[c + step] - base[c]) + (h[c + step] - h[c])) * inv_d;
  if (lo)
    return ((base[c] - base[c - step]) + (h[c] - h[c - step])) * inv_d;
  return 0.0f;
}

/* Fields derived on read: the water surface (base + h on wet points, base on
 * dry ones), the unit normal of the water surface ((0, 0, 1) on dry points
 * and wherever the surface is level), the wet mask as 0 / 1, or the wave
 * height (0 on dry points, which a wave set before any step may not be). */
__kernel void water_surface_derive(__global const float *restrict h,
                                   __global const float *restrict base,
                                   __global const uchar *restrict wet, __global float *restrict out,
                                   int nx, int ny, float inv_dx, float inv_dy, int what) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny))
    return;
  int c = gr_idx(i, j, nx);
  bool w = wet[c] != 0;
  if (what == GR_WATER_SURFACE_DERIVE_SURFACE) {
    out[c] = w ? base[c] + h[c] : base[c];
    return;
  }
  if (what == GR_WATER_SURFACE_DERIVE_WET) {
    out[c] = w ? 1.0f : 0.0f;
    return;
  }
  if (what == GR_WATER_SURFACE_DERIVE_WAVE) {
    out[c] = w ? h[c] : 0.0f;
    return;
  }
  float gx = 0.0f, gy = 0.0f;
  if (w) {
    gx = gr_ws_slope(base, h, c, 1, i > 0 && wet[c - 1], i < nx - 1 && wet[c + 1], inv_dx);
    gy = gr_ws_slope(base, h, c, nx, j > 0 && wet[c - nx], j < ny - 1 && wet[c + nx], inv_dy);
  }
  float g2 = gx * gx + gy * gy;
  float nxv = 0.0f, nyv = 0.0f, nzv = 1.0f;
  if (g2 > 0.0f) {
    float inv_len = 1.0f / sqrt(g2 + 1.0f);
    nxv = (0.0f - gx) * inv_len;
    nyv = (0.0f - gy) * inv_len;
    nzv = inv_len;
  }
  out[3 * c] = nxv;
  out[3 * c + 1] = nyv;
  out[3 * c + 2] = nzv;
}
