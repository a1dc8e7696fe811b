/* The rain_runoff program's shallow-water model (the program starts in
 * rain_runoff.cl, which inlines this file where it is built with
 * GR_RAIN_RUNOFF_SW; its fused stages in tiles are in rain_runoff_sw_tiles.cl,
 * inlined below).
 *
 * FlowModel 0 (graupel/rain_runoff.h), the default: the 2-D shallow-water
 * equations by finite volumes, cell-centred state (h, qu = h u, qv = h v).
 * Fluxes: HLL
 * on the hydrostatic reconstruction of Audusse, Bouchut, Bristeau, Klein &
 * Perthame (2004), second order: minmod slopes of the depth, the surface
 * (as bed differences plus depth differences, so that large elevations
 * lose nothing to rounding; flat within the depths' rounding, gr_sw_rise),
 * and the velocities; Heun's method (SSP-RK2) in time. A step is nine
 * launches, each a gather that writes only what its own work-item owns:
 * rain_runoff_sw_prep (stage 1's points: the depth
 * after rain and infiltration, the velocities), then per stage
 * rain_runoff_sw_faces* and rain_runoff_sw_rim* (every face once, the
 * interior's without the edges' cases, then the rim's, stored: the two cells
 * that share it read the same floats, so the mass that leaves one cell is
 * the float that arrives in the other), rain_runoff_sw_update* (every cell from its
 * four faces; stage 2 also folds the new state into the flood maps) and
 * rain_runoff_sw_edges (the rim's cells book the stage's edge flows).
 * Every face reads two cells either side of it, so a stage reads two cells
 * away and a step four: a piece's ring is GR_RAIN_RUNOFF_GHOST_SW cells and
 * the halo is exchanged once per step. On GPUs the step is two launches
 * instead (rain_runoff_sw_stage1, 2: the same functions, faces in local
 * memory; see gr_sw_fused). Computing each face once instead of
 * in both its cells, and keeping <2 x float> values out of the kernels (see
 * gr_sw_pt, gr_sw_hll), made the step 4-6x faster on PoCL, the same floats. */

/* Depth below which a cell's velocity is desingularised (Kurganov & Petrova
 * 2007): u = 2 h q / (h^2 + max(h^2, eps^2)), which is q / h above it and
 * falls smoothly to 0 with the depth below it, so films a step leaves
 * behind at a front do not get huge velocities from rounding. */
#define GR_RAIN_RUNOFF_SW_EPS 1.0e-5f

GR_INLINE float gr_sw_velocity(float h, float q) {
  float h2 = h * h;
  return 2.0f * h * q / (h2 + fmax(h2, GR_RAIN_RUNOFF_SW_EPS * GR_RAIN_RUNOFF_SW_EPS));
}

/* The smaller slope where both have one sign, else 0. Two forms of the
 * same floats: on GPUs (GR_RAIN_RUNOFF_GPU) the smaller of the two where it
 * is positive, the larger where it is negative, selected from values both
 * computed, since NVIDIA's compiler made the tests of each sign into
 * branches, eight a face, diverging wherever neighbouring slopes differ in
 * sign (the H200's shallow-water step at 4096^2 took 1.51 ms with them and
 * the HLL speeds' branches, 1.40 without); on CPUs the tests of each sign, since PoCL pairs the
 * other form's fmin and fmax into a <2 x float> and then runs the stage
 * kernels scalar (1024^2: 28 ms a step became 90), and the smaller or the
 * larger of two of one sign as a comparison: fmin and fmax, which must
 * handle a NaN (never one here: both slopes passed a test of their sign),
 * cost PoCL three instructions each, and the faces' kernel a sixth of its
 * vector instructions (the same floats; 1024^2: 56.9 ms a step became
 * 48.6). */
GR_INLINE float gr_sw_minmod(float a, float b) {
#if GR_RAIN_RUNOFF_GPU
  float lo = fmin(a, b), hi = fmax(a, b);
  return lo > 0.0f ? lo : (hi < 0.0f ? hi : 0.0f);
#else
  return a > 0.0f && b > 0.0f ? (b < a ? b : a) : (a < 0.0f && b < 0.0f ? (b > a ? b : a) : 0.0f);
#endif
}

/* A cell of a line: depth, bed, velocity along and across the line. The
 * fifth float is never read: a struct of four floats is passed and returned
 * as two <2 x float> registers under the x86-64 ABI, and such vector values
 * kept PoCL's vectoriser off every kernel that used one (a step 5x slower);
 * one of five floats is passed in memory, which inlining then removes. */
typedef struct gr_sw_pt {
  float h, b, un, ut, abi;
} gr_sw_pt;

/* One cell's reconstruction along an axis: its depth h, bed b, normal and
 * tangential velocities un, ut, and the slopes (full-cell differences) of
 * the depth, of the surface (se: bed differences plus depth differences,
 * gr_sw_rise), of the bed under the reconstructed surface (sb = se - sh),
 * and of the velocities. */
typedef struct gr_sw_cell {
  float h, b, un, ut, sh, se, sb, sun, sut;
} gr_sw_cell;

/* The surface's rise from cell m to cell p, (b_p - b_m) + (h_p - h_m): bed
 * and depth differences, so that large elevations lose nothing to rounding,
 * and 0 where it is within the depths' own rounding, GR_RAIN_RUNOFF_SW_FLAT
 * (h_m + h_p). A lake given as depths level - b (or as its level: the core
 * turns a water_surface into those depths) has them rounded wherever
 * b < level / 2, so its surface is level only to half an ulp of the depth;
 * a scheme that took that rise for a slope stirred a frictionless lake to
 * 7e-6 m/s in 10^4 s (the depths move by whole ulps only, so the push never
 * balances). Such a lake's rise, as computed here, stays within
 * FLT_EPSILON (h_m + h_p) (10^7 random lakes, levels 0.01 to 1000 m, beds
 * of either sign); twice that is flat, far below any flow (5e-7 m on 1 m of
 * water, 5e-11 m on 0.1 mm). */
#define GR_RAIN_RUNOFF_SW_FLAT (2.0f * FLT_EPSILON)

GR_INLINE float gr_sw_rise(gr_sw_pt m, gr_sw_pt p, float after) {
  /* On CPUs + 0 after: the flat depth waits for another rise (after is
   * finite, the sum exact), so that CPU compilers do not pair two rises
   * into a <2 x float> before vectorising across work-items (see
   * gr_sw_hll); GPUs have no vectoriser to steer, and the same floats cost
   * them two instructions fewer a rise. */
  float d = (p.b - m.b) + (p.h - m.h);
#if GR_RAIN_RUNOFF_GPU
  float flat = GR_RAIN_RUNOFF_SW_FLAT * (m.h + p.h);
#else
  float flat = GR_RAIN_RUNOFF_SW_FLAT * (m.h + p.h) + 0.0f * fabs(after);
#endif
  return fabs(d) <= flat ? 0.0f : d;
}

/* Cell p between its neighbours m and q along the line, its slopes 0 unless
 * both neighbours exist (both): computed either way and selected, without
 * a branch, so that CPU compilers vectorise across work-items. */
GR_INLINE gr_sw_cell gr_sw_recon(gr_sw_pt m, gr_sw_pt p, gr_sw_pt q, bool both) {
  gr_sw_cell c;
  c.h = p.h;
  c.b = p.b;
  c.un = p.un;
  c.ut = p.ut;
  float dhm = p.h - m.h, dhp = q.h - p.h;
  float dem = gr_sw_rise(m, p, 0.0f), dep = gr_sw_rise(p, q, dem);
  float sh = gr_sw_minmod(dhm, dhp), se = gr_sw_minmod(dem, dep);
  c.sh = both ? sh : 0.0f;
  c.se = both ? se : 0.0f;
  c.sb = both ? se - sh : 0.0f;
  c.sun = both ? gr_sw_minmod(p.un - m.un, q.un - p.un) : 0.0f;
  c.sut = both ? gr_sw_minmod(p.ut - m.ut, q.ut - p.ut) : 0.0f;
  return c;
}

/* HLL flux between two states (depth, normal and tangential velocity) along
 * the normal: mass, normal momentum; the tangential momentum is carried
 * upwind with the mass. Dry sides take the dry-front speeds. */
GR_INLINE void gr_sw_hll(float hL, float uL, float vL, float hR, float uR, float vR, float g,
                         float *fh, float *fm, float *ft) {
  /* Every branch computed and the right one selected: CPU compilers then
   * vectorise across work-items (a dry pair's NaN is never selected). */
  bool dryL = hL <= 0.0f, dryR = hR <= 0.0f;
  /* cR waits for cL (0 cL is +0: cL is finite and >= 0; g hR + 0 is g hR
   * but for the sign of a zero, and cR is never read where hR is 0), so
   * that CPU compilers do not pair the two square roots into a <2 x float>
   * before vectorising across work-items, which such values prevent. */
#if GR_RAIN_RUNOFF_GPU
  float cL = sqrt(g * hL), cR = sqrt(g * hR); /* GPUs: as gr_sw_rise */
#else
  float cL = sqrt(g * hL), cR = sqrt(g * hR + 0.0f * cL);
#endif
  /* Each speed's three cases computed, then selected (nested conditionals
   * of expressions compiled to branches on NVIDIA devices). */
#if GR_RAIN_RUNOFF_GPU
  float lo_w = fmin(uL - cL, uR - cR), hi_w = fmax(uL + cL, uR + cR);
#else
  /* On CPUs as comparisons: fmin and fmax cost PoCL three instructions
   * each for a NaN that never comes (finite velocities and depths); where
   * the two are equal zeros of either sign, the speed's sign is never read
   * (sL >= 0 and sR <= 0 hold for both, and their quotient w is selected
   * away), so the fluxes are the same floats. */
  float aL = uL - cL, aR = uR - cR, bL = uL + cL, bR = uR + cR;
  float lo_w = aR < aL ? aR : aL, hi_w = bR > bL ? bR : bL;
#endif
  float lo_dl = uR - 2.0f * cR, lo_dr = uL - cL;
  float hi_dr = uL + 2.0f * cL, hi_dl = uR + cR;
  float sL = dryL ? lo_dl : (dryR ? lo_dr : lo_w);
  float sR = dryR ? hi_dr : (dryL ? hi_dl : hi_w);
  float qL = hL * uL, qR = hR * uR;
  float mL = qL * uL + 0.5f * g * hL * hL, mR = qR * uR + 0.5f * g * hR * hR;
  /* (sR F_L - sL F_R + sL sR (U_R - U_L)) / (sR - sL), written as F_L plus
   * a difference so that equal states give F_L exactly (a lake at rest
   * then balances to the bit). */
  float w = sL / (sR - sL);
  float mass = qL + w * (sR * (hR - hL) - (qR - qL));
  float mom = mL + w * (sR * (qR - qL) - (mR - mL));
  bool left = sL >= 0.0f, right = sR <= 0.0f, none = dryL && dryR;
  mass = none ? 0.0f : (left ? qL : (right ? qR : mass));
  mom = none ? 0.0f : (left ? mL : (right ? mR : mom));
  *fh = mass;
  *fm = mom;
  *ft = mass * (mass > 0.0f ? vL : vR);
}

/* The face between reconstructed cells L and R (R on the high side): the
 * hydrostatic reconstruction at the face's bed max(b_L, b_R) (the
 * difference db = b_R - b_L of the two sides' face beds, so a flat bed
 * keeps the depths exactly), the HLL flux, and the normal momentum flux as
 * seen by L (fmL) and by R (fmR) less the hydrostatic pressure of each
 * side's own face depth, g h^2 / 2, which gr_sw_balance adds back with the bed
 * source in one product that vanishes where the surface is flat: a lake at
 * rest then balances to the bit, not to rounding. Between two cells of the
 * grid (inner), the side on the lower face bed is cut to the other side's
 * depth less the surface's rise across the face (d, gr_sw_rise of the two
 * cells, less their half slopes), the depth hL - db would give in exact
 * arithmetic: where the surface is flat (d and the slopes 0) both sides are
 * then the same float. A ghost's face is at its cell's face bed (db = 0,
 * gr_sw_ghost), which keeps both depths. */
GR_INLINE void gr_sw_face(gr_sw_cell L, gr_sw_cell R, bool inner, float d, float g, float *fh,
                          float *fmL, float *fmR, float *ft) {
  float hL = L.h + 0.5f * L.sh, hR = R.h - 0.5f * R.sh;
  float uL = L.un + 0.5f * L.sun, uR = R.un - 0.5f * R.sun;
  float vL = L.ut + 0.5f * L.sut, vR = R.ut - 0.5f * R.sut;
  float db = (R.b - L.b) - 0.5f * (L.sb + R.sb);
  float rise = d - 0.5f * (L.se + R.se); /* surface at R's side less at L's */
  float cutL = inner ? hR - rise : hL - db, cutR = inner ? hL + rise : hR + db;
#if GR_RAIN_RUNOFF_GPU
  float hLs = fmax(0.0f, db > 0.0f ? cutL : hL), hRs = fmax(0.0f, db < 0.0f ? cutR : hR);
#else
  /* fmax(0, x) as a comparison on CPUs (see gr_sw_hll): +0 for either
   * zero and for a NaN, as fmax gives. */
  float xL = db > 0.0f ? cutL : hL, xR = db < 0.0f ? cutR : hR;
  float hLs = xL > 0.0f ? xL : 0.0f, hRs = xR > 0.0f ? xR : 0.0f;
#endif
  float fm;
  gr_sw_hll(hLs, uL, vL, hRs, uR, vR, g, fh, &fm, ft);
  *fmL = fm - 0.5f * g * hLs * hLs;
  *fmR = fm - 0.5f * g * hRs * hRs;
}

/* The ghost beyond the grid's edge next to cell C, as a reconstructed cell
 * whose face toward C carries (low: C's west face; else its east face): a
 * wall's mirror image of C's face values (normal velocity negated), an
 * open edge's dry, still cell, or a level edge's water up to `level` with
 * C's face velocities; at C's face bed in every case (db = 0 exactly), so
 * that gr_sw_face gives the wall's, the outfall's or the level's flux.
 * (A transmissive edge needs no ghost: gr_sw_continue continues the line.) */
GR_INLINE gr_sw_cell gr_sw_ghost(gr_sw_cell C, bool low, int kind, float level) {
  float s = low ? -0.5f : 0.5f;
  bool wall = kind == GR_RAIN_RUNOFF_B_CLOSED, lv = kind == GR_RAIN_RUNOFF_B_LEVEL;
  float bed = C.b + s * C.sb;
  gr_sw_cell g;
  g.h = wall ? C.h + s * C.sh : (lv ? fmax(level - bed, 0.0f) : 0.0f);
  g.un = wall ? -(C.un + s * C.sun) : (lv ? C.un + s * C.sun : 0.0f);
  g.ut = wall || lv ? C.ut + s * C.sut : 0.0f;
  g.b = C.b;
  g.sb = -C.sb;
  g.se = 0.0f;
  g.sh = 0.0f;
  g.sun = 0.0f;
  g.sut = 0.0f;
  return g;
}

/* a where use, else b, field by field (a conditional on whole structs
 * compiles to a branch, which keeps CPU compilers from vectorising). */
GR_INLINE gr_sw_cell gr_sw_pick(bool use, gr_sw_cell a, gr_sw_cell b) {
  gr_sw_cell c;
  c.h = use ? a.h : b.h;
  c.b = use ? a.b : b.b;
  c.un = use ? a.un : b.un;
  c.ut = use ? a.ut : b.ut;
  c.sh = use ? a.sh : b.sh;
  c.se = use ? a.se : b.se;
  c.sb = use ? a.sb : b.sb;
  c.sun = use ? a.sun : b.sun;
  c.sut = use ? a.sut : b.sut;
  return c;
}

/* The line continued k cells beyond its edge cell a, away from a's inner
 * neighbour m (a transmissive edge): a's depth and velocities over the bed
 * a.b + k (a.b - m.b). Every work-item that needs a continued cell computes
 * it from the same two cells by this expression, so the faces near the edge
 * stay the same floats in both cells that share them. */
GR_INLINE gr_sw_pt gr_sw_extend(gr_sw_pt a, gr_sw_pt m, float k) {
  gr_sw_pt p = a;
  p.b = a.b + k * (a.b - m.b);
  return p;
}

GR_INLINE gr_sw_pt gr_sw_pick_pt(bool use, gr_sw_pt a, gr_sw_pt b) {
  gr_sw_pt c;
  c.h = use ? a.h : b.h;
  c.b = use ? a.b : b.b;
  c.un = use ? a.un : b.un;
  c.ut = use ? a.ut : b.ut;
  c.abi = 0.0f;
  return c;
}

/* The cells k - 2 .. k + 1 (q0 .. q3, masked to dry, flat and still beyond
 * the array) of a line of n cells, those beyond a transmissive edge (tlo,
 * thi) continued (gr_sw_extend) from the edge cell away from its inner
 * neighbour (itself on a line of one cell). Every work-item continues the
 * line from the same two cells by the same expression, so a face near the
 * edge is the same float whichever work-item computes it. */
GR_INLINE void gr_sw_continue(gr_sw_pt *q0, gr_sw_pt *q1, gr_sw_pt *q2, gr_sw_pt *q3, int k, int n,
                              bool tlo, bool thi) {
  /* A branch on the arguments alone (the same for every work-item): a grid
   * without transmissive edges pays nothing for them. */
  if (!(tlo || thi))
    return;
  gr_sw_pt a0 = gr_sw_pick_pt(k == 0, *q2, *q1), a1 = gr_sw_pick_pt(k == 0, *q3, *q2);
  gr_sw_pt in_lo = gr_sw_pick_pt(n > 1, a1, a0); /* cell 0 and its inner neighbour */
  gr_sw_pt z0 = gr_sw_pick_pt(k == n, *q1, *q2), z1 = gr_sw_pick_pt(k == n, *q0, *q1);
  gr_sw_pt in_hi = gr_sw_pick_pt(n > 1, z1, z0); /* cell n - 1 and its inner neighbour */
  *q0 = gr_sw_pick_pt(tlo && k == 0, gr_sw_extend(a0, in_lo, 2.0f),
                      gr_sw_pick_pt(tlo && k == 1, gr_sw_extend(a0, in_lo, 1.0f), *q0));
  *q1 = gr_sw_pick_pt(tlo && k == 0, gr_sw_extend(a0, in_lo, 1.0f), *q1);
  *q3 = gr_sw_pick_pt(thi && k == n, gr_sw_extend(z0, in_hi, 2.0f),
                      gr_sw_pick_pt(thi && k == n - 1, gr_sw_extend(z0, in_hi, 1.0f), *q3));
  *q2 = gr_sw_pick_pt(thi && k == n, gr_sw_extend(z0, in_hi, 1.0f), *q2);
}

/* Face k of a line of n cells (between cells k - 1 and k; 0 and n are the
 * grid's edge faces), from the cells k - 2 .. k + 1: the depth flux fh,
 * the normal momentum flux as seen by the low cell (fmL) and by the high
 * cell (fmR) (gr_sw_face), and the tangential flux ft; and cell k's depth
 * and surface slopes sh, se (its reconstruction R, where k < n: the
 * slopes its update takes, gr_sw_balance). kind_lo, kind_hi, lvl_lo, lvl_hi: the kinds
 * and levels of the line's low and high edges. A transmissive edge continues the line
 * (gr_sw_continue), so its face is computed as an inner one; the other
 * edges' faces have a ghost (gr_sw_ghost): a wall passes no water, an open
 * edge only outflow, a level edge both ways. Each face is computed once per
 * stage and read by the two cells that share it (rain_runoff_sw_update*,
 * or within a work-group's tile: rain_runoff_sw_stage*). */
GR_INLINE void gr_sw_line_flux(gr_sw_pt q0, gr_sw_pt q1, gr_sw_pt q2, gr_sw_pt q3, int k, int n,
                               int kind_lo, int kind_hi, float lvl_lo, float lvl_hi, float g,
                               float *out_fh, float *out_fmL, float *out_fmR, float *out_ft,
                               float *out_sh, float *out_se) {
  bool tlo = kind_lo == GR_RAIN_RUNOFF_B_TRANSMISSIVE,
       thi = kind_hi == GR_RAIN_RUNOFF_B_TRANSMISSIVE;
  gr_sw_continue(&q0, &q1, &q2, &q3, k, n, tlo, thi);
  /* Each side's slopes where that cell has (or continues to) both
   * neighbours. */
  gr_sw_cell L = gr_sw_recon(q0, q1, q2, (k > 1 || tlo) && (k < n || thi));
  gr_sw_cell R = gr_sw_recon(q1, q2, q3, (k > 0 || tlo) && (k < n - 1 || thi));
  *out_sh = R.sh;
  *out_se = R.se;
  gr_sw_cell gl = gr_sw_ghost(R, true, kind_lo, lvl_lo);
  gr_sw_cell gh = gr_sw_ghost(L, false, kind_hi, lvl_hi);
  L = gr_sw_pick(k == 0 && !tlo, gl, L);
  R = gr_sw_pick(k == n && !thi, gh, R);
  float fh, fmL, fmR, ft;
  gr_sw_face(L, R, (k > 0 || tlo) && (k < n || thi), gr_sw_rise(q1, q2, 0.0f), g, &fh, &fmL, &fmR,
             &ft);
  /* At the edges: nothing through a wall, nothing in through an open or a
   * transmissive edge (a still wall then: no momentum either; see
   * gr_rain_runoff_edge_q for why). */
  bool wall_lo = kind_lo == GR_RAIN_RUNOFF_B_CLOSED, wall_hi = kind_hi == GR_RAIN_RUNOFF_B_CLOSED;
  bool only_out_lo = kind_lo == GR_RAIN_RUNOFF_B_OPEN || tlo;
  bool only_out_hi = kind_hi == GR_RAIN_RUNOFF_B_OPEN || thi;
  bool stop_lo = k == 0 && (wall_lo || (only_out_lo && fh > 0.0f));
  bool stop_hi = k == n && (wall_hi || (only_out_hi && fh < 0.0f));
  fmR = stop_lo && !wall_lo ? 0.0f : fmR;
  fmL = stop_hi && !wall_hi ? 0.0f : fmL;
  bool stop = stop_lo || stop_hi;
  fh = stop ? 0.0f : fh;
  ft = stop ? 0.0f : ft;
  *out_fh = fh;
  *out_fmL = fmL;
  *out_fmR = fmR;
  *out_ft = ft;
}

/* gr_sw_line_flux of a face two cells or more inside the grid (2 <= k <=
 * n - 2): inner, both its cells with both neighbours, no line continued,
 * no ghost, no edge stop; the same floats without the edges' cases. The
 * fused stages call it for whole tiles of such faces (a branch every
 * work-item takes alike), and the separate launches for the interior's
 * faces in a launch of their own (rain_runoff_sw_faces*; the same branch per
 * work-group in one kernel made PoCL's step 35 % slower, 26 -> 36 ms at
 * 1024^2). */
GR_INLINE void gr_sw_inner_flux(gr_sw_pt q0, gr_sw_pt q1, gr_sw_pt q2, gr_sw_pt q3, float g,
                                float *fh, float *fmL, float *fmR, float *ft, float *sh,
                                float *se) {
  gr_sw_cell R = gr_sw_recon(q1, q2, q3, true);
  *sh = R.sh;
  *se = R.se;
  gr_sw_face(gr_sw_recon(q0, q1, q2, true), R, true, gr_sw_rise(q1, q2, 0.0f), g, fh, fmL, fmR, ft);
}

/* A face's six values stored at out[u] and the five planes after it
 * (plane floats apart), in global memory (gr_sw_line_face) or a tile's local
 * memory (gr_sw_tile_face): a macro, since OpenCL 1.2 has no pointer to
 * either. */
#define GR_SW_PUT_FACE(out, u, plane, fh, fmL, fmR, ft, sh, se)                                    \
  do {                                                                                             \
    (out)[(u)] = (fh);                                                                             \
    (out)[(u) + (plane)] = (fmL);                                                                  \
    (out)[(u) + 2 * (plane)] = (fmR);                                                              \
    (out)[(u) + 3 * (plane)] = (ft);                                                               \
    (out)[(u) + 4 * (plane)] = (sh);                                                               \
    (out)[(u) + 5 * (plane)] = (se);                                                               \
  } while (0)

/* gr_sw_line_flux's six values written to out[f] and the five planes
 * after it (plane floats apart): fh, fmL, fmR, ft, sh, se. */
GR_INLINE void gr_sw_line_face(gr_sw_pt q0, gr_sw_pt q1, gr_sw_pt q2, gr_sw_pt q3, int k, int n,
                               int kind_lo, int kind_hi, float lvl_lo, float lvl_hi, float g,
                               __global float *restrict out, int f, int plane) {
  float fh, fmL, fmR, ft, sh, se;
  gr_sw_line_flux(q0, q1, q2, q3, k, n, kind_lo, kind_hi, lvl_lo, lvl_hi, g, &fh, &fmL, &fmR, &ft,
                  &sh, &se);
  GR_SW_PUT_FACE(out, f, plane, fh, fmL, fmR, ft, sh, se);
}

/* The flux balance along one axis of a cell of depth h and slopes sh, se
 * (as its low face keeps them, gr_sw_line_flux), from its low face's fh, fmR, ft and its high
 * face's fh, fmL, ft (gr_sw_line_flux): dh (mass in minus out), dqn and dqt (momentum, with the
 * bed's source), per unit of the axis' face length. */
GR_INLINE void gr_sw_balance(float h, float sh, float se, float fh_lo, float fmR_lo, float ft_lo,
                             float fh_hi, float fmL_hi, float ft_hi, float g, float *dh, float *dqn,
                             float *dqt) {
  float hw = h - 0.5f * sh, he = h + 0.5f * sh;
  *dh = fh_lo - fh_hi;
  /* (fmw + g hw^2 / 2) - (fme + g he^2 / 2) - g (hw + he) / 2 (bed slope)
   * = fmw - fme - g (hw + he) / 2 (surface slope). */
  *dqn = (fmR_lo - fmL_hi) - 0.5f * g * (hw + he) * se;
  *dqt = ft_lo - ft_hi;
}
/* Manning friction on the discharge (qx, qy) of water h deep over dt,
 * implicit in the new discharge: |q'| (1 + g dt n^2 |q'| / h^(7/3)) = |q|,
 * in q's direction (solved exactly, as the local inertial model does). */
GR_INLINE void gr_sw_friction(float h, float dt, float g, float n2, float *qx, float *qy) {
  /* Computed whatever the depth and discharge, then selected (none of the
   * unused values is ever kept): conditions around the divisions were
   * branches on NVIDIA devices, diverging at every wet/dry edge. */
  float qm = sqrt(*qx * *qx + *qy * *qy);
  float kf = g * dt * n2 * gr_rain_runoff_pow_m73(fmax(h, GR_RAIN_RUNOFF_DRY));
  float ratio = gr_rain_runoff_solve(qm, kf) / qm;
  float scale = qm > 0.0f ? ratio : 0.0f;
  bool on = h > 0.0f && n2 > 0.0f;
  *qx = on ? *qx * scale : *qx;
  *qy = on ? *qy * scale : *qy;
}

/* Rain and infiltration on a cell's water (as the local inertial model
 * takes them), its momentum scaled with the water infiltration removes. */
GR_INLINE float gr_sw_wet_q(float h, float q, float r, float s, float dt, float hw) {
  /* The share computed whether or not there is water (a dry cell's 0 / 0
   * is never selected): a conditional share made NVIDIA's compiler load q
   * only after the test. */
  float h1 = gr_rain_runoff_gain(h, r, s, dt), share = hw / h1;
  return h1 > 0.0f ? q * share : 0.0f;
}

/* The arguments every shallow-water step kernel takes (each uses those it
 * needs): the state (h, qu, qv, h_comp), Heun's stage (h1, qu1, qv1, dh1),
 * the points the faces read (stage 1: wh, wu, wv, the depth after rain and
 * infiltration and the velocities; stage 2: h1, u1, v1), the faces (fx:
 * (nx+1) x ny x-faces, row stride nx+1; fy: nx x (ny+1) y-faces, numbered
 * like cells with one more row; six planes each, fh, fmL, fmR, ft, sh and se
 * of gr_sw_line_face: separate planes, not float4s, which CPU compilers do
 * not vectorise across work-items), the inputs and the ledger's per-cell sums. */
#define GR_SW_STEP_ARGS                                                                            \
  __global float *restrict h, __global float *restrict qu, __global float *restrict qv,            \
      __global float *restrict h_comp, __global float *restrict h1, __global float *restrict qu1,  \
      __global float *restrict qv1, __global float *restrict dh1, __global float *restrict wh,     \
      __global float *restrict wu, __global float *restrict wv, __global float *restrict u1,       \
      __global float *restrict v1, __global float *restrict fx, __global float *restrict fy,       \
      __global const float *restrict b, __global const float *restrict rain,                       \
      __global const float *restrict perm, __global const float *restrict src, int use_src,        \
      __global const float *restrict nodata, int use_nodata, __global float *restrict infiltrated, \
      __global float *restrict infiltrated_comp, __global float *restrict outflow,                 \
      __global float *restrict outflow_comp, __global float *restrict inflow,                      \
      __global float *restrict inflow_comp, int nx, int ny, float dt, float inv_dx, float inv_dy,  \
      float g, float n2, __global const float *restrict n2map, int use_n2, int use_rain,           \
      float rain_uniform, int use_perm, float perm_uniform, int bnd_w, int bnd_e, int bnd_s,       \
      int bnd_n, float lvl_w, float lvl_e, float lvl_s, float lvl_n, GR_RAIN_RUNOFF_MAP_ARGS,      \
      float4 map_time

/* The arguments of a stage's cell update (gr_sw_update_cell), the state,
 * the stage and the ledger of GR_SW_STEP_ARGS. */
#define GR_SW_CELL_ARGS                                                                            \
  __global float *restrict h, __global float *restrict qu, __global float *restrict qv,            \
      __global float *restrict h_comp, __global float *restrict h1, __global float *restrict qu1,  \
      __global float *restrict qv1, __global float *restrict dh1, __global float *restrict u1,     \
      __global float *restrict v1, __global const float *restrict b,                               \
      __global const float *restrict rain, __global const float *restrict perm,                    \
      __global const float *restrict src, int use_src, __global const float *restrict nodata,      \
      int use_nodata, __global float *restrict infiltrated,                                        \
      __global float *restrict infiltrated_comp, __global float *restrict outflow,                 \
      __global float *restrict outflow_comp, __global float *restrict inflow,                      \
      __global float *restrict inflow_comp, int nx, int ny, float dt, float inv_dx, float inv_dy,  \
      float g, float n2, __global const float *restrict n2map, int use_n2, int use_rain,           \
      float rain_uniform, int use_perm, float perm_uniform, int bnd_w, int bnd_e, int bnd_s,       \
      int bnd_n, GR_RAIN_RUNOFF_MAP_ARGS, float4 map_time
#define GR_SW_CELL_PASS                                                                            \
  h, qu, qv, h_comp, h1, qu1, qv1, dh1, u1, v1, b, rain, perm, src, use_src, nodata, use_nodata,   \
      infiltrated, infiltrated_comp, outflow, outflow_comp, inflow, inflow_comp, nx, ny, dt,       \
      inv_dx, inv_dy, g, n2, n2map, use_n2, use_rain, rain_uniform, use_perm, perm_uniform, bnd_w, \
      bnd_e, bnd_s, bnd_n, GR_RAIN_RUNOFF_MAP_PASS, map_time

/* Cell q's point in stage 1: its depth after rain and infiltration (*hw)
 * and the velocities (*u, *v) of its momentum scaled with the water
 * infiltration removed (as the local inertial model takes rain and
 * infiltration): rain_runoff_sw_prep's and the fused stages' tiles'. */
GR_INLINE void gr_sw_wet_point(GR_SW_CELL_ARGS, int q, float *hw, float *u, float *v) {
  float h0 = h[q], r = GR_RAIN_RUNOFF_RAIN(q), k = GR_RAIN_RUNOFF_PERM(q);
  float sc = GR_RAIN_RUNOFF_SRC(q);
  float w = gr_rain_runoff_wet(h0, r, sc, k, dt);
  *hw = w;
  *u = gr_sw_velocity(w, gr_sw_wet_q(h0, qu[q], r, sc, dt, w));
  *v = gr_sw_velocity(w, gr_sw_wet_q(h0, qv[q], r, sc, dt, w));
}

/* Stage 1's points for the separate launches, once per cell
 * (gr_sw_wet_point). */
__kernel void rain_runoff_sw_prep(GR_SW_STEP_ARGS) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny))
    return;
  int c = gr_idx(i, j, nx);
  float hw, u, v;
  gr_sw_wet_point(GR_SW_CELL_PASS, c, &hw, &u, &v);
  wh[c] = hw;
  wu[c] = u;
  wv[c] = v;
}

/* One point of a line (in: inside the local array; q its index): depth,
 * bed, velocities along (pn) and across (pt) the line; 0 where outside. */
GR_INLINE gr_sw_pt gr_sw_point(__global const float *restrict ph, __global const float *restrict pn,
                               __global const float *restrict pt, __global const float *restrict b,
                               bool in, int q) {
  gr_sw_pt p;
  p.h = in ? ph[q] : 0.0f;
  p.b = in ? b[q] : 0.0f;
  p.un = in ? pn[q] : 0.0f;
  p.ut = in ? pt[q] : 0.0f;
  p.abi = 0.0f;
  return p;
}

/* The faces of a stage at (i, j), once: the x-face left of cell (i, j)
 * (for j < ny) and the y-face below it (for i < nx), from the points (ph,
 * pu, pv) two cells either side. Indices stay linear and loads beyond the
 * array masked, so that CPU compilers vectorise the loads. inner: both
 * faces lie two cells or more inside the grid (2 <= i <= nx - 2, 2 <= j <=
 * ny - 2), so they take gr_sw_inner_flux, the same floats without the
 * edges' cases (ghosts, picks, stops), which made up about a third of a
 * face's instructions on CPUs. */
GR_INLINE void gr_sw_faces_at(__global const float *restrict ph, __global const float *restrict pu,
                              __global const float *restrict pv, __global const float *restrict b,
                              __global float *restrict fx, __global float *restrict fy, int nx,
                              int ny, float g, int bnd_w, int bnd_e, int bnd_s, int bnd_n,
                              float lvl_w, float lvl_e, float lvl_s, float lvl_n, int i, int j,
                              const int inner) {
  int c = j * nx + i;
  if (inner || j < ny) {
    gr_sw_pt q0 = gr_sw_point(ph, pu, pv, b, inner || i >= 2, c - 2);
    gr_sw_pt q1 = gr_sw_point(ph, pu, pv, b, inner || i >= 1, c - 1);
    gr_sw_pt q2 = gr_sw_point(ph, pu, pv, b, inner || i < nx, c);
    gr_sw_pt q3 = gr_sw_point(ph, pu, pv, b, inner || i + 1 < nx, c + 1);
    int f = j * (nx + 1) + i, plane = (nx + 1) * ny;
    if (inner) {
      float fh, fmL, fmR, ft, sh, se;
      gr_sw_inner_flux(q0, q1, q2, q3, g, &fh, &fmL, &fmR, &ft, &sh, &se);
      GR_SW_PUT_FACE(fx, f, plane, fh, fmL, fmR, ft, sh, se);
    } else {
      gr_sw_line_face(q0, q1, q2, q3, i, nx, bnd_w, bnd_e, lvl_w, lvl_e, g, fx, f, plane);
    }
  }
  if (inner || i < nx) {
    gr_sw_pt q0 = gr_sw_point(ph, pv, pu, b, inner || j >= 2, c - 2 * nx);
    gr_sw_pt q1 = gr_sw_point(ph, pv, pu, b, inner || j >= 1, c - nx);
    gr_sw_pt q2 = gr_sw_point(ph, pv, pu, b, inner || j < ny, c);
    gr_sw_pt q3 = gr_sw_point(ph, pv, pu, b, inner || j + 1 < ny, c + nx);
    int plane = nx * (ny + 1);
    if (inner) {
      float fh, fmL, fmR, ft, sh, se;
      gr_sw_inner_flux(q0, q1, q2, q3, g, &fh, &fmL, &fmR, &ft, &sh, &se);
      GR_SW_PUT_FACE(fy, c, plane, fh, fmL, fmR, ft, sh, se);
    } else {
      gr_sw_line_face(q0, q1, q2, q3, j, ny, bnd_s, bnd_n, lvl_s, lvl_n, g, fy, c, plane);
    }
  }
}

/* The interior's faces (gr_sw_faces_at, inner): work-item (i, j) of a
 * launch at offset (2, 2) over (nx - 3) x (ny - 3), rounded up to whole
 * work-groups. */
GR_INLINE void gr_sw_faces(__global const float *restrict ph, __global const float *restrict pu,
                           __global const float *restrict pv, __global const float *restrict b,
                           __global float *restrict fx, __global float *restrict fy, int nx, int ny,
                           float g, int bnd_w, int bnd_e, int bnd_s, int bnd_n, float lvl_w,
                           float lvl_e, float lvl_s, float lvl_n) {
  int i = get_global_id(0), j = get_global_id(1);
  if (i > nx - 2 || j > ny - 2)
    return;
  gr_sw_faces_at(ph, pu, pv, b, fx, fy, nx, ny, g, bnd_w, bnd_e, bnd_s, bnd_n, lvl_w, lvl_e, lvl_s,
                 lvl_n, i, j, 1);
}

/* The rim's faces, every (i, j) of the (nx + 1) x (ny + 1) faces' grid
 * outside the interior (gr_sw_faces), with their edges' cases: one
 * work-item each, numbered along the two rows at either end, then four a
 * row in between (columns 0, 1, nx - 1, nx); the whole grid where it has no
 * interior (nx or ny under 4). gr_rain_runoff_sw_rim_count on the host
 * counts them. */
GR_INLINE void gr_sw_rim_faces(__global const float *restrict ph, __global const float *restrict pu,
                               __global const float *restrict pv, __global const float *restrict b,
                               __global float *restrict fx, __global float *restrict fy, int nx,
                               int ny, float g, int bnd_w, int bnd_e, int bnd_s, int bnd_n,
                               float lvl_w, float lvl_e, float lvl_s, float lvl_n) {
  int k = get_global_id(0), w = nx + 1, i, j;
  if (nx < 4 || ny < 4) {
    if (k >= w * (ny + 1))
      return;
    i = k % w;
    j = k / w;
  } else if (k < 4 * w) {
    i = k % w;
    j = k < 2 * w ? k / w : ny - 3 + k / w; /* rows 0, 1, then ny - 1, ny */
  } else {
    int t = k - 4 * w, col = t % 4;
    if (t >= 4 * (ny - 3))
      return;
    j = 2 + t / 4;
    i = col < 2 ? col : nx - 3 + col; /* columns 0, 1, nx - 1, nx */
  }
  gr_sw_faces_at(ph, pu, pv, b, fx, fy, nx, ny, g, bnd_w, bnd_e, bnd_s, bnd_n, lvl_w, lvl_e, lvl_s,
                 lvl_n, i, j, 0);
}

__kernel void rain_runoff_sw_faces1(GR_SW_STEP_ARGS) {
  gr_sw_faces(wh, wu, wv, b, fx, fy, nx, ny, g, bnd_w, bnd_e, bnd_s, bnd_n, lvl_w, lvl_e, lvl_s,
              lvl_n);
}

__kernel void rain_runoff_sw_faces2(GR_SW_STEP_ARGS) {
  gr_sw_faces(h1, u1, v1, b, fx, fy, nx, ny, g, bnd_w, bnd_e, bnd_s, bnd_n, lvl_w, lvl_e, lvl_s,
              lvl_n);
}

__kernel void rain_runoff_sw_rim1(GR_SW_STEP_ARGS) {
  gr_sw_rim_faces(wh, wu, wv, b, fx, fy, nx, ny, g, bnd_w, bnd_e, bnd_s, bnd_n, lvl_w, lvl_e, lvl_s,
                  lvl_n);
}

__kernel void rain_runoff_sw_rim2(GR_SW_STEP_ARGS) {
  gr_sw_rim_faces(h1, u1, v1, b, fx, fy, nx, ny, g, bnd_w, bnd_e, bnd_s, bnd_n, lvl_w, lvl_e, lvl_s,
                  lvl_n);
}

/* One stage of Heun's method for every cell (one work-item per cell of the
 * local array, which reads and writes that cell's values only) from its
 * four faces, Manning friction implicit in each stage (gr_sw_friction) on
 * its forward-Euler discharge:
 *   stage 1: U1 = Uw + dt L(Uw), Uw the state after rain and infiltration,
 *            from h, qu, qv (and the points wh, wu, wv); also the
 *            velocities u1, v1 of U1, stage 2's points;
 *   stage 2: U = (Uw + U1 + dt L(U1)) / 2, from h1, qu1, qv1, written over
 *            h, qu, qv (each cell reads its own old values only), with the
 *            infiltration and half of each stage's edge outflow booked in
 *            Kahan sums. */

/* What a cell's update reads before it stores anything: the state, and in
 * stage 2 the depth's compensation, stage 1's depth change, the flood maps
 * and, where the cell infiltrates, its infiltrated water (the same test as
 * the update's, so nothing more is read). The fused stages read it first
 * and give it to gr_sw_update_cell (given 1): NVIDIA's compiler keeps
 * loads after earlier stores, so maps and infiltration read in the update,
 * after the new state's stores, each waited a memory latency of their own.
 * The separate launches read in the update (given 0): given the values,
 * PoCL's step at 1024^2 was 4 % slower. */
typedef struct gr_sw_cell_in {
  float h0, qu0, qv0, hc, dh1, is, ic;
  gr_rain_runoff_maps_at m;
} gr_sw_cell_in;

GR_INLINE gr_sw_cell_in gr_sw_cell_read(GR_SW_CELL_ARGS, int c, const int stage) {
  gr_sw_cell_in in = {0.0f};
  in.h0 = h[c];
  in.qu0 = qu[c];
  in.qv0 = qv[c];
  if (stage == 2) {
    in.hc = h_comp[c];
    in.dh1 = dh1[c];
    in.m = gr_rain_runoff_maps_read(c, GR_RAIN_RUNOFF_MAP_PASS);
    float inf = gr_rain_runoff_infiltration(in.h0, GR_RAIN_RUNOFF_RAIN(c), GR_RAIN_RUNOFF_SRC(c),
                                            GR_RAIN_RUNOFF_PERM(c), dt);
    if (inf != 0.0f) {
      in.is = infiltrated[c];
      in.ic = infiltrated_comp[c];
    }
  }
  return in;
}

/* Cell (i, j)'s update in a stage (see gr_sw_update) from its point x2
 * (along x), its slopes along x (shx, sex) and y (shy, sey) (its west and south faces' sh, se),
 * its four faces' values as gr_sw_balance takes them (west, east, south, north) and its
 * momenta before the stage (suc, svc; stage 2's, stage 1 takes the wet
 * ones); with velocities, stage 1 also writes U1's velocities u1, v1. Both
 * launch paths call it, so they give the same floats. given: what the
 * update reads comes in `in`, read before anything is stored
 * (gr_sw_cell_read; the fused stages), else it is read here (the separate
 * launches: PoCL at 1024^2 took 25 ms a step with the state given, 24
 * without). */
GR_INLINE void gr_sw_update_cell(GR_SW_CELL_ARGS, int i, int j, gr_sw_pt x2, float shx, float sex,
                                 float shy, float sey, float fh_w, float fm_w, float ft_w,
                                 float fh_e, float fm_e, float ft_e, float fh_s, float fm_s,
                                 float ft_s, float fh_n, float fm_n, float ft_n, float suc,
                                 float svc, const int given, gr_sw_cell_in in, const int stage,
                                 const int velocities) {
  int c = gr_idx(i, j, nx);
  float n2c = GR_RAIN_RUNOFF_USES(GR_RAIN_RUNOFF_IN_N2, use_n2)
                  ? n2map[c]
                  : n2; /* the cell's own roughness, n^2 */
  float dhx, dqx_x, dqy_x, dhy, dqy_y, dqx_y;
  gr_sw_balance(x2.h, shx, sex, fh_w, fm_w, ft_w, fh_e, fm_e, ft_e, g, &dhx, &dqx_x, &dqy_x);
  gr_sw_balance(x2.h, shy, sey, fh_s, fm_s, ft_s, fh_n, fm_n, ft_n, g, &dhy, &dqy_y, &dqx_y);
  float dh = dt * (dhx * inv_dx + dhy * inv_dy);
  float hn = x2.h + dh;
  float qun = suc + dt * (dqx_x * inv_dx + dqx_y * inv_dy);
  float qvn = svc + dt * (dqy_x * inv_dx + dqy_y * inv_dy);
  if (stage == 1) {
    /* su, sv are the momenta before rain: take the wet ones. */
    float r = GR_RAIN_RUNOFF_RAIN(c);
    float sc = GR_RAIN_RUNOFF_SRC(c);
    float hw = x2.h;
    float h0 = given ? in.h0 : h[c], qu0 = given ? in.qu0 : qu[c], qv0 = given ? in.qv0 : qv[c];
    qun = gr_sw_wet_q(h0, qu0, r, sc, dt, hw) + dt * (dqx_x * inv_dx + dqx_y * inv_dy);
    qvn = gr_sw_wet_q(h0, qv0, r, sc, dt, hw) + dt * (dqy_x * inv_dx + dqy_y * inv_dy);
    /* Friction in each stage: without it a film on a steep slope would
     * gather g S dt of speed in the first stage and empty its cell in the
     * second. */
    gr_sw_friction(hn, dt, g, n2c, &qun, &qvn);
    float hs = fmax(hn, 0.0f), qus = hn > 0.0f ? qun : 0.0f, qvs = hn > 0.0f ? qvn : 0.0f;
    h1[c] = hs;
    dh1[c] = dh;
    qu1[c] = qus;
    qv1[c] = qvs;
    /* The fused path computes them again from h1, qu1, qv1 (the same
     * floats) instead of reading them. */
    if (velocities) {
      u1[c] = gr_sw_velocity(hs, qus);
      v1[c] = gr_sw_velocity(hs, qvs);
    }
  } else {
    float h0 = given ? in.h0 : h[c];
    float r = GR_RAIN_RUNOFF_RAIN(c);
    float k = GR_RAIN_RUNOFF_PERM(c);
    float sc = GR_RAIN_RUNOFF_SRC(c);
    float hw = gr_rain_runoff_wet(h0, r, sc, k, dt);
    float inf = gr_rain_runoff_infiltration(h0, r, sc, k, dt);
    /* The new depth h0 + (r dt - i) + (dh1 + dh) / 2, Kahan-summed as the
     * local inertial model's (h - h_comp is the water): without it the
     * rounding of the depth would show in the ledger after 10^3 steps. */
    float delta = ((r * dt - inf) + sc * dt) + 0.5f * ((given ? in.dh1 : dh1[c]) + dh);
    float y = delta - (given ? in.hc : h_comp[c]);
    float hf = h0 + y;
    float comp = (hf - h0) - y;
    gr_sw_friction(hn, dt, g, n2c, &qun, &qvn);
    float qx = 0.5f * (gr_sw_wet_q(h0, given ? in.qu0 : qu[c], r, sc, dt, hw) + qun);
    float qy = 0.5f * (gr_sw_wet_q(h0, given ? in.qv0 : qv[c], r, sc, dt, hw) + qvn);
    /* An outfall no-data cell drains (its water is outflow). */
    float gone = gr_rain_runoff_drain(nodata, use_nodata, c, hf, comp);
    bool keep = hf > 0.0f && gone == 0.0f;
    float d = gone == 0.0f ? fmax(hf, 0.0f) : 0.0f, u = keep ? qx : 0.0f, v = keep ? qy : 0.0f;
    h[c] = d;
    h_comp[c] = keep ? comp : 0.0f;
    qu[c] = u;
    qv[c] = v;
    /* The flood maps from the new state (the cell was wet for them if the
     * step's starting depth, which the fold before left, was). */
    gr_rain_runoff_map_fold(c, h0 > wetting_depth, d, u, v,
                            given ? in.m : gr_rain_runoff_maps_read(c, GR_RAIN_RUNOFF_MAP_PASS),
                            GR_RAIN_RUNOFF_MAP_PASS, map_time);
    if (gone != 0.0f)
      gr_kahan_add(outflow, outflow_comp, c, gone);
    if (inf != 0.0f)
      gr_kahan_store(infiltrated, infiltrated_comp, c, given ? in.is : infiltrated[c],
                     given ? in.ic : infiltrated_comp[c], inf);
    /* The sources' water is inflow, the very float the depth gained. */
    if (sc != 0.0f)
      gr_kahan_add(inflow, inflow_comp, c, sc * dt);
  }
  /* Half of each stage's edge flows (Heun's average) are booked after
   * this (rain_runoff_sw_edges after the launch; in the fused stages by the
   * same work-item): here, their sums paired into <2 x float> values kept
   * CPU compilers from vectorising the update. */
}

GR_INLINE void gr_sw_update(GR_SW_CELL_ARGS, __global const float *restrict fx,
                            __global const float *restrict fy, __global const float *restrict ph,
                            __global const float *restrict pu, __global const float *restrict pv,
                            __global const float *restrict su, __global const float *restrict sv,
                            const int stage) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny))
    return;
  int c = gr_idx(i, j, nx);
  gr_sw_pt x2 = gr_sw_point(ph, pu, pv, b, true, c);
  /* The planes of gr_sw_line_face: fh, fmL, fmR, ft, sh, se; the cell's
   * slopes are those its west and south faces kept (on PoCL at 1024^2 the
   * step took 24-25 ms reconstructing the cell again here, and 22-23
   * reading them). */
  int f = j * (nx + 1) + i, px = (nx + 1) * ny, py = nx * (ny + 1);
  gr_sw_cell_in none = {0.0f}; /* the update reads the cell itself (given 0) */
  gr_sw_update_cell(GR_SW_CELL_PASS, i, j, x2, fx[f + 4 * px], fx[f + 5 * px], fy[c + 4 * py],
                    fy[c + 5 * py], fx[f], fx[f + 2 * px], fx[f + 3 * px], fx[f + 1],
                    fx[f + 1 + px], fx[f + 1 + 3 * px], fy[c], fy[c + 2 * py], fy[c + 3 * py],
                    fy[c + nx], fy[c + nx + py], fy[c + nx + 3 * py], su[c], sv[c], 0, none, stage,
                    1);
}

/* The two stages' updates as two kernels, each reading one state and
 * writing another that the compiler can tell apart (a pointer chosen at
 * run time between them kept PoCL from vectorising across work-items). */
__kernel void rain_runoff_sw_update1(GR_SW_STEP_ARGS) {
  gr_sw_update(GR_SW_CELL_PASS, fx, fy, wh, wu, wv, qu, qv, 1);
}

__kernel void rain_runoff_sw_update2(GR_SW_STEP_ARGS) {
  gr_sw_update(GR_SW_CELL_PASS, fx, fy, h1, u1, v1, qu1, qv1, 2);
}

/* Half of a stage's flows through the domain's edges (Heun's average),
 * booked after the stage's update (rain_runoff_sw_update*, which books
 * the rest of a cell's ledger first): one work-item per cell on the grid's
 * rim (the rows j = 0 and ny - 1, then the columns i = 0 and nx - 1 in
 * between), each from its edge faces, all four sides at once. */
__kernel void rain_runoff_sw_edges(GR_SW_STEP_ARGS) {
  int k = get_global_id(0);
  int cols = nx > 1 ? 2 : 1, rows = ny > 1 ? 2 : 1;
  if (k >= rows * nx + (ny - rows) * cols)
    return;
  int i, j;
  if (k < rows * nx) {
    i = k % nx;
    j = k < nx ? 0 : ny - 1;
  } else {
    int t = k - rows * nx;
    j = 1 + t / cols;
    i = t % cols == 0 ? 0 : nx - 1;
  }
  int c = gr_idx(i, j, nx), f = j * (nx + 1) + i;
  float olx = i > 0 ? 0.0f : -fx[f], ohx = i < nx - 1 ? 0.0f : fx[f + 1];
  float oly = j > 0 ? 0.0f : -fy[c], ohy = j < ny - 1 ? 0.0f : fy[c + nx];
  gr_rain_runoff_book_edges(outflow, outflow_comp, inflow, inflow_comp, c, 0.5f * dt, inv_dx,
                            inv_dy, olx, ohx, oly, ohy);
}

#include "rain_runoff_sw_tiles.cl"

/* The stable step's inputs, per work-group: the deepest cell and the
 * fastest rate (|u| + sqrt(g h)) / dx + (|v| + sqrt(g h)) / dy of the owned
 * cells (a cell's own sum: what its update needs, and the same maximum
 * whichever way the domain is split). */
__kernel void
rain_runoff_sw_speed(__global const float *restrict h, __global const float *restrict qu,
                     __global const float *restrict qv, __global float *restrict partial,
                     __local float *restrict scratch, int n, int row, int own_x0, int own_x1,
                     int own_y0, int own_y1, int masked, float g, float inv_dx, float inv_dy) {
  int lid = get_local_id(0), wg = get_local_size(0), start, end;
  gr_reduce_block(n, &start, &end);
  float hmax = 0.0f, rate = 0.0f;
  for (int c = start + lid; c < end; c += wg) {
    if (masked) {
      int i = c % row, j = c / row;
      if (i < own_x0 || i >= own_x1 || j < own_y0 || j >= own_y1)
        continue;
    }
    float d = h[c], a = sqrt(g * d);
    hmax = fmax(hmax, d);
    rate = fmax(rate, (fabs(gr_sw_velocity(d, qu[c])) + a) * inv_dx +
                          (fabs(gr_sw_velocity(d, qv[c])) + a) * inv_dy);
  }
  __local float *mine = gr_reduce_slots(scratch, 0, 2);
  mine[0] = hmax;
  mine[1] = rate;
  gr_reduce_group(scratch, 0, 2, partial);
}
