/* Rain on terrain (seed 004's water height map, rain and infiltration,
 * with a conservative flow in place of its tangential flow): the program
 * rain_runoff, its two flow models documented in graupel/rain_runoff.h.
 * This file holds what both models share: the build options, the inputs
 * (rain, infiltration, sources, no-data cells, roughness), the friction's
 * powers, the edges' bookkeeping, the flood maps, and the kernels of either
 * model (the sources, the ledger's reduction, the derived fields, the flood
 * maps); the local inertial model follows in rain_runoff_li.cl and the
 * shallow-water model, the default, in rain_runoff_sw.cl (both inlined
 * here when the program is embedded, as the headers are). Every expression
 * is written so that a mirrored face computes the exact negative, and sums
 * over a cell's faces pair the mirrored terms: mirror-symmetric inputs give
 * mirror-symmetric fields bit for bit. */

#include "common.h"
#include "rain_runoff_shared.h"
#include "reduce.h"

/* The optional inputs this program is built for (GR_RAIN_RUNOFF_IN_* bits,
 * -DGR_RAIN_RUNOFF_INPUTS=...; all of them by default). The kernels still
 * take every input and its use_* flag, and a program is right for any
 * simulation whose inputs in use are among its bits: an input the program
 * is not built for reads as absent at compile time, and the compiler drops
 * its loads and tests. On CPUs that is most of the step's cost: PoCL's
 * vectorised local inertial step at 1024^2 took 17 ms with every input
 * possible and 6.3 ms without (a uniform rain and permeability). The host
 * builds the program for the inputs in use (gr_rain_runoff_specialise);
 * the same expressions give the same floats either way. */
#ifndef GR_RAIN_RUNOFF_INPUTS
#define GR_RAIN_RUNOFF_INPUTS GR_RAIN_RUNOFF_IN_ALL
#endif
#define GR_RAIN_RUNOFF_USES(bit, flag) ((GR_RAIN_RUNOFF_INPUTS & (bit)) != 0 && (flag))
/* Built for a GPU (-DGR_RAIN_RUNOFF_GPU=1, gr_rain_runoff_specialise):
 * where an expression has two forms of the same floats, the one SIMT
 * devices run without branches (gr_sw_minmod). */
#ifndef GR_RAIN_RUNOFF_GPU
#define GR_RAIN_RUNOFF_GPU 0
#endif

/* Whether the program has the shallow-water model's kernels (below). */
#ifndef GR_RAIN_RUNOFF_SW
#define GR_RAIN_RUNOFF_SW 1
#endif

GR_INLINE float gr_rain_runoff_input(__global const float *restrict field, int use_field,
                                     float uniform, long c) {
  return use_field ? field[c] : uniform;
}

/* Depth after rain and the sources (inflows, m/s of depth): (h + r dt) +
 * s dt, two products the ledger books apart (the rain on the host, the
 * sources per cell); with no source the rain's h + r dt to the bit. */
GR_INLINE float gr_rain_runoff_gain(float h, float r, float s, float dt) {
  return (h + r * dt) + s * dt;
}

/* Depth after rain and source gain and infiltration (at most k dt, never
 * more than the water there). */
GR_INLINE float gr_rain_runoff_wet(float h, float r, float s, float k, float dt) {
  float h1 = gr_rain_runoff_gain(h, r, s, dt);
  return h1 - fmin(k * dt, h1);
}

GR_INLINE float gr_rain_runoff_infiltration(float h, float r, float s, float k, float dt) {
  float h1 = gr_rain_runoff_gain(h, r, s, dt);
  return fmin(k * dt, h1);
}

/* The friction's n^2 at a face between cells a and b: the uniform n2, or
 * with a Manning map (use_n2) the mean of the two cells' n^2 (the same
 * float whichever side computes it; n2 itself where both are n2). */
GR_INLINE float gr_rain_runoff_face_n2(__global const float *restrict n2map, int use_n2, float n2,
                                       int a, int b) {
  return GR_RAIN_RUNOFF_USES(GR_RAIN_RUNOFF_IN_N2, use_n2) ? 0.5f * (n2map[a] + n2map[b]) : n2;
}

/* No-data cells (NaN elevations, graupel/rain_runoff.h): nodata[c] is 0 for
 * a cell of the domain, 1 for a wall, 2 for an outfall (use_nodata: there
 * are some). Nothing rains, enters or infiltrates there. */
#define GR_RAIN_RUNOFF_ACTIVE(c)                                                                   \
  (!GR_RAIN_RUNOFF_USES(GR_RAIN_RUNOFF_IN_NODATA, use_nodata) || nodata[(c)] == 0.0f)
#define GR_RAIN_RUNOFF_RAIN(c)                                                                     \
  (GR_RAIN_RUNOFF_ACTIVE(c)                                                                        \
       ? gr_rain_runoff_input(rain, GR_RAIN_RUNOFF_USES(GR_RAIN_RUNOFF_IN_RAIN, use_rain),         \
                              rain_uniform, (c))                                                   \
       : 0.0f)
#define GR_RAIN_RUNOFF_PERM(c)                                                                     \
  (GR_RAIN_RUNOFF_ACTIVE(c)                                                                        \
       ? gr_rain_runoff_input(perm, GR_RAIN_RUNOFF_USES(GR_RAIN_RUNOFF_IN_PERM, use_perm),         \
                              perm_uniform, (c))                                                   \
       : 0.0f)

/* A cell's source rate (m/s of depth): the source field's, 0 without one. */
#define GR_RAIN_RUNOFF_SRC(c)                                                                      \
  (GR_RAIN_RUNOFF_ACTIVE(c)                                                                        \
       ? gr_rain_runoff_input(src, GR_RAIN_RUNOFF_USES(GR_RAIN_RUNOFF_IN_SRC, use_src), 0.0f, (c)) \
       : 0.0f)

/* The water an outfall no-data cell received in a step leaves the domain:
 * its new depth t (and Kahan compensation comp) go to the outflow, and the
 * cell ends dry. Returns the water booked (0 for every other cell). */
GR_INLINE float gr_rain_runoff_drain(__global const float *restrict nodata, int use_nodata, int c,
                                     float t, float comp) {
  return GR_RAIN_RUNOFF_USES(GR_RAIN_RUNOFF_IN_NODATA, use_nodata) && nodata[c] == 2.0f && t > 0.0f
             ? t - comp
             : 0.0f;
}

/* x^(-1/3) for x > 0 (a normal float): an exponent-thirding first guess and
 * three Newton steps (2e-7 relative). Plain multiplications, unlike a
 * library cbrt or pow, which PoCL calls per work-item (the flux kernel was
 * seven times slower with cbrt, and the stable step's film rate spent a
 * third of a run on the real DEM in it); and the same answer on every IEEE
 * device. */
GR_INLINE float gr_rain_runoff_rcbrt(float x) {
  float y = as_float(0x54a21d2au - as_uint(x) / 3u);
  y = y * (4.0f - x * y * y * y) * (1.0f / 3.0f);
  y = y * (4.0f - x * y * y * y) * (1.0f / 3.0f);
  y = y * (4.0f - x * y * y * y) * (1.0f / 3.0f);
  return y;
}

/* x^(-7/3) for x > 0, the friction's depth factor. */
GR_INLINE float gr_rain_runoff_pow_m73(float x) {
  float y = gr_rain_runoff_rcbrt(x);
  float y2 = y * y;
  return y2 * y2 * y2 * y;
}

/* q' from q'(1 + kf |q'|) = m: the friction taken implicitly, solved
 * exactly (and without cancellation). */
GR_INLINE float gr_rain_runoff_solve(float m, float kf) {
  return 2.0f * m / (1.0f + sqrt(1.0f + 4.0f * kf * fabs(m)));
}

/* The discharge that flowed through a face: q* scaled by the limiter of the
 * cell it leaves. */
GR_INLINE float gr_rain_runoff_limited(float q, float k_low, float k_high) {
  return q * (q > 0.0f ? k_low : k_high);
}

/* The discharge q through a domain edge's face (positive toward the high
 * side; low: the west or south edge) as the edge's kind lets it through: a
 * wall nothing, an outfall and a transmissive edge outflow only (a
 * zero-gradient inflow would grow with the edge cell's depth and feed a pit
 * at the edge without end), a level edge both ways. */
GR_INLINE float gr_rain_runoff_edge_q(int kind, float q, bool low) {
  float out_only = low ? fmin(q, 0.0f) : fmax(q, 0.0f);
  return kind == GR_RAIN_RUNOFF_B_CLOSED ? 0.0f : (kind == GR_RAIN_RUNOFF_B_LEVEL ? q : out_only);
}

/* Books a cell's flow through the domain's edges, given per edge face as
 * what leaves the cell (m^2/s; negative: what enters), times dt over the
 * face's cell width: outflow and inflow (metres of depth, Kahan sums). */
GR_INLINE void gr_rain_runoff_book_edges(__global float *restrict outflow,
                                         __global float *restrict outflow_comp,
                                         __global float *restrict inflow,
                                         __global float *restrict inflow_comp, int c, float dt,
                                         float inv_dx, float inv_dy, float ow, float oe, float os,
                                         float on) {
  float out = dt * ((fmax(ow, 0.0f) + fmax(oe, 0.0f)) * inv_dx +
                    (fmax(os, 0.0f) + fmax(on, 0.0f)) * inv_dy);
  float in = dt * ((fmax(-ow, 0.0f) + fmax(-oe, 0.0f)) * inv_dx +
                   (fmax(-os, 0.0f) + fmax(-on, 0.0f)) * inv_dy);
  if (out != 0.0f)
    gr_kahan_add(outflow, outflow_comp, c, out);
  if (in != 0.0f)
    gr_kahan_add(inflow, inflow_comp, c, in);
}

/* The flood maps' arguments (graupel/rain_runoff.h, "Flood maps"; see
 * rain_runoff_maps), also taken by each model's last step kernel, which
 * folds the state it leaves into them (map_time: see gr_rain_runoff_map_fold).
 * The wet duration is kept by its transitions: wet_time (+ wet_time_lo, a
 * double-float pair) is the duration of the cell's wet spells that have
 * ended, wet_since (+ wet_since_lo) the time the spell under way began, -1
 * while the cell is dry; the host adds the time now - wet_since to read it
 * (gr_rain_runoff_get_map). */
#define GR_RAIN_RUNOFF_MAP_ARGS                                                                    \
  __global float *restrict max_depth, __global float *restrict max_speed,                          \
      __global float *restrict arrival, __global float *restrict wet_time,                         \
      __global float *restrict wet_time_lo, __global float *restrict max_hazard,                   \
      __global float *restrict wet_since, __global float *restrict wet_since_lo,                   \
      float wetting_depth, float debris_factor
#define GR_RAIN_RUNOFF_MAP_PASS                                                                    \
  max_depth, max_speed, arrival, wet_time, wet_time_lo, max_hazard, wet_since, wet_since_lo,       \
      wetting_depth, debris_factor
/* The same arrays from cell c on (their index 0; see gr_rain_runoff_update_cell). */
#define GR_RAIN_RUNOFF_MAP_PASS_AT(c)                                                              \
  max_depth + (c), max_speed + (c), arrival + (c), wet_time + (c), wet_time_lo + (c),              \
      max_hazard + (c), wet_since + (c), wet_since_lo + (c), wetting_depth, debris_factor

/* Cell c's flood maps that every fold reads (gr_rain_runoff_map_fold folds
 * a new state into them; the shallow-water stages read them early, see
 * gr_sw_cell_read). The arrival and the wet duration are read only where
 * the cell turns wet or dry (gr_rain_runoff_wet_turn). */
typedef struct gr_rain_runoff_maps_at {
  float md, msp, mh;
} gr_rain_runoff_maps_at;

GR_INLINE gr_rain_runoff_maps_at gr_rain_runoff_maps_read(int c, GR_RAIN_RUNOFF_MAP_ARGS) {
  gr_rain_runoff_maps_at m;
  m.md = max_depth[c];
  m.msp = max_speed[c];
  m.mh = max_hazard[c];
  (void)arrival;
  (void)wet_time;
  (void)wet_time_lo;
  (void)wet_since;
  (void)wet_since_lo;
  (void)wetting_depth;
  (void)debris_factor;
  return m;
}

/* Cell c turns wet (wet) or dry at the start of the step whose end folds
 * it, t0 = (t0_hi + t0_lo, a double-float pair): a wet spell begins at t0
 * (and the arrival time, the step's end t1, is set where the cell was
 * never wet), or the spell under way ends and its length t0 - wet_since
 * joins wet_time in double-float arithmetic (TwoSum, FP_CONTRACT off: to
 * about 2^-44 of the times). So a spell wet after the steps ending t_a ..
 * t_b counts t_b - (t_a - dt_a), the sum of those steps' dt. A cell the
 * maps take for dry (wet_since < 0) adds nothing when it dries: a ring
 * cell of a piece whose depth its neighbour's exchange set. */
GR_INLINE void gr_rain_runoff_wet_turn(int c, bool wet, GR_RAIN_RUNOFF_MAP_ARGS, float t1,
                                       float t0_hi, float t0_lo) {
  float sh = wet_since[c];
  if (wet) {
    if (sh < 0.0f) {
      wet_since[c] = t0_hi;
      wet_since_lo[c] = t0_lo;
    }
    if (arrival[c] < 0.0f)
      arrival[c] = t1;
  } else if (sh >= 0.0f) {
    /* (a, e) = t0_hi - sh exactly, then the low words' difference. */
    float a = t0_hi - sh;
    float bb = a - t0_hi;
    float e = (t0_hi - (a - bb)) + (-sh - bb);
    e += t0_lo - wet_since_lo[c];
    /* wet_time + (a + e): TwoSum of the high words, the rest to the low. */
    float wh = wet_time[c];
    float s = wh + a;
    float sb = s - wh;
    float lo = ((wh - (s - sb)) + (a - sb)) + (wet_time_lo[c] + e);
    float hi = s + lo;
    wet_time[c] = hi;
    wet_time_lo[c] = lo - (hi - s);
    wet_since[c] = -1.0f;
    wet_since_lo[c] = 0.0f;
  }
  (void)max_depth;
  (void)max_speed;
  (void)max_hazard;
  (void)wetting_depth;
  (void)debris_factor;
}

/* Folds cell c's depth d and discharges (u, v) (m^2/s) into the flood maps
 * m read before (gr_rain_runoff_maps_read): the state at the end t1 =
 * map_time.x of a step that began at t0 = map_time.y + map_time.z (a
 * double-float pair; t0 = t1 where no step led to it). was_wet: the cell
 * was above the wetting depth when the maps last saw it (the step kernels:
 * the depth at the step's start, which the fold before left; the maps
 * kernel: wet_since >= 0), so that the arrival and the wet duration are
 * read and written only where the cell turns wet or dry. */
GR_INLINE void gr_rain_runoff_map_fold(int c, bool was_wet, float d, float u, float v,
                                       gr_rain_runoff_maps_at m, GR_RAIN_RUNOFF_MAP_ARGS,
                                       float4 map_time) {
  int moving = d >= GR_RAIN_RUNOFF_VELOCITY_DEPTH;
  /* Divided either way, then selected (a dry cell's quotient is never
   * used): a division under a condition is a branch on NVIDIA devices. */
  float uq = u / d, vq = v / d;
  float ux = moving ? uq : 0.0f, vy = moving ? vq : 0.0f;
  float speed = sqrt(ux * ux + vy * vy);
  /* FD2321's debris factor applies above 0.25 m only (its table gives 0
   * below that depth for every land use). */
  float hazard = d * (speed + 0.5f) + (d > GR_RAIN_RUNOFF_DEBRIS_DEPTH ? debris_factor : 0.0f);
  /* Stores only where a value changes: past the peak most cells write
   * nothing, which keeps the launch's traffic near its reads. */
  bool wet = d > wetting_depth;
  if (d > m.md)
    max_depth[c] = d;
  /* The speed of water above the wetting depth only: q / h of the films a
   * front leaves behind says nothing of the flow (hundreds of m/s). */
  if (wet && speed > m.msp)
    max_speed[c] = speed;
  if (hazard > m.mh)
    max_hazard[c] = hazard;
  if (wet != was_wet)
    gr_rain_runoff_wet_turn(c, wet, GR_RAIN_RUNOFF_MAP_PASS, map_time.x, map_time.y, map_time.z);
}

/* Reads cell c's flood maps, then folds the new state into them. The three
 * maxima are read first, whether or not their values change: reads that
 * wait on the new depth cost the local inertial update on the H200 4 % of
 * its time where every wet cell made them (the arrival and the wet time,
 * before they were kept by transitions). */
GR_INLINE void gr_rain_runoff_map_cell(int c, bool was_wet, float d, float u, float v,
                                       GR_RAIN_RUNOFF_MAP_ARGS, float4 map_time) {
  gr_rain_runoff_map_fold(c, was_wet, d, u, v, gr_rain_runoff_maps_read(c, GR_RAIN_RUNOFF_MAP_PASS),
                          GR_RAIN_RUNOFF_MAP_PASS, map_time);
}

/* The sources of the next step, per cell (m/s of depth): the point inflows
 * field (pts, when use_pts) and the inflow of each domain edge's hydrograph
 * spread evenly over its cells (edge_*: west, east, south, north; 0 on a
 * side without one, or with a neighbour), added in that fixed order. */
__kernel void rain_runoff_source(__global const float *restrict pts, int use_pts,
                                 __global float *restrict src, int nx, int ny, float edge_w,
                                 float edge_e, float edge_s, float edge_n) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny))
    return;
  int c = gr_idx(i, j, nx);
  float s = use_pts ? pts[c] : 0.0f;
  s += i == 0 ? edge_w : 0.0f;
  s += i == nx - 1 ? edge_e : 0.0f;
  s += j == 0 ? edge_s : 0.0f;
  s += j == ny - 1 ? edge_n : 0.0f;
  src[c] = s;
}

/* One pass over the grid for the ledger (reduce.h): per work-group the
 * stored, infiltrated, outflow and inflow depths (each cell's Kahan sum,
 * value and compensation, in fixed point: gr_fixed_add's coarse and fine
 * words, metres summed over cells) and the deepest cell (its float's bits);
 * masked: only the cells [own_x0, own_x1) x [own_y0, own_y1) of the
 * row-wide local array (a piece without its ring). Integer sums: the
 * pieces of a split domain add up to the whole grid's, bit for bit.
 * with_sums 0: the deepest cell only (the stable step), one float a cell
 * read instead of eight. */
__kernel void rain_runoff_reduce(
    __global const float *restrict h, __global const float *restrict h_comp,
    __global const float *restrict infiltrated, __global const float *restrict infiltrated_comp,
    __global const float *restrict outflow, __global const float *restrict outflow_comp,
    __global const float *restrict inflow, __global const float *restrict inflow_comp,
    __global long *restrict partial, __local long *restrict scratch, int n, int row, int own_x0,
    int own_x1, int own_y0, int own_y1, int masked, int with_sums) {
  int lid = get_local_id(0), wg = get_local_size(0), start, end;
  gr_reduce_block(n, &start, &end);
  long w[2 * GR_RAIN_RUNOFF_SUMS];
  for (int q = 0; q < 2 * GR_RAIN_RUNOFF_SUMS; ++q)
    w[q] = 0;
  float hmax = 0.0f;
  for (int c = start + lid; c < end; c += wg) {
    if (masked) {
      /* A piece sums its own cells only: its ring belongs to a neighbour. */
      int i = c % row, j = c / row;
      if (i < own_x0 || i >= own_x1 || j < own_y0 || j >= own_y1)
        continue;
    }
    float d = h[c];
    hmax = fmax(hmax, d);
    if (!with_sums)
      continue;
    gr_fixed_add(&w[0], &w[1], d);
    gr_fixed_add(&w[0], &w[1], -h_comp[c]);
    gr_fixed_add(&w[2], &w[3], infiltrated[c]);
    gr_fixed_add(&w[2], &w[3], -infiltrated_comp[c]);
    gr_fixed_add(&w[4], &w[5], outflow[c]);
    gr_fixed_add(&w[4], &w[5], -outflow_comp[c]);
    gr_fixed_add(&w[6], &w[7], inflow[c]);
    gr_fixed_add(&w[6], &w[7], -inflow_comp[c]);
  }
  const int slots = 2 * GR_RAIN_RUNOFF_SUMS + GR_RAIN_RUNOFF_MAXES;
  __local long *mine = gr_reduce_slots_long(scratch, slots);
  for (int q = 0; q < 2 * GR_RAIN_RUNOFF_SUMS; ++q)
    mine[q] = w[q];
  mine[2 * GR_RAIN_RUNOFF_SUMS] = as_int(hmax); /* >= +0: its bits order as the depths */
  gr_reduce_group_long_max(scratch, 2 * GR_RAIN_RUNOFF_SUMS, GR_RAIN_RUNOFF_MAXES, partial);
}

/* Fields derived on read, per cell: 0 water surface (b + h), 1 velocity
 * (3 components, m/s, 0 below GR_RAIN_RUNOFF_VELOCITY_DEPTH), 2 discharge |q|
 * (m^2/s, cell-centred average of the faces), 3 infiltrated (cumulative,
 * m). */
__kernel void
rain_runoff_derive(__global const float *restrict h, __global const float *restrict b,
                   __global const float *restrict qx, __global const float *restrict qy,
                   __global const float *restrict limit, __global const float *restrict infiltrated,
                   __global const float *restrict infiltrated_comp,
                   __global const float *restrict qu, __global const float *restrict qv,
                   __global float *restrict out, int nx, int ny, int what, int sw) {
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
  if (sw) {
    /* The shallow-water model's discharges are the cells' own. */
    float u = qu[c], v = qv[c], d = h[c];
    if (what == 2) {
      out[c] = sqrt(u * u + v * v);
      return;
    }
    int wet = d >= GR_RAIN_RUNOFF_VELOCITY_DEPTH;
    out[3 * c] = wet ? u / d : 0.0f;
    out[3 * c + 1] = wet ? v / d : 0.0f;
    out[3 * c + 2] = 0.0f;
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

/* ------------------------------------------------------- flood maps
 *
 * The cumulative maps (graupel/rain_runoff.h, "Flood maps"), updated from
 * the state a step left by the step's last kernel (rain_runoff_update,
 * rain_runoff_sw_update2: gr_rain_runoff_map_cell) and by this kernel when
 * no step did (a reset, a new initial depth), per cell and in place: each
 * work-item (i, j) reads and writes its own cell only, so the launch needs
 * no atomics and gives the same floats whatever the work-group size. The
 * velocity is the one VELOCITY reads (rain_runoff_derive's): the cell's own
 * discharges for shallow water, the mean of its limited faces for the local
 * inertial model, over the depth, 0 below GR_RAIN_RUNOFF_VELOCITY_DEPTH.
 * arrival < 0 means "never wet" (the host reads it as NaN: a NaN would not
 * survive a compiler's finite-math assumptions). It folds the present
 * state in at map_time (x: the time, y + z: the same as a double-float
 * pair) without adding time (after a reset, a new initial depth, a loaded
 * checkpoint or a new wetting depth), the cell's wet state before taken
 * from the maps themselves (wet_since), not from a depth: the depth may
 * have been set since. */
__kernel void rain_runoff_maps(__global const float *restrict h, __global const float *restrict qu,
                               __global const float *restrict qv, __global const float *restrict qx,
                               __global const float *restrict qy,
                               __global const float *restrict limit, GR_RAIN_RUNOFF_MAP_ARGS,
                               int nx, int ny, int sw, float4 map_time) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny))
    return;
  int c = gr_idx(i, j, nx);
  float d = h[c], u, v;
  if (sw) {
    u = qu[c];
    v = qv[c];
  } else {
    float kc = limit[c];
    float fw =
        gr_rain_runoff_limited(qx[j * (nx + 1) + i], limit[gr_idx(max(i - 1, 0), j, nx)], kc);
    float fe = gr_rain_runoff_limited(qx[j * (nx + 1) + i + 1], kc,
                                      limit[gr_idx(min(i + 1, nx - 1), j, nx)]);
    float fs = gr_rain_runoff_limited(qy[j * nx + i], limit[gr_idx(i, max(j - 1, 0), nx)], kc);
    float fn =
        gr_rain_runoff_limited(qy[(j + 1) * nx + i], kc, limit[gr_idx(i, min(j + 1, ny - 1), nx)]);
    u = 0.5f * (fw + fe);
    v = 0.5f * (fs + fn);
  }
  gr_rain_runoff_map_cell(c, wet_since[c] >= 0.0f, d, u, v, GR_RAIN_RUNOFF_MAP_PASS, map_time);
}

/* The local inertial model: always in the program (its stable step's
 * kernel serves either model's program). */
#include "rain_runoff_li.cl"

/* The shallow-water model's functions and kernels, left out of a program
 * built for the local inertial model alone (-DGR_RAIN_RUNOFF_SW=0: half the
 * source, a third less time to build on PoCL). */
#if GR_RAIN_RUNOFF_SW
#include "rain_runoff_sw.cl"
#endif /* GR_RAIN_RUNOFF_SW */
