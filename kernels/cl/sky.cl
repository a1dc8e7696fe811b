/* The cloud cover of seed 001's sky: fBm of the
 * terrain's gradient noise drifting with the wind, thresholded at the
 * Cover's quantile and shaped by Elias's density curve. The model is
 * documented in graupel/sky.h; the lightning is host code (kernels/src/sky.c). */
#include "common.h"
#include "noise.h"
#include "sky_shared.h"

/* n in [0, 1] at point (i, j): octave o's lattice coordinate is
 * lat_o + frac_o + i*step_o (the host splits the origin, as the terrain
 * does, so that float keeps its precision far from (0, 0)). */
__kernel void sky_cloud_noise(__global float *restrict noise, int nx, int ny,
                              __global const float *restrict table,
                              __global const int *restrict lattice, uint seed) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny))
    return;
  float sum = 0.0f, norm = 0.0f, a = 1.0f;
#pragma unroll
  for (int o = 0; o < GR_SKY_OCTAVES; ++o) {
    __global const float *row = table + GR_SKY_TABLE_STRIDE * o;
    float x = row[0] + (float)i * row[2];
    float y = row[1] + (float)j * row[3];
    float fx = floor(x), fy = floor(y);
    __global const int *cell = lattice + GR_SKY_LATTICE_STRIDE * o;
    sum +=
        a * gr_gradient_noise(cell[0] + (int)fx, cell[1] + (int)fy, x - fx, y - fy, seed + (uint)o);
    norm += a;
    a *= (float)GR_SKY_PERSISTENCE;
  }
  noise[gr_idx(i, j, nx)] = clamp(0.5f * (sum / norm + 1.0f), 0.0f, 1.0f);
}

/* cloud = 1 - Sharpness^(255 (n - T)) above the threshold T, else 0;
 * log_sharpness = 255 ln(Sharpness) (<= 0). sky_rgb: blue mixed towards
 * white by cloud, the thickest cloud greyed. One work-item per pixel of
 * the band k0 .. kend-1 (row-major indices). */
__kernel void sky_cloud_shade(__global const float *restrict noise, __global float *restrict cloud,
                              __global uchar *restrict rgb, int k0, int kend, float threshold,
                              float log_sharpness) {
  int k = k0 + (int)get_global_id(0);
  if (k >= kend)
    return;
  float e = noise[k] - threshold;
  float c = e > 0.0f ? 1.0f - exp(log_sharpness * e) : 0.0f;
  c = clamp(c, 0.0f, 1.0f);
  cloud[k] = c;
  float white = GR_SKY_WHITE + (GR_SKY_GREY - GR_SKY_WHITE) * c * c;
  float r = GR_SKY_BLUE_R + (white - GR_SKY_BLUE_R) * c;
  float g = GR_SKY_BLUE_G + (white - GR_SKY_BLUE_G) * c;
  float b = GR_SKY_BLUE_B + (white - GR_SKY_BLUE_B) * c;
  rgb[3 * k + 0] = (uchar)(255.0f * r + 0.5f);
  rgb[3 * k + 1] = (uchar)(255.0f * g + 0.5f);
  rgb[3 * k + 2] = (uchar)(255.0f * b + 0.5f);
}
