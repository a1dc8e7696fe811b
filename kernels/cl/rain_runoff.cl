/* Rain on terrain (seed 004, notes/004.md 2.4-2.7 with the conservative
 * deviation of item 17): rain gain, infiltration, and runoff by the local
 * inertial approximation of the shallow water equations (Bates, Horritt &
 * Fewtrell 2010) on a staggered grid. The model is documented in
 * graupel/rain_runoff.h.
 *
 * State: depth h (cells) with a Kahan compensation, discharges qx ((nx+1) x
 * ny faces, row stride nx+1) and qy (nx x (ny+1) faces, numbered like cells
 * with one more row) in two sets that alternate between steps, the outflow
 * limiter K of every cell, the cumulative infiltration and boundary outflow
 * per cell (metres of depth) with their Kahan compensations.
 *
 * One step is three launches, each a gather that writes only what its own
 * work-item owns:
 *   rain_runoff_flux    per face: the unlimited discharge q* from the depth
 *                       after rain and infiltration and the previous step's
 *                       limited discharges (q*_prev K_prev(upwind)) of the
 *                       face and its two neighbours in line;
 *   rain_runoff_limit   per cell: K = the share of its outgoing q* it can
 *                       afford without going below zero;
 *   rain_runoff_update  per cell: rain, infiltration and the four faces'
 *                       limited discharges q* K(upwind) into the new depth.
 * The face arrays keep q* and the cell array K: the discharge that flows is
 * q* K(upwind cell), the same float from the same two inputs in both cells
 * that share the face, so what leaves one cell arrives in the other. Rain
 * and infiltration are recomputed by each launch from the same inputs with
 * the same expression (FP_CONTRACT is off), which gives the same float
 * every time; only the last launch writes the depth. Every expression is
 * written so that a mirrored face computes the exact negative, and sums over
 * a cell's faces pair the mirrored terms: mirror-symmetric inputs give
 * mirror-symmetric fields bit for bit. */
#include "common.h"
#include "rain_runoff_shared.h"
#include "reduce.h"

GR_INLINE float gr_rain_runoff_input(__global const float *restrict field, int use_field,
                                     float uniform, int c) {
  return use_field ? field[c] : uniform;
}

/* Depth after rain gain (h + r dt) and infiltration (at most k dt, never more
 * than the water there). */
GR_INLINE float gr_rain_runoff_wet(float h, float r, float k, float dt) {
  float h1 = h + r * dt;
  return h1 - fmin(k * dt, h1);
}

GR_INLINE float gr_rain_runoff_infiltration(float h, float r, float k, float dt) {
  float h1 = h + r * dt;
  return fmin(k * dt, h1);
}

/* x^(-7/3) for x > 0 (a normal float), the friction's depth factor: x^(-1/3)
 * from an exponent-thirding first guess and three Newton steps (2e-7
 * relative), to the seventh power. Plain multiplications, unlike a library
 * cbrt or pow, which PoCL calls per work-item (the flux kernel was seven
 * times slower with cbrt); and the same answer on every IEEE device. */
GR_INLINE float gr_rain_runoff_pow_m73(float x) {
  float y = as_float(0x54a21d2au - as_uint(x) / 3u);
  y = y * (4.0f - x * y * y * y) * (1.0f / 3.0f);
  y = y * (4.0f - x * y * y * y) * (1.0f / 3.0f);
  y = y * (4.0f - x * y * y * y) * (1.0f / 3.0f);
  float y2 = y * y;
  return y2 * y2 * y2 * y;
}

/* q' from q'(1 + kf |q'|) = m: the friction taken implicitly, solved
 * exactly (and without cancellation). */
GR_INLINE float gr_rain_runoff_solve(float m, float kf) {
  return 2.0f * m / (1.0f + sqrt(1.0f + 4.0f * kf * fabs(m)));
}

/* The local inertial discharge through a face from cell L to cell R
 * (positive towards R), m^2/s, from the previous discharge smoothed (q~) or
 * the face's own (q). Written in terms of differences, so that depths far
 * smaller than the float spacing of large elevations still move, and so that
 * the mirrored face (L and R swapped) gives exactly the negated discharge:
 *   h_f = max(eta_L, eta_R) - max(b_L, b_R)
 *       = db >= 0 ? max(h_R, h_L - db) : max(h_L, h_R + db),   db = b_R - b_L
 *   S   = (eta_R - eta_L) / d = (db + (h_R - h_L)) / d
 *   m   = q~ - g h_f dt S,   q' (1 + g dt n^2 |q'| / h_f^(7/3)) = m.
 * Where q' would flow against the surface slope (momentum carried over from
 * the neighbouring faces, e.g. across a nearly dry cell), m takes the face's
 * own q instead, as LISFLOOD-FP does. */
GR_INLINE float gr_rain_runoff_face(float hL, float hR, float bL, float bR, float smooth, float own,
                                    float dt, float g, float n2, float inv_d) {
  float db = bR - bL;
  float hf = db >= 0.0f ? fmax(hR, hL - db) : fmax(hL, hR + db);
  float deta = db + (hR - hL);
  float push = g * hf * dt * (deta * inv_d);
  float hs = fmax(hf, GR_RAIN_RUNOFF_DRY);
  float kf = g * dt * n2 * gr_rain_runoff_pow_m73(hs);
  float q = gr_rain_runoff_solve(smooth - push, kf);
  q = q * deta > 0.0f ? gr_rain_runoff_solve(own - push, kf) : q;
  return hf < GR_RAIN_RUNOFF_DRY ? 0.0f : q;
}

/* The discharge that flowed through a face: q* scaled by the limiter of the
 * cell it leaves. */
GR_INLINE float gr_rain_runoff_limited(float q, float k_low, float k_high) {
  return q * (q > 0.0f ? k_low : k_high);
}

/* The previous step's discharge through a face, smoothed along the flow
 * direction (de Almeida, Bates, Freer & Souvignet 2012):
 *   theta q_f + (1 - theta) (q_before + q_after) / 2
 * of the limited discharges of the face and its two neighbours in line.
 * Without it the scheme keeps ripples a few cells long on deep, smooth water
 * indefinitely. The grid's edge faces keep their own discharge. */
GR_INLINE float gr_rain_runoff_smooth(float own, float before, float after, float theta,
                                      bool edge) {
  float smooth = theta * own + (1.0f - theta) * 0.5f * (before + after);
  return edge ? own : smooth;
}

/* Work-item (i, j) of an (nx+1) x (ny+1) launch owns the x-face left of cell
 * (i, j) (for j < ny) and the y-face below it (for i < nx). The grid's edge
 * faces are walls when closed; when open they lead into a dry ghost cell at
 * the edge cell's ground height, and only outflow passes. The discharges of
 * the previous step are read from qx_old, qy_old and the new ones written
 * to qx, qy (the face arrays alternate between steps).
 *
 * Every index is linear in i and a load beyond the grid is masked instead
 * of clamped, so that CPU compilers (PoCL) vectorise with contiguous loads
 * (clamped indices became gathers, three times slower). A masked limiter
 * reads as 1 and a masked depth as 0: where that happens, the value is not
 * used (an edge face's discharge only ever leaves its edge cell). */
__kernel void rain_runoff_flux(__global const float *restrict h, __global const float *restrict b,
                               __global const float *restrict rain,
                               __global const float *restrict perm,
                               __global const float *restrict qx_old,
                               __global const float *restrict qy_old, __global float *restrict qx,
                               __global float *restrict qy, __global const float *restrict limit,
                               int nx, int ny, float dt, float inv_dx, float inv_dy, float g,
                               float n2, float theta, int use_rain, float rain_uniform,
                               int use_perm, float perm_uniform, int closed) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx + 1, ny + 1))
    return;
  int c = gr_idx(i, j, nx);
  bool in_c = i < nx && j < ny;
  float hc = in_c ? gr_rain_runoff_wet(h[c], gr_rain_runoff_input(rain, use_rain, rain_uniform, c),
                                       gr_rain_runoff_input(perm, use_perm, perm_uniform, c), dt)
                  : 0.0f;
  float bc = in_c ? b[c] : 0.0f;
  float kc = in_c ? limit[c] : 1.0f;
  if (j < ny) {
    /* Cell (i-1, j) is L, cell (i, j) is R; at the edges one is the ghost. */
    int w = c - 1;
    bool in_w = i > 0;
    float hw = in_w
                   ? gr_rain_runoff_wet(h[w], gr_rain_runoff_input(rain, use_rain, rain_uniform, w),
                                        gr_rain_runoff_input(perm, use_perm, perm_uniform, w), dt)
                   : 0.0f;
    float bw = in_w ? b[w] : 0.0f;
    float kw = in_w ? limit[w] : 1.0f;
    float hL = i == 0 ? 0.0f : hw, bL = i == 0 ? bc : bw;
    float hR = i == nx ? 0.0f : hc, bR = i == nx ? bw : bc;
    int f = j * (nx + 1) + i;
    float own = gr_rain_runoff_limited(qx_old[f], kw, kc);
    float before =
        i > 0 ? gr_rain_runoff_limited(qx_old[f - 1], i > 1 ? limit[c - 2] : 1.0f, kw) : 0.0f;
    float after =
        i < nx ? gr_rain_runoff_limited(qx_old[f + 1], kc, i < nx - 1 ? limit[c + 1] : 1.0f) : 0.0f;
    float prev = gr_rain_runoff_smooth(own, before, after, theta, i == 0 || i == nx);
    float q = gr_rain_runoff_face(hL, hR, bL, bR, prev, own, dt, g, n2, inv_dx);
    if (i == 0)
      q = closed ? 0.0f : fmin(q, 0.0f);
    if (i == nx)
      q = closed ? 0.0f : fmax(q, 0.0f);
    qx[f] = q;
  }
  if (i < nx) {
    int s = c - nx;
    bool in_s = j > 0;
    float hs = in_s
                   ? gr_rain_runoff_wet(h[s], gr_rain_runoff_input(rain, use_rain, rain_uniform, s),
                                        gr_rain_runoff_input(perm, use_perm, perm_uniform, s), dt)
                   : 0.0f;
    float bs = in_s ? b[s] : 0.0f;
    float ks = in_s ? limit[s] : 1.0f;
    float hL = j == 0 ? 0.0f : hs, bL = j == 0 ? bc : bs;
    float hR = j == ny ? 0.0f : hc, bR = j == ny ? bs : bc;
    int f = c; /* y-faces are numbered like cells, with one more row */
    float own = gr_rain_runoff_limited(qy_old[f], ks, kc);
    float before =
        j > 0 ? gr_rain_runoff_limited(qy_old[f - nx], j > 1 ? limit[c - 2 * nx] : 1.0f, ks) : 0.0f;
    float after =
        j < ny ? gr_rain_runoff_limited(qy_old[f + nx], kc, j < ny - 1 ? limit[c + nx] : 1.0f)
               : 0.0f;
    float prev = gr_rain_runoff_smooth(own, before, after, theta, j == 0 || j == ny);
    float q = gr_rain_runoff_face(hL, hR, bL, bR, prev, own, dt, g, n2, inv_dy);
    if (j == 0)
      q = closed ? 0.0f : fmin(q, 0.0f);
    if (j == ny)
      q = closed ? 0.0f : fmax(q, 0.0f);
    qy[f] = q;
  }
}

/* K = min(1, depth / outgoing depth in dt), a little less when limiting (see
 * GR_RAIN_RUNOFF_KEEP). Outgoing terms are summed in mirror-symmetric pairs. */
__kernel void rain_runoff_limit(__global const float *restrict h,
                                __global const float *restrict rain,
                                __global const float *restrict perm,
                                __global const float *restrict qx,
                                __global const float *restrict qy, __global float *restrict limit,
                                int nx, int ny, float dt, float inv_dx, float inv_dy, int use_rain,
                                float rain_uniform, int use_perm, float perm_uniform) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny))
    return;
  int c = gr_idx(i, j, nx);
  float wet = gr_rain_runoff_wet(h[c], gr_rain_runoff_input(rain, use_rain, rain_uniform, c),
                                 gr_rain_runoff_input(perm, use_perm, perm_uniform, c), dt);
  float qw = qx[j * (nx + 1) + i], qe = qx[j * (nx + 1) + i + 1];
  float qs = qy[j * nx + i], qn = qy[(j + 1) * nx + i];
  float out = dt * ((fmax(-qw, 0.0f) + fmax(qe, 0.0f)) * inv_dx +
                    (fmax(-qs, 0.0f) + fmax(qn, 0.0f)) * inv_dy);
  limit[c] = out > wet ? wet / out * GR_RAIN_RUNOFF_KEEP : 1.0f;
}

/* The new depth from rain, infiltration and the four faces' limited
 * discharges; edge cells of an open grid book what left through the edge.
 * The depth is Kahan-summed too (h - h_comp is the water to about twice
 * float precision): its rounding would otherwise be the same in every step
 * where a pond gains the same rain, and 10^5 such steps would show in the
 * water balance. */
__kernel void
rain_runoff_update(__global float *restrict h, __global float *restrict h_comp,
                   __global const float *restrict rain, __global const float *restrict perm,
                   __global const float *restrict qx, __global const float *restrict qy,
                   __global const float *restrict limit, __global float *restrict infiltrated,
                   __global float *restrict infiltrated_comp, __global float *restrict outflow,
                   __global float *restrict outflow_comp, int nx, int ny, float dt, float inv_dx,
                   float inv_dy, int use_rain, float rain_uniform, int use_perm,
                   float perm_uniform) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny))
    return;
  int c = gr_idx(i, j, nx);
  float r = gr_rain_runoff_input(rain, use_rain, rain_uniform, c);
  float k = gr_rain_runoff_input(perm, use_perm, perm_uniform, c);
  float h0 = h[c];
  float inf = gr_rain_runoff_infiltration(h0, r, k, dt);
  float kc = limit[c];
  /* Masked, not clamped, neighbours (see rain_runoff_flux): an edge face
   * never uses the limiter beyond the grid. */
  float kw = i > 0 ? limit[c - 1] : 1.0f, ke = i < nx - 1 ? limit[c + 1] : 1.0f;
  float ks = j > 0 ? limit[c - nx] : 1.0f, kn = j < ny - 1 ? limit[c + nx] : 1.0f;
  float fw = gr_rain_runoff_limited(qx[j * (nx + 1) + i], kw, kc);
  float fe = gr_rain_runoff_limited(qx[j * (nx + 1) + i + 1], kc, ke);
  float fs = gr_rain_runoff_limited(qy[j * nx + i], ks, kc);
  float fn = gr_rain_runoff_limited(qy[(j + 1) * nx + i], kc, kn);
  float delta = (r * dt - inf) + dt * ((fw - fe) * inv_dx + (fs - fn) * inv_dy);
  float y = delta - h_comp[c];
  float t = h0 + y;
  float comp = (t - h0) - y;
  /* The limiter keeps t >= 0 but for rounding; a cell that ends at or
   * below 0 is dry, with nothing owed. */
  h[c] = t > 0.0f ? t : 0.0f;
  h_comp[c] = t > 0.0f ? comp : 0.0f;
  if (inf != 0.0f)
    gr_kahan_add(infiltrated, infiltrated_comp, c, inf);
  if (i == 0 || j == 0 || i == nx - 1 || j == ny - 1) {
    /* Edge faces carry outflow only (0 when closed). */
    float ow = i == 0 ? -fw : 0.0f, oe = i == nx - 1 ? fe : 0.0f;
    float os = j == 0 ? -fs : 0.0f, on = j == ny - 1 ? fn : 0.0f;
    float out = dt * ((ow + oe) * inv_dx + (os + on) * inv_dy);
    if (out != 0.0f)
      gr_kahan_add(outflow, outflow_comp, c, out);
  }
}

/* One pass over the grid for the ledger (reduce.h): per work-group the
 * stored, infiltrated and outflow depths (double-float, metres summed over
 * cells) and the deepest cell; masked: only the cells [own_x0, own_x1) x
 * [own_y0, own_y1) of the row-wide local array (a piece without its ring). */
__kernel void rain_runoff_reduce(
    __global const float *restrict h, __global const float *restrict h_comp,
    __global const float *restrict infiltrated, __global const float *restrict infiltrated_comp,
    __global const float *restrict outflow, __global const float *restrict outflow_comp,
    __global float *restrict partial, __local float *restrict scratch, int n, int row, int own_x0,
    int own_x1, int own_y0, int own_y1, int masked) {
  int lid = get_local_id(0), wg = get_local_size(0), start, end;
  gr_reduce_block(n, &start, &end);
  float s_hi = 0.0f, s_lo = 0.0f, i_hi = 0.0f, i_lo = 0.0f, o_hi = 0.0f, o_lo = 0.0f;
  float hmax = 0.0f;
  for (int c = start + lid; c < end; c += wg) {
    if (masked) {
      /* A piece sums its own cells only: its ring belongs to a neighbour. */
      int i = c % row, j = c / row;
      if (i < own_x0 || i >= own_x1 || j < own_y0 || j >= own_y1)
        continue;
    }
    float d = h[c];
    gr_df_add(&s_hi, &s_lo, d);
    gr_df_add(&s_hi, &s_lo, -h_comp[c]);
    gr_df_add(&i_hi, &i_lo, infiltrated[c]);
    gr_df_add(&i_hi, &i_lo, -infiltrated_comp[c]);
    gr_df_add(&o_hi, &o_lo, outflow[c]);
    gr_df_add(&o_hi, &o_lo, -outflow_comp[c]);
    hmax = fmax(hmax, d);
  }
  __local float *mine = gr_reduce_slots(scratch, GR_RAIN_RUNOFF_SUMS, GR_RAIN_RUNOFF_MAXES);
  mine[0] = s_hi;
  mine[1] = s_lo;
  mine[2] = i_hi;
  mine[3] = i_lo;
  mine[4] = o_hi;
  mine[5] = o_lo;
  mine[6] = hmax;
  gr_reduce_group(scratch, GR_RAIN_RUNOFF_SUMS, GR_RAIN_RUNOFF_MAXES, partial);
}

/* Fields derived on read, per cell: 0 water surface (b + h), 1 velocity
 * (3 components, m/s, 0 below GR_RAIN_RUNOFF_VELOCITY_DEPTH), 2 discharge |q|
 * (m^2/s, cell-centred average of the faces), 3 infiltrated (cumulative,
 * m). */
__kernel void rain_runoff_derive(__global const float *restrict h, __global const float *restrict b,
                                 __global const float *restrict qx,
                                 __global const float *restrict qy,
                                 __global const float *restrict limit,
                                 __global const float *restrict infiltrated,
                                 __global const float *restrict infiltrated_comp,
                                 __global float *restrict out, int nx, int ny, int what) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny))
    return;
  int c = gr_idx(i, j, nx);
  if (what == 0) {
    out[c] = b[c] + h[c];
    return;
  }
  if (what == 3) {
    out[c] = infiltrated[c] - infiltrated_comp[c];
    return;
  }
  float kc = limit[c];
  float fw = gr_rain_runoff_limited(qx[j * (nx + 1) + i], limit[gr_idx(max(i - 1, 0), j, nx)], kc);
  float fe = gr_rain_runoff_limited(qx[j * (nx + 1) + i + 1], kc,
                                    limit[gr_idx(min(i + 1, nx - 1), j, nx)]);
  float fs = gr_rain_runoff_limited(qy[j * nx + i], limit[gr_idx(i, max(j - 1, 0), nx)], kc);
  float fn =
      gr_rain_runoff_limited(qy[(j + 1) * nx + i], kc, limit[gr_idx(i, min(j + 1, ny - 1), nx)]);
  float u = 0.5f * (fw + fe), v = 0.5f * (fs + fn);
  if (what == 2) {
    out[c] = sqrt(u * u + v * v);
    return;
  }
  float d = h[c];
  int wet = d >= GR_RAIN_RUNOFF_VELOCITY_DEPTH;
  out[3 * c] = wet ? u / d : 0.0f;
  out[3 * c + 1] = wet ? v / d : 0.0f;
  out[3 * c + 2] = 0.0f;
}
