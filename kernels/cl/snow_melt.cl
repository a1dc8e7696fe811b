/* Snow melt: Hock's (1999) enhanced temperature-index melt with potential
 * clear-sky radiation, cast shadows from precomputed horizons, rain, held
 * liquid water, refreezing and settling, point by point. The model and the
 * step's order are documented in graupel/snow_melt.h. */
#include "common.h"
#include "reduce.h"
#include "snow_melt_shared.h"

/* m (>= 0) of water equivalent as the state's integers (2^-32 m), to
 * nearest: a cut toward zero after adding 1/2 below 2^23 units (where the
 * sum is exact), the float itself from there (a whole number from 2^23 on).
 * PoCL vectorises this, where convert_long_rte is a call per work-item. */
GR_INLINE long gr_sm_units(float m) {
  float u = m * 4294967296.0f;
  return convert_long(u < 8388608.0f ? u + 0.5f : u);
}

GR_INLINE float gr_sm_metres(long u) {
  return convert_float(u) * 2.3283064365386963e-10f; /* 2^-32 */
}

/* h at the fractional index (x, y) of an nx x ny field, 0 <= x <= nx-1,
 * 0 <= y <= ny-1 (terrain_analysis.cl's reading). */
GR_INLINE float gr_sm_bilinear(__global const float *restrict h, int nx, int ny, float x, float y) {
  int ix = min((int)x, max(nx - 2, 0)), iy = min((int)y, max(ny - 2, 0));
  float fx = x - (float)ix, fy = y - (float)iy;
  int ix1 = min(ix + 1, nx - 1), iy1 = min(iy + 1, ny - 1);
  float h00 = h[gr_idx(ix, iy, nx)], h10 = h[gr_idx(ix1, iy, nx)];
  float h01 = h[gr_idx(ix, iy1, nx)], h11 = h[gr_idx(ix1, iy1, nx)];
  float lo = h00 + fx * (h10 - h00), hi = h01 + fx * (h11 - h01);
  return lo + fy * (hi - lo);
}

/* The horizon angle (rad, at least 0) of own point (i, jj) in each of the
 * sectors directions k 2 pi / sectors clockwise from north, over the whole
 * domain's terrain (nx x gny; the own rows start at its row j0): a ray
 * steps one cell along its faster axis, reading the terrain bilinearly, and
 * keeps the steepest rise; it ends where it leaves the domain or where the
 * highest terrain (h_max) could no longer rise above what it found. Blocks
 * of GR_SNOW_MELT_BLOCK cells whose highest point (block_max: the block and
 * the row and column after it, all a bilinear read inside it touches) could
 * not rise above what was found are stepped over whole: samples that cannot
 * change a maximum are never taken, so the answer is the full march's. */
__kernel void snow_melt_horizon(__global const float *restrict terrain,
                                __global const float *restrict block_max, int nx, int gny, int j0,
                                int own_ny, float dx, float dy, int sectors, float h_max,
                                __global float *restrict horizon) {
  int i = get_global_id(0), jj = get_global_id(1);
  if (i >= nx || jj >= own_ny)
    return;
  int j = j0 + jj, n = nx * own_ny, c = gr_idx(i, jj, nx);
  int bnx = (nx + GR_SNOW_MELT_BLOCK - 1) / GR_SNOW_MELT_BLOCK;
  float h0 = terrain[gr_idx(i, j, nx)];
  float x_end = (float)(nx - 1), y_end = (float)(gny - 1);
  for (int k = 0; k < sectors; ++k) {
    float az = (float)k * (6.283185307179586f / (float)sectors);
    float ux = sin(az) / dx, uy = cos(az) / dy; /* index units per metre */
    float step_len = 1.0f / fmax(fabs(ux), fabs(uy));
    float step_i = ux * step_len, step_j = uy * step_len;
    float best = 0.0f; /* the tangent of the highest rise, never below level */
    for (int q = 1;;) {
      float x = (float)i + (float)q * step_i, y = (float)j + (float)q * step_j;
      if (!(x >= 0.0f && x <= x_end && y >= 0.0f && y <= y_end))
        break;
      float t = (float)q * step_len;
      if ((h_max - h0) / t <= best)
        break;
      int bi = (int)x / GR_SNOW_MELT_BLOCK, bj = (int)y / GR_SNOW_MELT_BLOCK;
      if ((block_max[bj * bnx + bi] - h0) / t <= best) {
        /* The first step whose sample lies in another block. */
        float lo_x = (float)(bi * GR_SNOW_MELT_BLOCK), lo_y = (float)(bj * GR_SNOW_MELT_BLOCK);
        float qx = step_i > 0.0f   ? ceil((lo_x + GR_SNOW_MELT_BLOCK - (float)i) / step_i)
                   : step_i < 0.0f ? floor(((float)i - lo_x) / -step_i) + 1.0f
                                   : INFINITY;
        float qy = step_j > 0.0f   ? ceil((lo_y + GR_SNOW_MELT_BLOCK - (float)j) / step_j)
                   : step_j < 0.0f ? floor(((float)j - lo_y) / -step_j) + 1.0f
                                   : INFINITY;
        q = max(q + 1, (int)fmin(fmin(qx, qy), 1.0e9f));
        continue;
      }
      best = fmax(best, (gr_sm_bilinear(terrain, nx, gny, x, y) - h0) / t);
      ++q;
    }
    horizon[k * n + c] = atan(best);
  }
}

/* The mean potential direct radiation I (W/m^2) over the ns sub-steps of
 * records first .. first + ns - 1: Hock's I0 (Rm/R)^2 Psi^(P / (P0 cos Z))
 * cos(theta) on the slope of unit normal nrm.xyz, nrm.w = ln(Psi) P / P0;
 * 0 where the sun is down, behind the slope or (shadows) below the horizon
 * interpolated between the sectors around its azimuth. */
GR_INLINE float gr_sm_radiation(__global const float *restrict table, int first, int ns, float4 nrm,
                                __global const float *restrict horizon, int c, int n, int sectors,
                                int shadows) {
  float sum = 0.0f;
  for (int q = 0; q < ns; ++q) {
    __global const float *r = table + (first + q) * GR_SNOW_MELT_RECORD;
    float top = r[3];
    float cos_theta = nrm.x * r[0] + nrm.y * r[1] + nrm.z * r[2];
    if (!(top > 0.0f) || !(cos_theta > 0.0f))
      continue;
    if (shadows) {
      float pos = r[5];
      int k0 = min((int)pos, sectors - 1);
      float w = pos - (float)k0;
      int k1 = k0 + 1 == sectors ? 0 : k0 + 1;
      float hz = horizon[k0 * n + c] * (1.0f - w) + horizon[k1 * n + c] * w;
      if (!(r[6] > hz))
        continue;
    }
    sum += top * exp(nrm.w * r[4]) * cos_theta;
  }
  return sum / (float)ns;
}

/* One step of dt (dt_h hours) at each own point c < n, in the order of
 * snow_melt.h (precip_m: the forcing's precipitation in the step, m;
 * field_m: m per mm/h of the precipitation field): the forcing, snowfall, rain, melt, refreezing,
 * release and settling. The water is in integers (gr_sm_units), every transfer one integer taken
 * from one side and added to the other and to its accumulators, so the balance is exact. */
__kernel void snow_melt_step(
    __global long *restrict frozen, __global long *restrict liquid,
    __global float *restrict density, __global float *restrict radiation,
    __global long *restrict acc, __global const float *restrict elevation,
    __global const float4 *restrict normal, __global const float *restrict horizon,
    __global const float *restrict temperature, __global const float *restrict precipitation,
    __global const float *restrict table, int first, int ns, int n, int sectors, int shadows,
    int use_t, int use_p, float t_ref, float lapse_per_m, float z_ref, float precip_m,
    float field_m, float dt_h, float mf_h, float rad_factor, float t0, float ts, float band,
    float rho_new, float rho_max, float settle, float capacity, float refreeze_h, float rain_heat) {
  int c = get_global_id(0);
  if (c >= n)
    return;
  float T = use_t ? temperature[c] : t_ref + lapse_per_m * (elevation[c] - z_ref);
  float4 nrm = normal[c];
  float I = gr_sm_radiation(table, first, ns, nrm, horizon, c, n, sectors, shadows);
  long F = frozen[c], L = liquid[c];
  float rho = density[c];
  /* Precipitation: the rain's integers, the snow the rest of the total. */
  float fl =
      band > 0.0f ? clamp((T - (ts - 0.5f * band)) / band, 0.0f, 1.0f) : (T >= ts ? 1.0f : 0.0f);
  float p_m = use_p ? precipitation[c] * field_m : precip_m; /* m in the step */
  long total = gr_sm_units(p_m), rain = gr_sm_units(p_m * fl);
  rain = min(rain, total);
  long snow = total - rain;
  if (snow > 0) {
    long swe = F + L;
    rho = swe > 0 ? (convert_float(swe) * rho + convert_float(snow) * rho_new) /
                        convert_float(swe + snow)
                  : rho_new;
    F += snow;
  }
  long released = 0;
  float melt_mm = 0.0f;
  if (F > 0) {
    L += rain;
    melt_mm = rain_heat * (p_m * fl * 1000.0f) * fmax(T, 0.0f);
  } else {
    released += rain;
  }
  if (T > t0)
    melt_mm += (mf_h + rad_factor * I) * (T - t0) * dt_h;
  long melt = min(gr_sm_units(melt_mm * 0.001f), F);
  F -= melt;
  L += melt;
  long refrozen = 0;
  if (T < t0) {
    refrozen = min(gr_sm_units(refreeze_h * (t0 - T) * dt_h * 0.001f), L);
    L -= refrozen;
    F += refrozen;
  }
  /* Held up to the capacity (none without frozen water). */
  long cap = F > 0 ? gr_sm_units(capacity * gr_sm_metres(F)) : 0;
  if (L > cap) {
    released += L - cap;
    L = cap;
  }
  if (F + L > 0)
    rho = rho_max - (rho_max - rho) * settle;
  frozen[c] = F;
  liquid[c] = L;
  density[c] = rho;
  radiation[c] = I;
  acc[GR_SNOW_MELT_ACC_SNOW * n + c] += snow;
  acc[GR_SNOW_MELT_ACC_RAIN * n + c] += rain;
  acc[GR_SNOW_MELT_ACC_MELT * n + c] += melt;
  acc[GR_SNOW_MELT_ACC_REFROZEN * n + c] += refrozen;
  acc[GR_SNOW_MELT_ACC_RELEASED * n + c] += released;
  acc[GR_SNOW_MELT_ACC_MARK_MELT * n + c] += melt;
  acc[GR_SNOW_MELT_ACC_MARK_RELEASED * n + c] += released;
}

/* The ledger's sums over the n own points: frozen, liquid and the
 * accumulators (snow, rain, melt, refrozen, released, released since the
 * mark), each as its bits above and below GR_SNOW_MELT_SPLIT_BITS: integer
 * sums, the same in any order and over any split. */
__kernel void snow_melt_reduce(__global const long *restrict frozen,
                               __global const long *restrict liquid,
                               __global const long *restrict acc, __global long *restrict partial,
                               __local long *restrict scratch, int n) {
  int lid = get_local_id(0), wg = get_local_size(0), start, end;
  gr_reduce_block(n, &start, &end);
  long w[GR_SNOW_MELT_WORDS];
  for (int q = 0; q < GR_SNOW_MELT_WORDS; ++q)
    w[q] = 0;
  const long low = (1L << GR_SNOW_MELT_SPLIT_BITS) - 1;
  for (int c = start + lid; c < end; c += wg) {
    long v[GR_SNOW_MELT_SUMS] = {frozen[c],
                                 liquid[c],
                                 acc[GR_SNOW_MELT_ACC_SNOW * n + c],
                                 acc[GR_SNOW_MELT_ACC_RAIN * n + c],
                                 acc[GR_SNOW_MELT_ACC_MELT * n + c],
                                 acc[GR_SNOW_MELT_ACC_REFROZEN * n + c],
                                 acc[GR_SNOW_MELT_ACC_RELEASED * n + c],
                                 acc[GR_SNOW_MELT_ACC_MARK_RELEASED * n + c]};
    for (int q = 0; q < GR_SNOW_MELT_SUMS; ++q) {
      w[2 * q] += v[q] >> GR_SNOW_MELT_SPLIT_BITS;
      w[2 * q + 1] += v[q] & low;
    }
  }
  __local long *mine = gr_reduce_slots_long(scratch, GR_SNOW_MELT_WORDS);
  for (int q = 0; q < GR_SNOW_MELT_WORDS; ++q)
    mine[q] = w[q];
  gr_reduce_group_long(scratch, GR_SNOW_MELT_WORDS, partial);
}

/* An output at each own point c < n (snow_melt.h's list); rate_scale turns
 * the integers since the mark into mm/h. */
__kernel void snow_melt_derive(__global const long *restrict frozen,
                               __global const long *restrict liquid,
                               __global const float *restrict density,
                               __global const float *restrict radiation,
                               __global const long *restrict acc, __global float *restrict out,
                               int n, int what, float rate_scale) {
  int c = get_global_id(0);
  if (c >= n)
    return;
  long swe = frozen[c] + liquid[c];
  float v;
  switch (what) {
  case GR_SNOW_MELT_DERIVE_DEPTH:
    v = swe > 0 ? gr_sm_metres(swe) * 1000.0f / density[c] : 0.0f;
    break;
  case GR_SNOW_MELT_DERIVE_DENSITY:
    v = swe > 0 ? density[c] : 0.0f;
    break;
  case GR_SNOW_MELT_DERIVE_SWE:
    v = gr_sm_metres(swe);
    break;
  case GR_SNOW_MELT_DERIVE_LIQUID:
    v = gr_sm_metres(liquid[c]);
    break;
  case GR_SNOW_MELT_DERIVE_MELT_RATE:
    v = convert_float(acc[GR_SNOW_MELT_ACC_MARK_MELT * n + c]) * rate_scale;
    break;
  case GR_SNOW_MELT_DERIVE_RELEASE_RATE:
    v = convert_float(acc[GR_SNOW_MELT_ACC_MARK_RELEASED * n + c]) * rate_scale;
    break;
  case GR_SNOW_MELT_DERIVE_RADIATION:
    v = radiation[c];
    break;
  default:
    v = gr_sm_metres(acc[GR_SNOW_MELT_ACC_MARK_RELEASED * n + c]);
    break;
  }
  out[c] = v;
}
