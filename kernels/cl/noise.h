/* 2-D gradient (Perlin) noise shared by the kernels that make procedural
 * fields: the terrain (procedural_terrain.cl) and the sky (sky.cl). Moved out
 * of procedural_terrain.cl unchanged, so the terrain's values are the same
 * bit for bit. */
#ifndef GRAUPEL_CL_NOISE_H
#define GRAUPEL_CL_NOISE_H

#include "common.h"

/* 16 unit gradients at multiples of 22.5 degrees, as separate x and y
 * tables: scalar loads keep the kernel vectorisable on CPUs. */
__constant float gr_grad_x[16] = {
    1.0f,  0.9238795f,  0.7071068f,  0.3826834f,  0.0f, -0.3826834f, -0.7071068f, -0.9238795f,
    -1.0f, -0.9238795f, -0.7071068f, -0.3826834f, 0.0f, 0.3826834f,  0.7071068f,  0.9238795f};
__constant float gr_grad_y[16] = {
    0.0f, 0.3826834f,  0.7071068f,  0.9238795f,  1.0f,  0.9238795f,  0.7071068f,  0.3826834f,
    0.0f, -0.3826834f, -0.7071068f, -0.9238795f, -1.0f, -0.9238795f, -0.7071068f, -0.3826834f};

GR_INLINE float gr_fade(float t) {
  /* 6t^5 - 15t^4 + 10t^3: C2-continuous interpolation weight. */
  return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f);
}

GR_INLINE float gr_corner(int ix, int iy, uint seed, float fx, float fy) {
  uint k = gr_hash3(ix, iy, seed) & 15U;
  return gr_grad_x[k] * fx + gr_grad_y[k] * fy;
}

/* Gradient noise at lattice cell (ix, iy) with fractional position (fx, fy)
 * in [0, 1); scaled by sqrt(2) so that |result| <= 1. */
GR_INLINE float gr_gradient_noise(int ix, int iy, float fx, float fy, uint seed) {
  float u = gr_fade(fx), v = gr_fade(fy);
  float n00 = gr_corner(ix, iy, seed, fx, fy);
  float n10 = gr_corner(ix + 1, iy, seed, fx - 1.0f, fy);
  float n01 = gr_corner(ix, iy + 1, seed, fx, fy - 1.0f);
  float n11 = gr_corner(ix + 1, iy + 1, seed, fx - 1.0f, fy - 1.0f);
  float a = n00 + u * (n10 - n00);
  float b = n01 + u * (n11 - n01);
  float n = (a + v * (b - a)) * 1.41421356f;
  return clamp(n, -1.0f, 1.0f);
}

#endif
