/* Snow deformation by objects (seed 000, with its errors
 * corrected as the header says; README's Sources). The model is documented in
 * graupel/snow_deformation.h.
 *
 * State: snow depth S and density rho per point (two sets, alternating
 * between talus iterations), the ground B; per object and step the underside
 * U (+inf where the object is not), the overlap D and the contour weight cw
 * (-1 off the contour); per step the lowest underside of all objects Umin,
 * the summed overlap and the contact flag.
 *
 * Every kernel is a gather that writes only its own point. What a point
 * gives (press, talus) is computed by the same inline function from the same
 * floats in the kernel of the giver and of the receiver, so what leaves one
 * point arrives in the other, and no atomics are needed. FP_CONTRACT is off
 * (common.h). */
#include "common.h"
#include "reduce.h"
#include "snow_deformation_shared.h"

/* The underside U(i, j): the lowest crossing of the vertical line through
 * grid point (i, j) by the object's triangles (world coordinates relative
 * to the grid's point (0, 0)), +inf where none crosses it. A scatter, one
 * work-item per triangle over the points of its box (within the object's
 * box [bi0, bi1] x [bj0, bj1]), into an integer minimum: a float's bits
 * made order-preserving as a signed int (snow_order), so atomic_min gives
 * the exact minimum whatever the order (deterministic, no float atomics).
 * snow_raster_clear fills the window with +inf first; snow_overlap turns
 * the ints back into floats. */
GR_INLINE int snow_order_bits(int b) {
  return b >= 0 ? b : b ^ 0x7fffffff; /* an involution: it also decodes */
}

GR_INLINE int snow_order(float z) {
  return snow_order_bits(as_int(z));
}

__kernel void snow_raster_clear(int nx, int ny, int x_end, int y_end,
                                __global int *restrict under) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny) || i >= x_end || j >= y_end)
    return;
  under[gr_idx(i, j, nx)] = snow_order(INFINITY);
}

/* The box [bi0, bi1] x [bj0, bj1] and the loop are in the whole domain's
 * indices (the coordinates of point (i, j) are i dx, j dy there, the same
 * floats on every piece); the point is stored at (i - ox, j - oy) of the
 * local array, whose point (0, 0) is the domain's (ox, oy). */
__kernel void snow_raster(__global const float *restrict tri, int first, int count, int nx,
                          float dx, float dy, int bi0, int bi1, int bj0, int bj1, int ox, int oy,
                          __global int *restrict under) {
  int t = get_global_id(0);
  if (t >= count)
    return;
  __global const float *v = tri + 9 * (first + t);
  float ax = v[0], ay = v[1], bx = v[3], by = v[4], cx = v[6], cy = v[7];
  float area = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
  if (area == 0.0f)
    return; /* vertical: its neighbours give the crossing */
  float xlo = fmin(ax, fmin(bx, cx)), xhi = fmax(ax, fmax(bx, cx));
  float ylo = fmin(ay, fmin(by, cy)), yhi = fmax(ay, fmax(by, cy));
  /* The points within a point of the triangle's box, in the object's box. */
  int i0 = max(bi0, (int)floor(xlo / dx) - 1), i1 = min(bi1, (int)ceil(xhi / dx) + 1);
  int j0 = max(bj0, (int)floor(ylo / dy) - 1), j1 = min(bj1, (int)ceil(yhi / dy) + 1);
  float s = area > 0.0f ? 1.0f : -1.0f, tol = -GR_SNOW_EDGE_EPS * fabs(area);
  for (int j = j0; j <= j1; ++j)
    for (int i = i0; i <= i1; ++i) {
      float px = i * dx, py = j * dy;
      float w0 = (bx - px) * (cy - py) - (by - py) * (cx - px);
      float w1 = (cx - px) * (ay - py) - (cy - py) * (ax - px);
      float w2 = (ax - px) * (by - py) - (ay - py) * (bx - px);
      if (s * w0 < tol || s * w1 < tol || s * w2 < tol)
        continue;
      float z = (w0 * v[2] + w1 * v[5] + w2 * v[8]) / area;
      atomic_min(under + gr_idx(i - ox, j - oy, nx), snow_order(z));
    }
}

/* An amount of snow rounded down to whole quanta (see
 * snow_deformation_shared.h); exact, as the quantum is a power of two. */
GR_INLINE float snow_q(float x) {
  return floor(x * GR_SNOW_QUANTUM_INV) * GR_SNOW_QUANTUM;
}

/* D = min(S, max(0, H - U)) in whole quanta: the ground is rigid. */
GR_INLINE float snow_overlap_of(float b, float s, float u) {
  return fmin(s, snow_q(fmax(0.0f, (b + s) - u)));
}

/* Also turns the raster's ordered ints back into the underside's floats. */
__kernel void snow_overlap(__global const float *restrict ground,
                           __global const float *restrict depth, __global float *restrict under,
                           int nx, int ny, int x_end, int y_end, __global float *restrict overlap) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny) || i >= x_end || j >= y_end)
    return;
  int c = gr_idx(i, j, nx);
  float u = as_float(snow_order_bits(as_int(under[c])));
  under[c] = u;
  overlap[c] = snow_overlap_of(ground[c], depth[c], u);
}

/* The room a deposit may fill at a point, in whole quanta: up to its
 * ceiling, the lowest underside above it (this object's u, an earlier
 * object's umin) less the clearance (twice GR_SNOW_DEFORMATION_CONTACT_GAP,
 * as the talus'); +inf where no object covers the point. */
GR_INLINE float snow_room(float b, float s, float u, float umin, float clearance) {
  return snow_q(fmax(0.0f, (fmin(u, umin) - clearance) - (b + s)));
}

/* Contour weight: -1 off the contour; on it s_w = max(0, v^ . w^) + r / K
 * with w^ the outward direction, minus the sum of the offsets of the
 * neighbours it borders. Ring 0 (the thesis' contour): the points not
 * overlapped nor touched with an overlapped neighbour. Ring 1, 2, ...: what
 * did not fit under an overhang goes on outward: the points with room
 * (snow_room) that border a full one (overlapped, or no room left: filled
 * by the ring before, or touched). */
__kernel void snow_contour(__global const float *restrict ground,
                           __global const float *restrict depth,
                           __global const float *restrict under,
                           __global const float *restrict under_min,
                           __global const float *restrict overlap, int nx, int ny, float vx,
                           float vy, float rest, float gap, float clearance, int ring, int x_end,
                           int y_end, __global float *restrict weight) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny) || i >= x_end || j >= y_end)
    return;
  int c = gr_idx(i, j, nx);
  float cw = -1.0f;
  /* A point the object touches without pressing it (pressed before: its
   * surface at the underside) lies under the object, not on its contour:
   * snow is never put under an object. */
  int open = ring == 0 ? ground[c] + depth[c] < under[c] - gap
                       : snow_room(ground[c], depth[c], under[c], under_min[c], clearance) > 0.0f;
  if (overlap[c] <= 0.0f && open) {
    int any = 0, ox = 0, oy = 0;
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        int a = i + di, b = j + dj;
        if ((di | dj) == 0 || a < 0 || b < 0 || a >= nx || b >= ny)
          continue;
        int m = gr_idx(a, b, nx);
        if (overlap[m] > 0.0f || (ring > 0 && snow_room(ground[m], depth[m], under[m], under_min[m],
                                                        clearance) <= 0.0f)) {
          any = 1;
          ox += di;
          oy += dj;
        }
      }
    if (any) {
      float len = sqrt((float)(ox * ox + oy * oy));
      float d = len > 0.0f ? (-(float)ox * vx - (float)oy * vy) / len : 0.0f;
      /* In whole units of 2^-20, so that their sum is an exact integer. */
      cw = rint((fmax(0.0f, d) + rest) * GR_SNOW_WEIGHT_INV) / GR_SNOW_WEIGHT_INV;
    }
  }
  weight[c] = cw;
}

/* The press of one point: the displaced height e and the new density
 * (mass-consistent Eqs. 3.9-3.11; see the header). w_const < 0 selects the
 * density-driven model. */
GR_INLINE float snow_displaced(float s, float rho, float d, float rho_min, float rho_max,
                               float w_const) {
  if (d <= 0.0f)
    return 0.0f;
  float w;
  if (w_const >= 0.0f)
    w = w_const;
  else if (rho_max > rho_min)
    w = clamp((rho - rho_min) / (rho_max - rho_min), 0.0f, 1.0f);
  else
    w = 1.0f;
  /* To the nearest quantum (d is whole quanta, so e stays within [0, d]):
   * the compressed fraction keeps no bias. */
  float e = fmax(w * d, s - (s - d) * (rho_max / rho));
  return rint(clamp(e, 0.0f, d) * GR_SNOW_QUANTUM_INV) * GR_SNOW_QUANTUM;
}

__kernel void
snow_object_reduce(__global const float *restrict ground, __global const float *restrict depth,
                   __global const float *restrict density, __global const float *restrict under,
                   __global const float *restrict overlap, __global const float *restrict weight,
                   float rho_min, float rho_max, float w_const, float gap, int nx, int x0, int y0,
                   int w, int n, __global long *restrict partial, __local long *restrict scratch) {
  /* Over the window [x0, x0 + w) x [y0, y0 + n / w), in fixed point
   * (snow_deformation_shared.h): e and D - e in quanta (exact), the weights
   * in their units (exact), the masses e rho and D rho in 2^-32 kg/m^2. */
  int lid = get_local_id(0), wg = get_local_size(0), start, end;
  gr_reduce_block(n, &start, &end);
  long acc[GR_SNOW_OBJ_SUMS];
  for (int q = 0; q < GR_SNOW_OBJ_SUMS; ++q)
    acc[q] = 0;
  for (int q = start + lid; q < end; q += wg) {
    int c = gr_idx(x0 + q % w, y0 + q / w, nx);
    float s = depth[c], rho = density[c], d = overlap[c], cw = weight[c];
    float e = snow_displaced(s, rho, d, rho_min, rho_max, w_const);
    acc[0] += (long)rint(e * GR_SNOW_QUANTUM_INV);
    acc[1] += (long)rint((e * rho) * GR_SNOW_PRESS_MASS_INV);
    if (cw >= 0.0f) {
      acc[2] += (long)rint(cw * GR_SNOW_WEIGHT_INV);
      acc[3] += 1;
    }
    acc[4] += (long)rint((d * rho) * GR_SNOW_PRESS_MASS_INV);
    acc[5] += (long)rint((d - e) * GR_SNOW_QUANTUM_INV);
    if (ground[c] + s >= under[c] - gap)
      acc[6] += 1;
  }
  __local long *mine = gr_reduce_slots_long(scratch, GR_SNOW_OBJ_SUMS);
  for (int q = 0; q < GR_SNOW_OBJ_SUMS; ++q)
    mine[q] = acc[q];
  gr_reduce_group_long(scratch, GR_SNOW_OBJ_SUMS, partial);
}

/* Press and deposit: an overlapped point drops to the underside keeping the
 * mass (S - e) rho; a contour point gains cw * add_depth of depth, at most
 * its room (snow_room: never up to an underside), of density add_rho, the
 * mean density of the displaced snow (add_depth = 0 when the object deforms
 * nothing this step). Ring 0 also keeps the step's overlap sum, contact flag
 * and lowest underside; a later ring (snow_contour) only deposits. Every
 * point of the window writes its deposit to got and 1 to full where the
 * room held less than its share (for snow_ring_reduce). */
__kernel void snow_apply(__global const float *restrict ground, __global float *restrict depth,
                         __global float *restrict density, __global const float *restrict under,
                         __global const float *restrict overlap,
                         __global const float *restrict weight, float rho_min, float rho_max,
                         float w_const, float gap, float clearance, float add_depth, float add_rho,
                         int press, int ring, int nx, int ny, int x_end, int y_end,
                         __global float *restrict overlap_sum, __global float *restrict contact,
                         __global float *restrict under_min, __global float *restrict got,
                         __global float *restrict full) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny) || i >= x_end || j >= y_end)
    return;
  int c = gr_idx(i, j, nx);
  float s = depth[c], rho = density[c], d = overlap[c], cw = weight[c], u = under[c];
  float umin = under_min[c], add = 0.0f, over = 0.0f;
  if (ring == 0) {
    if (ground[c] + s >= u - gap)
      contact[c] = 1.0f;
    under_min[c] = fmin(umin, u);
    if (press && d > 0.0f) {
      float e = snow_displaced(s, rho, d, rho_min, rho_max, w_const);
      float s1 = s - d;
      depth[c] = s1;
      /* rho (S - e) / (S - D) written as rho + rho (D - e) / (S - D): when
       * nothing is compressed (e = D) the density stays bit for bit. */
      if (s1 > 0.0f)
        density[c] = fmin(rho_max, rho + rho * ((d - e) / s1));
      overlap_sum[c] += d;
    }
  }
  if (press && d <= 0.0f && cw > 0.0f) {
    float share = snow_q(cw * add_depth), room = snow_room(ground[c], s, u, umin, clearance);
    add = fmin(share, room);
    over = share > room ? 1.0f : 0.0f;
    /* The mass-weighted mean written as a change, so that snow of the same
     * density leaves the density bit for bit as it was. */
    float s1 = s + add;
    depth[c] = s1;
    /* A share below one quantum rounds to nothing: bare ground stays bare
     * (and its density is not 0/0). */
    if (add > 0.0f)
      density[c] = rho + add * ((add_rho - rho) / s1);
  }
  got[c] = add;
  full[c] = over;
}

/* After a ring's deposit and the next ring's weights, over the window [x0,
 * x0 + w) x [y0, y0 + n / w): what the ring received (quanta), its points
 * that got less than their share (their rest goes on to the next ring),
 * the next ring's weights (units of 2^-20) and its points. */
__kernel void snow_ring_reduce(__global const float *restrict got,
                               __global const float *restrict full,
                               __global const float *restrict weight, int nx, int x0, int y0, int w,
                               int n, __global long *restrict partial,
                               __local long *restrict scratch) {
  int lid = get_local_id(0), wg = get_local_size(0), start, end;
  gr_reduce_block(n, &start, &end);
  long acc[4] = {0, 0, 0, 0};
  for (int q = start + lid; q < end; q += wg) {
    int c = gr_idx(x0 + q % w, y0 + q / w, nx);
    float cw = weight[c];
    acc[0] += (long)rint(got[c] * GR_SNOW_QUANTUM_INV);
    acc[1] += full[c] > 0.0f;
    if (cw >= 0.0f) {
      acc[2] += (long)rint(cw * GR_SNOW_WEIGHT_INV);
      acc[3] += 1;
    }
  }
  __local long *mine = gr_reduce_slots_long(scratch, 4);
  for (int q = 0; q < 4; ++q)
    mine[q] = acc[q];
  gr_reduce_group_long(scratch, 4, partial);
}

/* Depths to the nearest whole quantum. */
__kernel void snow_quantize(int n, __global float *restrict depth) {
  int c = get_global_id(0);
  if (c < n)
    depth[c] = rint(depth[c] * GR_SNOW_QUANTUM_INV) * GR_SNOW_QUANTUM;
}

/* The start of a step, on where the last step's objects wrote. */
__kernel void snow_reset(int nx, int ny, int x_end, int y_end, __global float *restrict overlap_sum,
                         __global float *restrict contact, __global float *restrict under_min) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny) || i >= x_end || j >= y_end)
    return;
  int c = gr_idx(i, j, nx);
  overlap_sum[c] = 0.0f;
  contact[c] = 0.0f;
  under_min[c] = INFINITY;
}

/* Talus: the excess of point a (height ha) over its neighbour b (height hb,
 * ceiling cb: the lowest underside above b less a clearance of twice
 * GR_SNOW_DEFORMATION_CONTACT_GAP, +inf where no object covers b) at the distance whose threshold
 * is thr, never more than the room under b's ceiling: snow slides in under an object (the gap a
 * ploughing object leaves behind it fills as the trench walls collapse) but never rises to touch
 * it, so talus never makes contact (only an object's press does) and never undoes an imprint. The
 * excess is continuous in the heights: a point never hides an excess that a small change would
 * reveal whole (what a bare "not if cb <= ha" did: there the trench walls under a ploughing sphere
 * crept for hundreds of iterations). */
GR_INLINE float snow_excess(float ha, float hb, float cb, float thr) {
  return fmin(fmax(0.0f, ha - hb - thr), fmax(0.0f, cb - hb));
}

/* The talus share for a largest excess big (see GR_SNOW_TALUS_SHARE): an
 * excess up to the threshold thr is carried on at GR_SNOW_TALUS_SHARE_SMALL,
 * a larger one (a collapse) at GR_SNOW_TALUS_SHARE. */
GR_INLINE float snow_share(float big, float thr) {
  return big <= thr ? GR_SNOW_TALUS_SHARE_SMALL : GR_SNOW_TALUS_SHARE;
}

/* The threshold of the offset (di, dj). */
GR_INLINE float snow_threshold(int di, int dj, float tx, float ty, float td) {
  return (di != 0 && dj != 0) ? td : (di != 0 ? tx : ty);
}

/* One talus iteration, per point (the same functions for the one-launch
 * iteration, snow_relax_rate and snow_relax_move, and for the blocked one,
 * snow_relax_block, so that both give the same bits). The 8 neighbours come
 * in the order of GR_SNOW_NEIGHBOUR_DI/DJ; a neighbour off the grid is the
 * point itself: a point has no excess over itself (the thresholds are
 * positive), so an edge drops the pair at both of its ends alike.
 *
 * The rate: k_out, the factor of every excess the point gives, and k_in,
 * the factor of every excess it may receive; the pair (a, b) moves
 * x_ab min(k_out_a, k_in_b). Thermal erosion's bound: a gives at most
 * GR_SNOW_TALUS_SHARE of its largest excess in all (and never more than it
 * holds) and b takes at most that share of its largest incoming excess, so
 * a lone pair ends a little below the threshold in one iteration and a pit
 * filled from eight sides at once still does not rise above them. A point gives
 * only if it is a giver (in the iteration's window) and can move more than
 * tol, min(S, its largest excess) (mv, for the check): the relaxation ends
 * when none can, and the points still moving bound the next window. */
GR_INLINE void snow_rate_at(float s, float g, float u, const float *sn, const float *gn,
                            const float *un, float tx, float ty, float td, int giver, float tol,
                            float *k_out, float *k_in, float *mv) {
  float ha = g + s, sum = 0.0f, big = 0.0f, sum_in = 0.0f, big_in = 0.0f;
  for (int q = 0; q < 8; ++q) {
    float hn = gn[q] + sn[q];
    float thr = snow_threshold(GR_SNOW_NEIGHBOUR_DI(q), GR_SNOW_NEIGHBOUR_DJ(q), tx, ty, td);
    float x = snow_excess(ha, hn, un[q], thr);
    sum += x;
    big = fmax(big, x);
    if (sn[q] > 0.0f) { /* a neighbour without snow gives nothing */
      float y = snow_excess(hn, ha, u, thr);
      sum_in += y;
      big_in = fmax(big_in, y);
    }
  }
  /* u = -inf: out of the step's reach (snow_ceiling) */
  float m = giver && s > 0.0f && u > -INFINITY ? fmin(s, big) : 0.0f, k = 0.0f;
  if (m > tol && sum > 0.0f)
    k = fmin(snow_share(big, fmin(tx, ty)) * (big / sum), GR_SNOW_KEEP * s / sum);
  *k_out = k;
  *k_in = sum_in > 0.0f ? snow_share(big_in, fmin(tx, ty)) * (big_in / sum_in) : 0.0f;
  *mv = m;
}

/* The move: the point gives x_bn min(k_b, k_in_n) to each neighbour n and
 * receives x_ab min(k_a, k_in_b) (with a's density) from each neighbour a:
 * the same floats both ways, in whole quanta. */
GR_INLINE void snow_move_at(float s, float rho, float g, float u, float kb, float kin,
                            const float *sn, const float *gn, const float *un, const float *rn,
                            const float *kon, const float *kinn, float tx, float ty, float td,
                            float *s_out, float *rho_out) {
  float hb = g + s, out = 0.0f, in = 0.0f, mass_in = 0.0f; /* mass_in: relative to rho */
  for (int q = 0; q < 8; ++q) {
    float thr = snow_threshold(GR_SNOW_NEIGHBOUR_DI(q), GR_SNOW_NEIGHBOUR_DJ(q), tx, ty, td);
    float hn = gn[q] + sn[q];
    if (kb > 0.0f)
      out += snow_q(snow_excess(hb, hn, un[q], thr) * fmin(kb, kinn[q]));
    if (kon[q] > 0.0f && kin > 0.0f) {
      float f = snow_q(snow_excess(hn, hb, u, thr) * fmin(kon[q], kin));
      in += f;
      mass_in += f * (rn[q] - rho);
    }
  }
  /* Whole quanta below 16 m: exact, and out <= S (the rate's bound). */
  float kept = fmax(0.0f, s - out), s1 = kept + in;
  *s_out = s1;
  /* (kept rho + sum f rho_a) / s1 as a change: equal densities stay put. */
  *rho_out = (in > 0.0f && s1 > 0.0f) ? rho + mass_in / s1 : rho;
}

/* The index of neighbour q of point (i, j), or the point's own off the
 * grid. */
GR_INLINE int snow_neighbour(int i, int j, int q, int nx, int ny) {
  int a = i + GR_SNOW_NEIGHBOUR_DI(q), b = j + GR_SNOW_NEIGHBOUR_DJ(q);
  return (a < 0 || b < 0 || a >= nx || b >= ny) ? gr_idx(i, j, nx) : gr_idx(a, b, nx);
}

/* Whether point (i, j) gives in iteration t of a launch whose givers'
 * window is [gx0, gx_end) x [gy0, gy_end) at its first iteration: the
 * window grows by one per iteration (snow leaves only its points, so only
 * points within one of it can have gained an excess). */
GR_INLINE int snow_giver(int i, int j, int t, int gx0, int gy0, int gx_end, int gy_end) {
  return i >= gx0 - t && j >= gy0 - t && i < gx_end + t && j < gy_end + t;
}

/* One-launch iteration t, first half: the rates on the launch (the move
 * window grown by one, so that every neighbour of a move has one), and
 * at t = 0 the movable amounts for the check. */
__kernel void snow_relax_rate(__global const float *restrict ground,
                              __global const float *restrict depth,
                              __global const float *restrict under_min, float clearance, int nx,
                              int ny, float tx, float ty, float td, float tol, int gx0, int gy0,
                              int gx_end, int gy_end, int t, int x_end, int y_end,
                              __global float *restrict rate, __global float *restrict rate_in,
                              __global float *restrict movable) {
  /* Launched on a window from its offset: the launch is rounded up to the
   * work-group shape (16 x 16 on a GPU), and a point beyond the window's end
   * must not run (its neighbours' rates there are stale). */
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny) || i >= x_end || j >= y_end)
    return;
  int c = gr_idx(i, j, nx);
  float sn[8], gn[8], un[8], k, kin, mv;
  for (int q = 0; q < 8; ++q) {
    int m = snow_neighbour(i, j, q, nx, ny);
    sn[q] = depth[m];
    gn[q] = ground[m];
    un[q] = under_min[m] - clearance; /* the ceiling (snow_excess) */
  }
  snow_rate_at(depth[c], ground[c], under_min[c] - clearance, sn, gn, un, tx, ty, td,
               snow_giver(i, j, t, gx0, gy0, gx_end, gy_end), tol, &k, &kin, &mv);
  rate[c] = k;
  rate_in[c] = kin;
  if (t == 0)
    movable[c] = mv;
}

/* One-launch iteration, second half: the moves, on the move window. */
__kernel void
snow_relax_move(__global const float *restrict ground, __global const float *restrict depth,
                __global const float *restrict density, __global const float *restrict under_min,
                __global const float *restrict rate, __global const float *restrict rate_in,
                float clearance, int nx, int ny, float tx, float ty, float td, int x_end, int y_end,
                __global float *restrict depth_out, __global float *restrict density_out) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny) || i >= x_end || j >= y_end)
    return; /* beyond the window (see snow_relax_rate) */
  int c = gr_idx(i, j, nx);
  float sn[8], gn[8], un[8], rn[8], kon[8], kinn[8], s1, r1;
  for (int q = 0; q < 8; ++q) {
    int m = snow_neighbour(i, j, q, nx, ny);
    sn[q] = depth[m];
    gn[q] = ground[m];
    un[q] = under_min[m] - clearance;
    rn[q] = density[m];
    kon[q] = rate[m];
    kinn[q] = rate_in[m];
  }
  snow_move_at(depth[c], density[c], ground[c], under_min[c] - clearance, rate[c], rate_in[c], sn,
               gn, un, rn, kon, kinn, tx, ty, td, &s1, &r1);
  depth_out[c] = s1;
  density_out[c] = r1;
}

/* The talus, GR_SNOW_BLOCK_ITERATIONS iterations per launch (temporal
 * blocking, for GPUs, where a launch costs more than its work): a
 * work-group loads its tile of lx x ly points and a halo of 2 per iteration
 * into local memory, iterates there, and writes the tile back. A point's
 * move depends on points two away (its rate on its neighbours' heights,
 * its move on its neighbours' rates), so after k iterations the tile is
 * still exact while the halo goes stale from its edge inwards, two a step.
 * The same functions as the one-launch iteration: the same bits.
 *
 * Local memory: 8 planes of (lx + 4 K) x (ly + 4 K) floats (K =
 * GR_SNOW_BLOCK_ITERATIONS): ground, lowest underside, depth and density
 * (two of each, ping-pong), k_out, k_in. The launch covers the move window
 * [its offset, x_end) x [.., y_end): only points there are written. */
__kernel void
snow_relax_block(__global const float *restrict ground, __global const float *restrict depth,
                 __global const float *restrict density, __global const float *restrict under_min,
                 float clearance, int nx, int ny, float tx, float ty, float td, float tol, int gx0,
                 int gy0, int gx_end, int gy_end, int x_end, int y_end, int iters,
                 __global float *restrict depth_out, __global float *restrict density_out,
                 __global float *restrict movable, __local float *restrict lmem) {
  const int lx = get_local_size(0), ly = get_local_size(1), halo = 2 * GR_SNOW_BLOCK_ITERATIONS;
  const int w = lx + 2 * halo, h = ly + 2 * halo, n = w * h;
  /* The grid point of local (0, 0). */
  const int ox = (int)get_global_offset(0) + (int)get_group_id(0) * lx - halo;
  const int oy = (int)get_global_offset(1) + (int)get_group_id(1) * ly - halo;
  const int lid = (int)get_local_id(1) * lx + (int)get_local_id(0), wg = lx * ly;
  __local float *G = lmem, *U = G + n, *S = U + n, *R = S + n, *S2 = R + n, *R2 = S2 + n,
                *KO = R2 + n, *KI = KO + n;
  for (int q = lid; q < n; q += wg) {
    int i = ox + q % w, j = oy + q / w;
    int on = i >= 0 && j >= 0 && i < nx && j < ny;
    int c = on ? gr_idx(i, j, nx) : 0;
    G[q] = on ? ground[c] : 0.0f;
    U[q] = on ? under_min[c] - clearance : INFINITY; /* the ceiling (snow_excess) */
    S[q] = on ? depth[c] : 0.0f;
    R[q] = on ? density[c] : 0.0f;
    KO[q] = KI[q] = 0.0f;
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  for (int t = 0; t < iters; ++t) {
    /* Only what the tile's last iteration needs: its moves on the tile,
     * its rates one further out, the iteration before two further, and so
     * on (the halo goes stale from its edge two a step anyway). */
    const int mr = halo - 2 * (iters - 1 - t) - 1, mm = mr + 1;
    for (int q = lid; q < n; q += wg) {
      int a = q % w, b = q / w, i = ox + a, j = oy + b;
      if (a < mr || b < mr || a >= w - mr || b >= h - mr || i < 0 || j < 0 || i >= nx || j >= ny)
        continue;
      float sn[8], gn[8], un[8], k, kin, mv;
      for (int e = 0; e < 8; ++e) {
        int di = GR_SNOW_NEIGHBOUR_DI(e), dj = GR_SNOW_NEIGHBOUR_DJ(e);
        int off = i + di < 0 || j + dj < 0 || i + di >= nx || j + dj >= ny;
        int m = off ? q : q + dj * w + di;
        sn[e] = S[m];
        gn[e] = G[m];
        un[e] = U[m];
      }
      snow_rate_at(S[q], G[q], U[q], sn, gn, un, tx, ty, td,
                   snow_giver(i, j, t, gx0, gy0, gx_end, gy_end), tol, &k, &kin, &mv);
      KO[q] = k;
      KI[q] = kin;
      if (t == 0 && a >= halo && b >= halo && a < halo + lx && b < halo + ly && i < x_end &&
          j < y_end)
        movable[gr_idx(i, j, nx)] = mv;
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    for (int q = lid; q < n; q += wg) {
      int a = q % w, b = q / w, i = ox + a, j = oy + b;
      if (a < mm || b < mm || a >= w - mm || b >= h - mm || i < 0 || j < 0 || i >= nx || j >= ny)
        continue;
      float sn[8], gn[8], un[8], rn[8], kon[8], kinn[8], s1, r1;
      for (int e = 0; e < 8; ++e) {
        int di = GR_SNOW_NEIGHBOUR_DI(e), dj = GR_SNOW_NEIGHBOUR_DJ(e);
        int off = i + di < 0 || j + dj < 0 || i + di >= nx || j + dj >= ny;
        int m = off ? q : q + dj * w + di;
        sn[e] = S[m];
        gn[e] = G[m];
        un[e] = U[m];
        rn[e] = R[m];
        kon[e] = KO[m];
        kinn[e] = KI[m];
      }
      snow_move_at(S[q], R[q], G[q], U[q], KO[q], KI[q], sn, gn, un, rn, kon, kinn, tx, ty, td, &s1,
                   &r1);
      S2[q] = s1;
      R2[q] = r1;
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    __local float *swap = S;
    S = S2;
    S2 = swap;
    swap = R;
    R = R2;
    R2 = swap;
  }
  for (int q = lid; q < lx * ly; q += wg) {
    int a = halo + q % lx, b = halo + q / lx, i = ox + a, j = oy + b;
    if (i >= nx || j >= ny || i >= x_end || j >= y_end)
      continue;
    int c = gr_idx(i, j, nx), m = b * w + a;
    depth_out[c] = S[m];
    density_out[c] = R[m];
  }
}

/* The talus' tail in one work-group: once the points still moving fit in
 * a small window, one launch runs the remaining iterations (at most cap)
 * instead of a launch or two per iteration and a check read back every few:
 * the work-group's barriers order the iterations, and it checks every
 * iteration itself. The same functions as the other launches, the same
 * window rule (the givers R: at first the host's window, then the box of
 * the points that could move more than tol grown by one), so the same bits;
 * it stops where nothing can move more than tol, at the cap, or when the
 * window's rates (R grown by two) exceed max_area points at an iteration
 * count (first, the iterations before the launch, plus those run) that is
 * a multiple of align (so that the launches after it keep their checks on
 * the same iterations), and leaves
 * in result the iterations run, whether nothing could move, and R (x0, y0,
 * x1, y1, inclusive). The state stays in depth/density (the moves go to
 * depth_tmp/density_tmp and are copied back on their window), so both
 * buffers of the pair equal each other wherever it wrote. */
__kernel void snow_relax_group(__global const float *restrict ground, __global float *depth,
                               __global float *density, __global float *depth_tmp,
                               __global float *density_tmp,
                               __global const float *restrict under_min, float clearance, int nx,
                               int ny, float tx, float ty, float td, float tol, int x0, int y0,
                               int x1, int y1, int cap, int max_area, int first, int align,
                               __global float *rate, __global float *rate_in,
                               __global int *restrict result) {
  __local int box[5]; /* the largest movable amount's bits, -x0, x1, -y0, y1 */
  const int lid = get_local_id(0), wg = get_local_size(0);
  int it = 0, still = 0;
  for (; it < cap; ++it) {
    if (x0 > x1 || y0 > y1)
      break;
    const int rx0 = max(x0 - 2, 0), ry0 = max(y0 - 2, 0), rx1 = min(x1 + 2, nx - 1),
              ry1 = min(y1 + 2, ny - 1), rw = rx1 - rx0 + 1, rn = rw * (ry1 - ry0 + 1);
    if (rn > max_area && (first + it) % align == 0) {
      still = 1;
      break;
    }
    if (lid == 0) {
      box[0] = 0;
      box[1] = box[2] = box[3] = box[4] = INT_MIN;
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    for (int q = lid; q < rn; q += wg) {
      int i = rx0 + q % rw, j = ry0 + q / rw, c = gr_idx(i, j, nx);
      float sn[8], gn[8], un[8], k, kin, mv;
      for (int e = 0; e < 8; ++e) {
        int m = snow_neighbour(i, j, e, nx, ny);
        sn[e] = depth[m];
        gn[e] = ground[m];
        un[e] = under_min[m] - clearance;
      }
      snow_rate_at(depth[c], ground[c], under_min[c] - clearance, sn, gn, un, tx, ty, td,
                   i >= x0 && i <= x1 && j >= y0 && j <= y1, tol, &k, &kin, &mv);
      rate[c] = k;
      rate_in[c] = kin;
      if (mv > tol) {
        atomic_max(&box[0], as_int(mv)); /* non-negative floats order as their bits */
        atomic_max(&box[1], -i);
        atomic_max(&box[2], i);
        atomic_max(&box[3], -j);
        atomic_max(&box[4], j);
      }
    }
    barrier(CLK_GLOBAL_MEM_FENCE | CLK_LOCAL_MEM_FENCE);
    const int moving = box[0] != 0, bx0 = -box[1], bx1 = box[2], by0 = -box[3], by1 = box[4];
    if (!moving)
      break; /* nothing gives: this iteration would change nothing */
    const int mx0 = max(x0 - 1, 0), my0 = max(y0 - 1, 0), mx1 = min(x1 + 1, nx - 1),
              my1 = min(y1 + 1, ny - 1), mw = mx1 - mx0 + 1, mn = mw * (my1 - my0 + 1);
    for (int q = lid; q < mn; q += wg) {
      int i = mx0 + q % mw, j = my0 + q / mw, c = gr_idx(i, j, nx);
      float sn[8], gn[8], un[8], rn[8], kon[8], kinn[8], s1, r1;
      for (int e = 0; e < 8; ++e) {
        int m = snow_neighbour(i, j, e, nx, ny);
        sn[e] = depth[m];
        gn[e] = ground[m];
        un[e] = under_min[m] - clearance;
        rn[e] = density[m];
        kon[e] = rate[m];
        kinn[e] = rate_in[m];
      }
      snow_move_at(depth[c], density[c], ground[c], under_min[c] - clearance, rate[c], rate_in[c],
                   sn, gn, un, rn, kon, kinn, tx, ty, td, &s1, &r1);
      depth_tmp[c] = s1;
      density_tmp[c] = r1;
    }
    barrier(CLK_GLOBAL_MEM_FENCE);
    for (int q = lid; q < mn; q += wg) {
      int c = gr_idx(mx0 + q % mw, my0 + q / mw, nx);
      depth[c] = depth_tmp[c];
      density[c] = density_tmp[c];
    }
    barrier(CLK_GLOBAL_MEM_FENCE);
    x0 = bx0 - 1, x1 = bx1 + 1, y0 = by0 - 1, y1 = by1 + 1;
    x0 = max(x0, 0), y0 = max(y0, 0), x1 = min(x1, nx - 1), y1 = min(y1, ny - 1);
  }
  if (lid == 0) {
    result[0] = it;
    result[1] = !still && it < cap; /* stopped because nothing could move */
    result[2] = x0;
    result[3] = y0;
    result[4] = x1;
    result[5] = y1;
  }
}

/* The reach: the points within h (8-neighbour steps) of a point of src
 * above thr in the box [sx0, sx1] x [sy0, sy1] (0 beyond it), a max filter
 * in two passes over the window [its offset, x_end) x [.., y_end): rows
 * (src to out, on the rows of the box) then columns (src, the rows'
 * result, to out). Integer logic on 0/1 floats: exact, whatever the split. */
__kernel void snow_reach_rows(__global const float *restrict src, float thr, int sx0, int sy0,
                              int sx1, int sy1, int h, int nx, int ny, int x_end, int y_end,
                              __global float *restrict out) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny) || i >= x_end || j >= y_end)
    return;
  float v = 0.0f;
  if (j >= sy0 && j <= sy1)
    for (int a = max(i - h, sx0); a <= min(i + h, sx1); ++a)
      v = src[gr_idx(a, j, nx)] > thr ? 1.0f : v;
  out[gr_idx(i, j, nx)] = v;
}

__kernel void snow_reach_cols(__global const float *restrict src, int sy0, int sy1, int h, int nx,
                              int ny, int x_end, int y_end, __global float *restrict out) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny) || i >= x_end || j >= y_end)
    return;
  float v = 0.0f;
  for (int b = max(j - h, sy0); b <= min(j + h, sy1); ++b)
    v = src[gr_idx(i, b, nx)] > 0.5f ? 1.0f : v;
  out[gr_idx(i, j, nx)] = v;
}

/* The reach's seeds on the window [its offset, x_end) x [.., y_end): the
 * movers (movable above tol, on the box [ax0, ax1] x [ay0, ay1] where it
 * was computed) and the points on a slope, those standing at least half
 * their talus threshold above a neighbour: the face of a heap, or a slope
 * at the talus angle, which what slides runs down as far as it goes; only
 * the flat snow beyond waits for the front. */
__kernel void snow_reach_seed(__global const float *restrict ground,
                              __global const float *restrict depth,
                              __global const float *restrict movable, float tol, int ax0, int ay0,
                              int ax1, int ay1, float tx, float ty, float td, int nx, int ny,
                              int x_end, int y_end, __global float *restrict reach) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny) || i >= x_end || j >= y_end)
    return;
  int c = gr_idx(i, j, nx);
  float v = (i >= ax0 && i <= ax1 && j >= ay0 && j <= ay1 && movable[c] > tol) ? 1.0f : 0.0f;
  float h = ground[c] + depth[c];
  for (int q = 0; q < 8 && v == 0.0f; ++q) {
    int m = snow_neighbour(i, j, q, nx, ny);
    float thr = snow_threshold(GR_SNOW_NEIGHBOUR_DI(q), GR_SNOW_NEIGHBOUR_DJ(q), tx, ty, td);
    if (h - (ground[m] + depth[m]) >= 0.5f * thr)
      v = 1.0f;
  }
  reach[c] = v;
}

/* The talus' ceilings under a reach (gr_snow_relax), on the window [its
 * offset, x_end) x [.., y_end): the lowest underside in the reach (the box
 * [bx0, bx1] x [by0, by1] and its mask), -inf out of it, where nothing fits
 * and snow_rate_at gives nothing: the talus kernels take this plane for
 * under_min. */
__kernel void snow_reach_ceiling(__global const float *restrict under_min,
                                 __global const float *restrict reach, int bx0, int by0, int bx1,
                                 int by1, int nx, int ny, int x_end, int y_end,
                                 __global float *restrict ceiling) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny) || i >= x_end || j >= y_end)
    return;
  int c = gr_idx(i, j, nx);
  int in = i >= bx0 && i <= bx1 && j >= by0 && j <= by1 && reach[c] > 0.5f;
  ceiling[c] = in ? under_min[c] : -INFINITY;
}

/* The largest movable amount on the window [x0, x0 + w) x [y0, y0 + h)
 * (n = w h points), and the box of the points that can still move more
 * than tol, as four maxima (-i, i, -j, j; -1e9 when there is none). */
__kernel void snow_check_reduce(__global const float *restrict movable, int nx, int x0, int y0,
                                int w, int n, float tol, __global float *restrict partial,
                                __local float *restrict scratch) {
  int lid = get_local_id(0), wg = get_local_size(0), start, end;
  gr_reduce_block(n, &start, &end);
  float m = 0.0f, bx0 = -1.0e9f, bx1 = -1.0e9f, by0 = -1.0e9f, by1 = -1.0e9f;
  for (int q = start + lid; q < end; q += wg) {
    int i = x0 + q % w, j = y0 + q / w;
    float v = movable[gr_idx(i, j, nx)];
    m = fmax(m, v);
    if (v > tol) {
      bx0 = fmax(bx0, (float)-i);
      bx1 = fmax(bx1, (float)i);
      by0 = fmax(by0, (float)-j);
      by1 = fmax(by1, (float)j);
    }
  }
  __local float *mine = gr_reduce_slots(scratch, 0, GR_SNOW_CHECK_MAXES);
  mine[0] = m;
  mine[1] = bx0;
  mine[2] = bx1;
  mine[3] = by0;
  mine[4] = by1;
  gr_reduce_group(scratch, 0, GR_SNOW_CHECK_MAXES, partial);
}

/* The ledger over the window [x0, x0 + w) x [y0, y0 + n / w) (a piece's own
 * points): sum S in quanta and sum S rho in 2^-24 kg/m^2. */
__kernel void snow_ledger_reduce(__global const float *restrict depth,
                                 __global const float *restrict density, int nx, int x0, int y0,
                                 int w, int n, __global long *restrict partial,
                                 __local long *restrict scratch) {
  int lid = get_local_id(0), wg = get_local_size(0), start, end;
  gr_reduce_block(n, &start, &end);
  long v = 0, m = 0;
  for (int q = start + lid; q < end; q += wg) {
    int c = gr_idx(x0 + q % w, y0 + q / w, nx);
    float s = depth[c];
    v += (long)rint(s * GR_SNOW_QUANTUM_INV);
    m += (long)rint((s * density[c]) * GR_SNOW_LEDGER_MASS_INV);
  }
  __local long *mine = gr_reduce_slots_long(scratch, GR_SNOW_LEDGER_SUMS);
  mine[0] = v;
  mine[1] = m;
  gr_reduce_group_long(scratch, GR_SNOW_LEDGER_SUMS, partial);
}

/* Snow surface B + S. */
__kernel void snow_surface(__global const float *restrict ground,
                           __global const float *restrict depth, int n,
                           __global float *restrict out) {
  int c = get_global_id(0);
  if (c < n)
    out[c] = ground[c] + depth[c];
}
