/* The rain_runoff program's local inertial model (FlowModel 1; the program
 * starts in rain_runoff.cl, which inlines this file): rain gain,
 * infiltration, and runoff by the local inertial approximation of the
 * shallow water equations (Bates, Horritt & Fewtrell 2010) on a staggered
 * grid. The model is documented in graupel/rain_runoff.h.
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
 *                       limited discharges q* K(upwind) into the new depth,
 *                       and the new state into the flood maps.
 * On GPUs the last two are one launch, rain_runoff_limit_update (the same
 * floats; see there).
 * The face arrays keep q* and the cell array K: the discharge that flows is
 * q* K(upwind cell), the same float from the same two inputs in both cells
 * that share the face, so what leaves one cell arrives in the other. Rain
 * and infiltration are recomputed by each launch from the same inputs with
 * the same expression (FP_CONTRACT is off), which gives the same float
 * every time; only the last launch writes the depth. Every expression is
 * written so that a mirrored face computes the exact negative, and sums over
 * a cell's faces pair the mirrored terms: mirror-symmetric inputs give
 * mirror-symmetric fields bit for bit. */

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

/* The cell beyond a domain edge of kind `kind` for the local inertial faces
 * (graupel/rain_runoff.h, "Boundaries"): its depth *hg and bed *bg from the
 * edge cell's depth hc (after rain and infiltration) and bed bc, and the bed
 * bi of the edge cell's inner neighbour. A wall's and an outfall's is dry at
 * bc (as before there were kinds); a transmissive edge continues the depth
 * over the continued bed slope; a level edge holds water up to its level
 * over bc (none when the level is below the ground: a free outfall). */
GR_INLINE void gr_rain_runoff_ghost(int kind, float level, float hc, float bc, float bi, float *hg,
                                    float *bg) {
  bool tr = kind == GR_RAIN_RUNOFF_B_TRANSMISSIVE, lv = kind == GR_RAIN_RUNOFF_B_LEVEL;
  *hg = tr ? hc : (lv ? fmax(level - bc, 0.0f) : 0.0f);
  *bg = tr ? bc - (bi - bc) : bc;
}

/* The arguments of gr_rain_runoff_li_face that rain_runoff_flux and
 * rain_runoff_li_step pass as they got them. */
#define GR_RAIN_RUNOFF_LI_FACE_ARGS                                                                \
  __global const float *restrict h, __global const float *restrict b,                              \
      __global const float *restrict rain, __global const float *restrict perm,                    \
      __global const float *restrict src, int use_src, __global const float *restrict nodata,      \
      int use_nodata, __global const float *restrict limit, float dt, float g, float n2,           \
      __global const float *restrict n2map, int use_n2, float theta, int use_rain,                 \
      float rain_uniform, int use_perm, float perm_uniform
#define GR_RAIN_RUNOFF_LI_FACE_PASS                                                                \
  h, b, rain, perm, src, use_src, nodata, use_nodata, limit, dt, g, n2, n2map, use_n2, theta,      \
      use_rain, rain_uniform, use_perm, perm_uniform

/* The local inertial q* through the face below cell c along one axis:
 * between cell c - cs (the low side; cs 1 along x, nx along y) and cell c
 * (hc, bc, kc: its depth after rain and infiltration, bed and limiter; 0,
 * 0, 1 beyond the grid), the face's index along the axis k of 0 .. n (0
 * and n: the grid's edge faces, which lead into a dry ghost at the edge
 * cell's ground and pass outflow only), the face f in the discharges q_old
 * of the previous step, fs apart along the axis. The previous discharges
 * are limited by their upwind cells' K and smoothed along the axis
 * (gr_rain_runoff_smooth); an edge face takes its one cell's roughness.
 * rain_runoff_flux and rain_runoff_li_step call it, so their faces are the
 * same floats. */
GR_INLINE float gr_rain_runoff_li_face(GR_RAIN_RUNOFF_LI_FACE_ARGS,
                                       __global const float *restrict q_old, int k, int n, int c,
                                       int cs, int f, int fs, float inv_d, float hc, float bc,
                                       float kc) {
  int w = c - cs;
  bool in_w = k > 0;
  float hw = in_w ? gr_rain_runoff_wet(h[w], GR_RAIN_RUNOFF_RAIN(w), GR_RAIN_RUNOFF_SRC(w),
                                       GR_RAIN_RUNOFF_PERM(w), dt)
                  : 0.0f;
  float bw = in_w ? b[w] : 0.0f;
  float kw = in_w ? limit[w] : 1.0f;
  float hL = k == 0 ? 0.0f : hw, bL = k == 0 ? bc : bw;
  float hR = k == n ? 0.0f : hc, bR = k == n ? bw : bc;
  float own = gr_rain_runoff_limited(q_old[f], kw, kc);
  float before =
      k > 0 ? gr_rain_runoff_limited(q_old[f - fs], k > 1 ? limit[c - 2 * cs] : 1.0f, kw) : 0.0f;
  float after =
      k < n ? gr_rain_runoff_limited(q_old[f + fs], kc, k < n - 1 ? limit[c + cs] : 1.0f) : 0.0f;
  float prev = gr_rain_runoff_smooth(own, before, after, theta, k == 0 || k == n);
  float n2f = gr_rain_runoff_face_n2(n2map, use_n2, n2, in_w ? w : c, k < n ? c : w);
  float q = gr_rain_runoff_face(hL, hR, bL, bR, prev, own, dt, g, n2f, inv_d);
  q = k == 0 ? fmin(q, 0.0f) : q;
  return k == n ? fmax(q, 0.0f) : q;
}

/* Work-item (i, j) of an (nx+1) x (ny+1) launch owns the x-face left of cell
 * (i, j) (for j < ny) and the y-face below it (for i < nx). The grid's edge
 * faces are those of an open edge here: they lead into a dry ghost cell at
 * the edge cell's ground height, and only outflow passes; the edges of
 * other kinds are rewritten by rain_runoff_flux_edges after this launch
 * (kinds known only at run time cost this kernel half its speed on PoCL). The discharges of
 * the previous step are read from qx_old, qy_old and the new ones written
 * to qx, qy (the face arrays alternate between steps).
 *
 * Every index is linear in i and a load beyond the grid is masked instead
 * of clamped, so that CPU compilers (PoCL) vectorise with contiguous loads
 * (clamped indices became gathers, three times slower). A masked limiter
 * reads as 1 and a masked depth as 0: where that happens, the value is not
 * used (an edge face's discharge only ever leaves its edge cell). */
__kernel void
rain_runoff_flux(__global const float *restrict h, __global const float *restrict b,
                 __global const float *restrict rain, __global const float *restrict perm,
                 __global const float *restrict src, int use_src,
                 __global const float *restrict nodata, int use_nodata,
                 __global const float *restrict qx_old, __global const float *restrict qy_old,
                 __global float *restrict qx, __global float *restrict qy,
                 __global const float *restrict limit, int nx, int ny, float dt, float inv_dx,
                 float inv_dy, float g, float n2, __global const float *restrict n2map, int use_n2,
                 float theta, int use_rain, float rain_uniform, int use_perm, float perm_uniform) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx + 1, ny + 1))
    return;
  int c = gr_idx(i, j, nx);
  bool in_c = i < nx && j < ny;
  float hc = in_c ? gr_rain_runoff_wet(h[c], GR_RAIN_RUNOFF_RAIN(c), GR_RAIN_RUNOFF_SRC(c),
                                       GR_RAIN_RUNOFF_PERM(c), dt)
                  : 0.0f;
  float bc = in_c ? b[c] : 0.0f;
  float kc = in_c ? limit[c] : 1.0f;
  /* Cell (i-1, j) is L, cell (i, j) is R; at the edges one is the ghost. */
  if (j < ny)
    qx[j * (nx + 1) + i] = gr_rain_runoff_li_face(GR_RAIN_RUNOFF_LI_FACE_PASS, qx_old, i, nx, c, 1,
                                                  j * (nx + 1) + i, 1, inv_dx, hc, bc, kc);
  /* y-faces are numbered like cells, with one more row. */
  if (i < nx)
    qy[c] = gr_rain_runoff_li_face(GR_RAIN_RUNOFF_LI_FACE_PASS, qy_old, j, ny, c, nx, c, nx, inv_dy,
                                   hc, bc, kc);
}

/* The faces of the domain's edges whose kind is not open (those the flux
 * kernel leaves as open), one work-item per edge face: west faces (ny), east
 * (ny), south (nx), north (nx). Each is the flux kernel's face expression
 * with the cell beyond the edge of its kind (gr_rain_runoff_ghost) and its
 * own previous discharge (edges are not smoothed), passed as the kind lets
 * it (gr_rain_runoff_edge_q): a mirrored edge gives the negated discharge. */
__kernel void rain_runoff_flux_edges(
    __global const float *restrict h, __global const float *restrict b,
    __global const float *restrict rain, __global const float *restrict perm,
    __global const float *restrict src, int use_src, __global const float *restrict nodata,
    int use_nodata, __global const float *restrict qx_old, __global const float *restrict qy_old,
    __global float *restrict qx, __global float *restrict qy, __global const float *restrict limit,
    int nx, int ny, float dt, float inv_dx, float inv_dy, float g, float n2,
    __global const float *restrict n2map, int use_n2, int use_rain, float rain_uniform,
    int use_perm, float perm_uniform, int bnd_w, int bnd_e, int bnd_s, int bnd_n, float lvl_w,
    float lvl_e, float lvl_s, float lvl_n) {
  int k = get_global_id(0);
  if (k >= 2 * (nx + ny))
    return;
  int side = k < ny ? 0 : (k < 2 * ny ? 1 : (k < 2 * ny + nx ? 2 : 3));
  int t = side == 0 ? k : (side == 1 ? k - ny : (side == 2 ? k - 2 * ny : k - 2 * ny - nx));
  int kind = side == 0 ? bnd_w : (side == 1 ? bnd_e : (side == 2 ? bnd_s : bnd_n));
  float level = side == 0 ? lvl_w : (side == 1 ? lvl_e : (side == 2 ? lvl_s : lvl_n));
  if (kind == GR_RAIN_RUNOFF_B_OPEN)
    return;
  bool xs = side < 2, low = side == 0 || side == 2;
  int len = xs ? nx : ny, stride = xs ? 1 : nx;
  /* The edge cell, its inner neighbour (for a transmissive edge's slope)
   * and the face (x-face rows are nx + 1 wide; y-faces numbered like cells). */
  int c = xs ? t * nx + (low ? 0 : nx - 1) : (low ? 0 : ny - 1) * nx + t;
  int inner = len > 1 ? (low ? c + stride : c - stride) : c;
  int f = xs ? t * (nx + 1) + (low ? 0 : nx) : (low ? 0 : ny) * nx + t;
  float hc = gr_rain_runoff_wet(h[c], GR_RAIN_RUNOFF_RAIN(c), GR_RAIN_RUNOFF_SRC(c),
                                GR_RAIN_RUNOFF_PERM(c), dt);
  float bc = b[c], kc = limit[c];
  float hg, bg;
  gr_rain_runoff_ghost(kind, level, hc, bc, b[inner], &hg, &bg);
  float old = xs ? qx_old[f] : qy_old[f];
  float own = low ? gr_rain_runoff_limited(old, 1.0f, kc) : gr_rain_runoff_limited(old, kc, 1.0f);
  float n2f = gr_rain_runoff_face_n2(n2map, use_n2, n2, c, c);
  float inv_d = xs ? inv_dx : inv_dy;
  float q = low ? gr_rain_runoff_face(hg, hc, bg, bc, own, own, dt, g, n2f, inv_d)
                : gr_rain_runoff_face(hc, hg, bc, bg, own, own, dt, g, n2f, inv_d);
  q = gr_rain_runoff_edge_q(kind, q, low);
  if (xs)
    qx[f] = q;
  else
    qy[f] = q;
}

/* K = min(1, depth / outgoing depth in dt), a little less when limiting (see
 * GR_RAIN_RUNOFF_KEEP), from the cell's depth after rain and infiltration
 * (wet) and its four faces' q*. Outgoing terms are summed in
 * mirror-symmetric pairs.
 * The x and y sums written differently (-min(qw, 0) is max(-qw, 0) but
 * for the sign of a zero, which adding a value >= +0 drops) and the y sum
 * waiting for the x sum (+ 0 ox: ox is finite and >= 0), so that CPU
 * compilers do not pair them into <2 x float> values, which kept PoCL
 * from vectorising the limit kernel; the same floats. */
GR_INLINE float gr_rain_runoff_k(float wet, float qw, float qe, float qs, float qn, float dt,
                                 float inv_dx, float inv_dy) {
  float ox = -fmin(qw, 0.0f) + fmax(qe, 0.0f);
  float oy = (fmax(-qs, 0.0f) + fmax(qn, 0.0f)) + 0.0f * ox;
  float out = dt * (ox * inv_dx + oy * inv_dy);
  return out > wet ? wet / out * GR_RAIN_RUNOFF_KEEP : 1.0f;
}

__kernel void rain_runoff_limit(__global const float *restrict h,
                                __global const float *restrict rain,
                                __global const float *restrict perm,
                                __global const float *restrict src, int use_src,
                                __global const float *restrict nodata, int use_nodata,
                                __global const float *restrict qx,
                                __global const float *restrict qy, __global float *restrict limit,
                                int nx, int ny, float dt, float inv_dx, float inv_dy, int use_rain,
                                float rain_uniform, int use_perm, float perm_uniform) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny))
    return;
  int c = gr_idx(i, j, nx);
  float wet = gr_rain_runoff_wet(h[c], GR_RAIN_RUNOFF_RAIN(c), GR_RAIN_RUNOFF_SRC(c),
                                 GR_RAIN_RUNOFF_PERM(c), dt);
  float qw = qx[j * (nx + 1) + i], qe = qx[j * (nx + 1) + i + 1];
  float qs = qy[j * nx + i], qn = qy[(j + 1) * nx + i];
  limit[c] = gr_rain_runoff_k(wet, qw, qe, qs, qn, dt, inv_dx, inv_dy);
}

/* The kinematic rate (1/s) at a face from cell L to cell R, d apart: the
 * film's celerity over d, as a step takes it. dq'/dh of gr_rain_runoff_face
 * is 5/3 of the Manning speed h_f^(2/3) sqrt|S| / n on a long step (friction
 * dominates) and at most (10/3) g |S| dt on a short one (inertia does), over
 * the face's depth and surface slope as the face writes them (so L and R
 * swapped give the same float). Of the two, the bound the step meets first:
 * min(5/3 u / d, sqrt(cfl (10/3) g |S| / d)), so that dt <= cfl / rate keeps
 * dt dq'/dh / d <= cfl either way. 0 for a dry face. */
GR_INLINE float gr_rain_runoff_film_rate(float hL, float hR, float bL, float bR, float n2,
                                         float inv_d, float g, float cfl) {
  float db = bR - bL;
  float hf = db >= 0.0f ? fmax(hR, hL - db) : fmax(hL, hR + db);
  float slope = fabs(db + (hR - hL)) * inv_d;
  /* hf^(4/3) = hf^2 hf^(-2/3) */
  float y = gr_rain_runoff_rcbrt(fmax(hf, GR_RAIN_RUNOFF_DRY));
  float friction = (5.0f / 3.0f) * sqrt(hf * hf * (y * y) * slope / n2) * inv_d;
  float inertia = sqrt(cfl * (10.0f / 3.0f) * g * slope * inv_d);
  return hf < GR_RAIN_RUNOFF_DRY || !(n2 > 0.0f) ? 0.0f : fmin(friction, inertia);
}

/* The local inertial model's kinematic rate for the stable step (see
 * gr_rain_runoff_stable_dt_impl), reduced like rain_runoff_sw_speed: the
 * largest rate of the faces of the owned cells. Faces within the local
 * array only (the domain's edge faces take their cell's own depth and bed
 * slope, which its inner face sees too), and none into a no-data cell
 * (whose wall or cliff is no slope of the terrain). Each face once: cell c
 * takes the face west of it in the owned rows from the first owned column
 * to the one past the last (whose west neighbour is owned), and the face
 * south of it likewise; a face's rate is the same float whichever side
 * computes it, so the maximum is the same whichever way the domain is
 * split (and as when each cell took its four faces, at half the cost: the
 * rate's cube root costs a few multiplications per face). */
__kernel void rain_runoff_li_speed(__global const float *restrict h,
                                   __global const float *restrict b,
                                   __global const float *restrict nodata, int use_nodata,
                                   __global const float *restrict n2map, int use_n2, float n2,
                                   __global float *restrict partial,
                                   __local float *restrict scratch, int n, int row, int rows,
                                   int own_x0, int own_x1, int own_y0, int own_y1, float inv_dx,
                                   float inv_dy, float g, float cfl) {
  int lid = get_local_id(0), wg = get_local_size(0), start, end;
  gr_reduce_block(n, &start, &end);
  float rate = 0.0f;
  for (int c = start + lid; c < end; c += wg) {
    int i = c % row, j = c / row;
    if (!GR_RAIN_RUNOFF_ACTIVE(c))
      continue;
    float hc = h[c], bc = b[c];
    if (j >= own_y0 && j < own_y1 && i >= own_x0 && i <= own_x1 && i > 0 &&
        GR_RAIN_RUNOFF_ACTIVE(c - 1))
      rate = fmax(rate, gr_rain_runoff_film_rate(
                            h[c - 1], hc, b[c - 1], bc,
                            gr_rain_runoff_face_n2(n2map, use_n2, n2, c - 1, c), inv_dx, g, cfl));
    if (i >= own_x0 && i < own_x1 && j >= own_y0 && j <= own_y1 && j > 0 && j < rows &&
        GR_RAIN_RUNOFF_ACTIVE(c - row))
      rate = fmax(rate, gr_rain_runoff_film_rate(
                            h[c - row], hc, b[c - row], bc,
                            gr_rain_runoff_face_n2(n2map, use_n2, n2, c - row, c), inv_dy, g, cfl));
  }
  __local float *mine = gr_reduce_slots(scratch, 0, 1);
  mine[0] = rate;
  gr_reduce_group(scratch, 0, 1, partial);
}

/* The new depth of cell c = (i, j) from its depth h0 before the step, its
 * rain r, permeability k and source sc, its limiter kc and its neighbours'
 * (kw, ke, ks, kn; 1 beyond the grid) and its four faces' q* (qw, qe, qs,
 * qn), written to h_out; edge cells book what left (outflow) and what came
 * in (inflow) through the domain's edges; the new state goes into the
 * flood maps. rain_runoff_update and rain_runoff_li_step both call it.
 * The depth is Kahan-summed too (h - h_comp is the water to about twice
 * float precision): its rounding would otherwise be the same in every step
 * where a pond gains the same rain, and 10^5 such steps would show in the
 * water balance. */
GR_INLINE void gr_rain_runoff_update_cell(
    int i, int j, long c, int nx, int ny, float h0, float r, float k, float sc, float kc, float kw,
    float ke, float ks, float kn, float qw, float qe, float qs, float qn,
    __global float *restrict h_out, __global float *restrict h_comp,
    __global const float *restrict nodata, int use_nodata, __global float *restrict infiltrated,
    __global float *restrict infiltrated_comp, __global float *restrict outflow,
    __global float *restrict outflow_comp, __global float *restrict inflow,
    __global float *restrict inflow_comp, float dt, float inv_dx, float inv_dy,
    GR_RAIN_RUNOFF_MAP_ARGS, float4 map_time) {
#if GR_RAIN_RUNOFF_GPU
  /* On GPUs everything the update reads of global memory is loaded
   * before it stores anything (the shallow-water stages' gr_sw_cell_read):
   * NVIDIA's compiler keeps a load after an earlier store to another
   * array, so read where they are used the compensation, the flood maps
   * and the infiltration waited on the stores before them (with the
   * program's register cap lifted and 32 x 4 work-groups the H200's update
   * at 4096^2 took 0.58 ms instead of 0.67). The same floats. */
  gr_rain_runoff_maps_at mm = gr_rain_runoff_maps_read(0, GR_RAIN_RUNOFF_MAP_PASS_AT(c));
  float inf_sum = infiltrated[c], inf_comp = infiltrated_comp[c], comp0 = h_comp[c];
#else
  float comp0 = h_comp[c];
#endif
  float inf = gr_rain_runoff_infiltration(h0, r, sc, k, dt);
  float fw = gr_rain_runoff_limited(qw, kw, kc);
  float fe = gr_rain_runoff_limited(qe, kc, ke);
  float fs = gr_rain_runoff_limited(qs, ks, kc);
  float fn = gr_rain_runoff_limited(qn, kc, kn);
  float delta = ((r * dt - inf) + sc * dt) + dt * ((fw - fe) * inv_dx + (fs - fn) * inv_dy);
  float y = delta - comp0;
  float t = h0 + y;
  float comp = (t - h0) - y;
  /* The limiter keeps t >= 0 but for rounding; a cell that ends at or
   * below 0 is dry, with nothing owed. An outfall no-data cell drains. */
  /* The helpers below get the arrays from cell c on (their index 0): c
   * is a long here, whose addresses CPU compilers see as consecutive in
   * rain_runoff_li_step, where an int's are not (see there). */
  float gone = gr_rain_runoff_drain(nodata + c, use_nodata, 0, t, comp);
  float d = t > 0.0f && gone == 0.0f ? t : 0.0f;
  h_out[c] = d;
  h_comp[c] = t > 0.0f && gone == 0.0f ? comp : 0.0f;
  /* The flood maps from the new state, with the velocity VELOCITY reads
   * (rain_runoff_derive's: an edge face limited by its own cell's K); the
   * cell was wet for them if the depth the step started from, which the
   * fold before left, was above the wetting depth. */
  bool was_wet = h0 > wetting_depth;
  float mw = i > 0 ? fw : gr_rain_runoff_limited(qw, kc, kc);
  float me = i < nx - 1 ? fe : gr_rain_runoff_limited(qe, kc, kc);
  float ms = j > 0 ? fs : gr_rain_runoff_limited(qs, kc, kc);
  float mn = j < ny - 1 ? fn : gr_rain_runoff_limited(qn, kc, kc);
#if GR_RAIN_RUNOFF_GPU
  gr_rain_runoff_map_fold(0, was_wet, d, 0.5f * (mw + me), 0.5f * (ms + mn), mm,
                          GR_RAIN_RUNOFF_MAP_PASS_AT(c), map_time);
#else
  gr_rain_runoff_map_cell(0, was_wet, d, 0.5f * (mw + me), 0.5f * (ms + mn),
                          GR_RAIN_RUNOFF_MAP_PASS_AT(c), map_time);
#endif
  if (gone != 0.0f)
    gr_kahan_add(outflow + c, outflow_comp + c, 0, gone);
#if GR_RAIN_RUNOFF_GPU
  if (inf != 0.0f)
    gr_kahan_store(infiltrated + c, infiltrated_comp + c, 0, inf_sum, inf_comp, inf);
#else
  if (inf != 0.0f)
    gr_kahan_add(infiltrated + c, infiltrated_comp + c, 0, inf);
#endif
  /* The sources' water is inflow, the very float the depth gained. */
  if (sc != 0.0f)
    gr_kahan_add(inflow + c, inflow_comp + c, 0, sc * dt);
  if (i == 0 || j == 0 || i == nx - 1 || j == ny - 1) {
    /* What the edge faces carry out of the cell (negative: in). */
    float ow = i == 0 ? -fw : 0.0f, oe = i == nx - 1 ? fe : 0.0f;
    float os = j == 0 ? -fs : 0.0f, on = j == ny - 1 ? fn : 0.0f;
    gr_rain_runoff_book_edges(outflow + c, outflow_comp + c, inflow + c, inflow_comp + c, 0, dt,
                              inv_dx, inv_dy, ow, oe, os, on);
  }
}

/* The new depth from rain, infiltration and the four faces' limited
 * discharges (gr_rain_runoff_update_cell). */
__kernel void
rain_runoff_update(__global float *restrict h, __global float *restrict h_comp,
                   __global const float *restrict rain, __global const float *restrict perm,
                   __global const float *restrict src, int use_src,
                   __global const float *restrict nodata, int use_nodata,
                   __global const float *restrict qx, __global const float *restrict qy,
                   __global const float *restrict limit, __global float *restrict infiltrated,
                   __global float *restrict infiltrated_comp, __global float *restrict outflow,
                   __global float *restrict outflow_comp, __global float *restrict inflow,
                   __global float *restrict inflow_comp, int nx, int ny, float dt, float inv_dx,
                   float inv_dy, int use_rain, float rain_uniform, int use_perm, float perm_uniform,
                   GR_RAIN_RUNOFF_MAP_ARGS, float4 map_time) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny))
    return;
  int c = gr_idx(i, j, nx);
  float kc = limit[c];
  /* Masked, not clamped, neighbours (see rain_runoff_flux): an edge face
   * never uses the limiter beyond the grid. */
  float kw = i > 0 ? limit[c - 1] : 1.0f, ke = i < nx - 1 ? limit[c + 1] : 1.0f;
  float ks = j > 0 ? limit[c - nx] : 1.0f, kn = j < ny - 1 ? limit[c + nx] : 1.0f;
  float qw = qx[j * (nx + 1) + i], qe = qx[j * (nx + 1) + i + 1];
  float qs = qy[j * nx + i], qn = qy[(j + 1) * nx + i];
  gr_rain_runoff_update_cell(i, j, c, nx, ny, h[c], GR_RAIN_RUNOFF_RAIN(c), GR_RAIN_RUNOFF_PERM(c),
                             GR_RAIN_RUNOFF_SRC(c), kc, kw, ke, ks, kn, qw, qe, qs, qn, h, h_comp,
                             nodata, use_nodata, infiltrated, infiltrated_comp, outflow,
                             outflow_comp, inflow, inflow_comp, dt, inv_dx, inv_dy,
                             GR_RAIN_RUNOFF_MAP_PASS, map_time);
}

/* rain_runoff_limit and rain_runoff_update in one launch (GPUs: the
 * limiter's own launch read the depth and the faces and wrote K, which the
 * update read again): each work-item computes K of its cell and of its four
 * neighbours from their depths after rain and infiltration and their faces
 * (gr_rain_runoff_k, as rain_runoff_limit: the same floats), writes its
 * own K to limit, and updates its cell (gr_rain_runoff_update_cell). The
 * neighbours' K needs their depths at the step's start, so the depth is
 * read from h and the new one written to h_out (the host swaps them after
 * the step, as after rain_runoff_li_step). On the H200 at 4096^2 the step
 * took 0.646 ms against 0.680 with the two launches: the limiter's launch
 * and its 16 bytes a cell gone, its five limiters a cell recomputed from
 * the caches. Taller work-groups (32 x 8: 0.663, 32 x 16: 0.686) and the
 * neighbours' K from local memory within the work-group (0.654) were
 * slower than the 32 x 4 of the other launches. */
__kernel void rain_runoff_limit_update(
    __global const float *restrict h, __global float *restrict h_out,
    __global float *restrict h_comp, __global const float *restrict rain,
    __global const float *restrict perm, __global const float *restrict src, int use_src,
    __global const float *restrict nodata, int use_nodata, __global const float *restrict qx,
    __global const float *restrict qy, __global float *restrict limit,
    __global float *restrict infiltrated, __global float *restrict infiltrated_comp,
    __global float *restrict outflow, __global float *restrict outflow_comp,
    __global float *restrict inflow, __global float *restrict inflow_comp, int nx, int ny, float dt,
    float inv_dx, float inv_dy, int use_rain, float rain_uniform, int use_perm, float perm_uniform,
    GR_RAIN_RUNOFF_MAP_ARGS, float4 map_time) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny))
    return;
  int c = gr_idx(i, j, nx);
  float qw = qx[j * (nx + 1) + i], qe = qx[j * (nx + 1) + i + 1];
  float qs = qy[j * nx + i], qn = qy[(j + 1) * nx + i];
  float h0 = h[c], r = GR_RAIN_RUNOFF_RAIN(c), k = GR_RAIN_RUNOFF_PERM(c),
        sc = GR_RAIN_RUNOFF_SRC(c);
  /* rain_runoff_limit's K of cell m = (mi, mj) (masked, not clamped,
   * neighbours: 1 beyond the grid, as rain_runoff_update takes it). */
#define GR_LU_K(m, mi, mj)                                                                         \
  gr_rain_runoff_k(gr_rain_runoff_wet(h[m], GR_RAIN_RUNOFF_RAIN(m), GR_RAIN_RUNOFF_SRC(m),         \
                                      GR_RAIN_RUNOFF_PERM(m), dt),                                 \
                   qx[(mj) * (nx + 1) + (mi)], qx[(mj) * (nx + 1) + (mi) + 1], qy[(mj)*nx + (mi)], \
                   qy[((mj) + 1) * nx + (mi)], dt, inv_dx, inv_dy)
  float kc =
      gr_rain_runoff_k(gr_rain_runoff_wet(h0, r, sc, k, dt), qw, qe, qs, qn, dt, inv_dx, inv_dy);
  float kw = i > 0 ? GR_LU_K(c - 1, i - 1, j) : 1.0f;
  float ke = i < nx - 1 ? GR_LU_K(c + 1, i + 1, j) : 1.0f;
  float ks = j > 0 ? GR_LU_K(c - nx, i, j - 1) : 1.0f;
  float kn = j < ny - 1 ? GR_LU_K(c + nx, i, j + 1) : 1.0f;
#undef GR_LU_K
  gr_rain_runoff_update_cell(i, j, c, nx, ny, h0, r, k, sc, kc, kw, ke, ks, kn, qw, qe, qs, qn,
                             h_out, h_comp, nodata, use_nodata, infiltrated, infiltrated_comp,
                             outflow, outflow_comp, inflow, inflow_comp, dt, inv_dx, inv_dy,
                             GR_RAIN_RUNOFF_MAP_PASS, map_time);
  /* After the update's stores: it loads everything before them. */
  limit[c] = kc;
}

/* The local inertial step in one launch (FlowModel 1; the same floats as
 * rain_runoff_flux, rain_runoff_limit and rain_runoff_update in turn: the
 * same expressions, FP_CONTRACT off). A work-group of lx x ly work-items
 * owns a tile of (lx - 3) x (ly - 3) cells; tiles overlap by 3 columns and
 * rows, and work-item (a, b) stands for cell (x0 - 1 + a, y0 - 1 + b) of
 * the tile at (x0, y0):
 *   1. the x-face left of its cell (rows b < ly - 1) and the y-face below
 *      it (columns a < lx - 1), as rain_runoff_flux writes them: every face
 *      of the tile's cells and of the ring of cells around them, into
 *      local memory with the cell's depth after rain and infiltration; the
 *      tile's own faces (and the grid's east and north edge faces in the
 *      last tiles) also to qx, qy;
 *   2. for the tile's cells, the limiter K of the cell and of its four
 *      neighbours from the faces in local memory (the cell's own also to
 *      limit_out), then the continuity update (gr_rain_runoff_update_cell).
 * A face reads cells up to two away (and the limiters up to two more in
 * line), all of the step's start: h and limit are read and h_out and
 * limit_out written (the host swaps them after the step), as the face
 * arrays alternate. Edges of other kinds than open (bit e of `fixed`: west,
 * east, south, north) were written to qx, qy by rain_runoff_flux_edges,
 * launched before: those faces are read from there. Local memory: 3 lx ly
 * floats (lmem). */
__kernel void rain_runoff_li_step(
    __global const float *restrict h, __global float *restrict h_out,
    __global float *restrict h_comp, __global const float *restrict b,
    __global const float *restrict rain, __global const float *restrict perm,
    __global const float *restrict src, int use_src, __global const float *restrict nodata,
    int use_nodata, __global const float *restrict qx_old, __global const float *restrict qy_old,
    __global float *restrict qx, __global float *restrict qy, __global const float *restrict limit,
    __global float *restrict limit_out, int nx, int ny, float dt, float inv_dx, float inv_dy,
    float g, float n2, __global const float *restrict n2map, int use_n2, float theta, int use_rain,
    float rain_uniform, int use_perm, float perm_uniform, __global float *restrict infiltrated,
    __global float *restrict infiltrated_comp, __global float *restrict outflow,
    __global float *restrict outflow_comp, __global float *restrict inflow,
    __global float *restrict inflow_comp, int fixed, GR_RAIN_RUNOFF_MAP_ARGS, float4 map_time,
    __local float *restrict lmem) {
  const int lx = (int)get_local_size(0), ly = (int)get_local_size(1);
  const int a = (int)get_local_id(0), bl = (int)get_local_id(1);
  const int x0 = (int)get_group_id(0) * (lx - 3), y0 = (int)get_group_id(1) * (ly - 3);
  const int i = x0 - 1 + a, j = y0 - 1 + bl, l = bl * lx + a;
  __local float *fxl = lmem, *fyl = lmem + lx * ly, *wl = lmem + 2 * lx * ly;
  int c = j * nx + i;
  bool in_c = i >= 0 && j >= 0 && i < nx && j < ny;
  float hc = in_c ? gr_rain_runoff_wet(h[c], GR_RAIN_RUNOFF_RAIN(c), GR_RAIN_RUNOFF_SRC(c),
                                       GR_RAIN_RUNOFF_PERM(c), dt)
                  : 0.0f;
  float bc = in_c ? b[c] : 0.0f;
  float kc = in_c ? limit[c] : 1.0f;
  /* Rows and columns the tile owns (faces: also the grid's far edge). */
  bool row_own = bl >= 1 && bl < ly - 2, col_own = a >= 1 && a < lx - 2;
  float fxv = 0.0f, fyv = 0.0f;
  if (bl < ly - 1 && j >= 0 && j < ny && i >= 0 && i <= nx) {
    /* rain_runoff_flux's x-face (i, j). */
    int f = j * (nx + 1) + i;
    float q = gr_rain_runoff_li_face(GR_RAIN_RUNOFF_LI_FACE_PASS, qx_old, i, nx, c, 1, f, 1, inv_dx,
                                     hc, bc, kc);
    bool kept = (i == 0 && (fixed & 1)) || (i == nx && (fixed & 2));
    if (kept)
      q = qx[f];
    else if (row_own && (col_own || (a == lx - 2 && i == nx)))
      qx[f] = q;
    fxv = q;
  }
  if (a < lx - 1 && i >= 0 && i < nx && j >= 0 && j <= ny) {
    /* rain_runoff_flux's y-face (i, j). */
    int f = c;
    float q = gr_rain_runoff_li_face(GR_RAIN_RUNOFF_LI_FACE_PASS, qy_old, j, ny, c, nx, c, nx,
                                     inv_dy, hc, bc, kc);
    bool kept = (j == 0 && (fixed & 4)) || (j == ny && (fixed & 8));
    if (kept)
      q = qy[f];
    else if (col_own && (row_own || (bl == ly - 2 && j == ny)))
      qy[f] = q;
    fyv = q;
  }
  fxl[l] = fxv;
  fyl[l] = fyv;
  /* The cell's depth after rain and infiltration for the limiter, -1 off
   * the grid. */
  wl[l] = in_c ? hc : -1.0f;
  barrier(CLK_LOCAL_MEM_FENCE);
  /* Nothing computed before the barrier is used after it, and the
   * work-item's indices are computed anew as longs, so that the compiler
   * cannot share them with the ints above: PoCL keeps values that live
   * across a barrier in an array per work-item, and indices read back from
   * there made LLVM gather and scatter every access after the barrier (a
   * step 4x slower on PoCL). */
  const long a2 = (long)get_local_id(0), b2 = (long)get_local_id(1);
  const long i2 = x0 - 1 + a2, j2 = y0 - 1 + b2, l2 = b2 * lx + a2, c2 = j2 * nx + i2;
  if (i2 < nx && j2 < ny && a2 >= 1 && a2 < lx - 2 && b2 >= 1 && b2 < ly - 2) {
    /* rain_runoff_limit's K of the cell and its four neighbours (each
     * neighbour's again in the cells around it: a third region would need
     * a third way to compute the indices, see above); 1 beyond the grid,
     * as rain_runoff_update takes it there. */
#define GR_LI_K(m)                                                                                 \
  (wl[m] >= 0.0f                                                                                   \
       ? gr_rain_runoff_k(wl[m], fxl[m], fxl[(m) + 1], fyl[m], fyl[(m) + lx], dt, inv_dx, inv_dy)  \
       : 1.0f)
    float kc = GR_LI_K(l2);
    limit_out[c2] = kc;
    gr_rain_runoff_update_cell(
        (int)i2, (int)j2, c2, nx, ny, h[c2], GR_RAIN_RUNOFF_RAIN(c2), GR_RAIN_RUNOFF_PERM(c2),
        GR_RAIN_RUNOFF_SRC(c2), kc, GR_LI_K(l2 - 1), GR_LI_K(l2 + 1), GR_LI_K(l2 - lx),
        GR_LI_K(l2 + lx), fxl[l2], fxl[l2 + 1], fyl[l2], fyl[l2 + lx], h_out, h_comp, nodata,
        use_nodata, infiltrated, infiltrated_comp, outflow, outflow_comp, inflow, inflow_comp, dt,
        inv_dx, inv_dy, GR_RAIN_RUNOFF_MAP_PASS, map_time);
#undef GR_LI_K
  }
}
