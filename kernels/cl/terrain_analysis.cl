/* Terrain analysis (seed 001's snow/ice cover and shadows): derivatives,
 * hillshade, snow cover and classes, and the ray-marched shadow mask. The
 * definitions are in graupel/terrain_analysis.h. */
#include "common.h"
#include "terrain_analysis_shared.h"

/* One derivative along an axis: central inside, one-sided at the ends, 0 on
 * an axis of one point. inv_d is 1 / spacing. */
GR_INLINE float gr_ta_diff(float lo, float mid, float hi, int at, int n, float inv_d) {
  if (n < 2)
    return 0.0f;
  if (at == 0)
    return (hi - mid) * inv_d;
  if (at == n - 1)
    return (mid - lo) * inv_d;
  return (hi - lo) * (0.5f * inv_d);
}

__kernel void
terrain_analysis_derive(__global const float *restrict heights, int nx, int ny, float inv_dx,
                        float inv_dy, float sun_x, float sun_y, float sun_z, float snow_exponent,
                        int cover_mode, float snow_cover_limit, float rock_slope, float water_level,
                        int use_shadow, __global const float *restrict shadow,
                        __global float *restrict normal, __global float *restrict slope,
                        __global float *restrict aspect, __global float *restrict hillshade,
                        __global float *restrict snow_cover, __global uchar *restrict cover_class) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny))
    return;
  int c = gr_idx(i, j, nx);
  float h = heights[c];
  float west = i > 0 ? heights[c - 1] : h, east = i < nx - 1 ? heights[c + 1] : h;
  float south = j > 0 ? heights[c - nx] : h, north = j < ny - 1 ? heights[c + nx] : h;
  float gx = gr_ta_diff(west, h, east, i, nx, inv_dx);
  float gy = gr_ta_diff(south, h, north, j, ny, inv_dy);
  float g2 = gx * gx + gy * gy;
  float inv_len = rsqrt(g2 + 1.0f);
  /* 0 - g, not -g: a flat field's normal is (+0, +0, 1), never -0. */
  float n_x = (0.0f - gx) * inv_len, n_y = (0.0f - gy) * inv_len, n_z = inv_len;
  normal[3 * c] = n_x;
  normal[3 * c + 1] = n_y;
  normal[3 * c + 2] = n_z;
  float s = degrees(atan(sqrt(g2)));
  slope[c] = s;
  /* Compass bearing of the downslope vector (-gx, -gy): atan2(east, north). */
  float a = degrees(atan2(0.0f - gx, 0.0f - gy));
  a = a < 0.0f ? a + 360.0f : a;
  aspect[c] = g2 > 0.0f ? (a >= 360.0f ? 0.0f : a) : GR_TA_ASPECT_FLAT;
  float lit = n_x * sun_x + n_y * sun_y + n_z * sun_z;
  lit = fmax(lit, 0.0f);
  if (use_shadow)
    lit *= shadow[c];
  hillshade[c] = lit;
  float cover = cover_mode == GR_TA_COVER_THRESHOLD ? (s <= rock_slope ? 1.0f : 0.0f)
                                                    : pow(clamp(n_z, 0.0f, 1.0f), snow_exponent);
  snow_cover[c] = cover;
  uchar k = GR_TA_CLASS_GROUND;
  if (h < water_level)
    k = GR_TA_CLASS_ICE;
  else if (s > rock_slope)
    k = GR_TA_CLASS_ROCK;
  else if (cover >= snow_cover_limit)
    k = GR_TA_CLASS_SNOW;
  cover_class[c] = k;
}

/* h at the fractional index (x, y), 0 <= x <= nx-1, 0 <= y <= ny-1. */
GR_INLINE float gr_ta_bilinear(__global const float *restrict heights, int nx, int ny, float x,
                               float y) {
  int ix = min((int)x, max(nx - 2, 0)), iy = min((int)y, max(ny - 2, 0));
  float fx = x - (float)ix, fy = y - (float)iy;
  int ix1 = min(ix + 1, nx - 1), iy1 = min(iy + 1, ny - 1);
  float h00 = heights[gr_idx(ix, iy, nx)], h10 = heights[gr_idx(ix1, iy, nx)];
  float h01 = heights[gr_idx(ix, iy1, nx)], h11 = heights[gr_idx(ix1, iy1, nx)];
  float lo = h00 + fx * (h10 - h00), hi = h01 + fx * (h11 - h01);
  return lo + fy * (hi - lo);
}

/* step_i, step_j: one step towards the sun in index units (the faster axis
 * moves by exactly 1); step_len: its length in metres. tan_lit, tan_dark:
 * the tangents of the lowest and highest sun elevation of the penumbra
 * (equal for a hard shadow); below tan_lit the point is fully lit, at or
 * above tan_dark fully dark. h_max: the field's maximum, which bounds what
 * a ray can still meet. ny is the end of the band of rows computed. */
__kernel void terrain_analysis_shadow(__global const float *restrict heights, int nx, int ny,
                                      int rows_end, float step_i, float step_j, float step_len,
                                      float tan_lit, float tan_dark, float sun_elevation,
                                      float penumbra, float h_max,
                                      __global float *restrict shadow) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, rows_end))
    return;
  float h0 = heights[gr_idx(i, j, nx)];
  float x_end = (float)(nx - 1), y_end = (float)(ny - 1);
  float best = -INFINITY; /* tangent of the highest horizon met so far */
  for (int k = 1;; ++k) {
    /* Positions by multiplication, not accumulation: along an axis they stay
     * on grid points exactly. */
    float x = (float)i + (float)k * step_i, y = (float)j + (float)k * step_j;
    if (!(x >= 0.0f && x <= x_end && y >= 0.0f && y <= y_end))
      break;
    float t = (float)k * step_len;
    /* Nothing farther can rise above (h_max - h0) / t: stop once that
     * cannot change the answer. */
    float bound = (h_max - h0) / t;
    if (bound <= best || bound < tan_lit || best >= tan_dark)
      break;
    float rise = (gr_ta_bilinear(heights, nx, ny, x, y) - h0) / t;
    best = fmax(best, rise);
  }
  float lit;
  if (penumbra > 0.0f) {
    float horizon = best == -INFINITY ? -90.0f : degrees(atan(best));
    lit = clamp(0.5f + (sun_elevation - horizon) / penumbra, 0.0f, 1.0f);
  } else {
    lit = best < tan_lit ? 1.0f : 0.0f;
  }
  shadow[gr_idx(i, j, nx)] = lit;
}
