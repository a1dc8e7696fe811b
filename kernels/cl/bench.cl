/* The practical bandwidth limit of a device: a plain float4 copy. The
 * benchmark reports every core's traffic as a fraction of this. */
#include "common.h"

__kernel void bench_copy(__global const float4 *src, __global float4 *dst, int n4) {
  int i = get_global_id(0);
  if (i < n4)
    dst[i] = src[i];
}

/* The yardstick of issues 8 and 10 (a step against plain 5-point stencil
 * passes measured in the same run): one Jacobi pass of the 5-point
 * Laplacian, edges clamped. */
__kernel void bench_stencil5(__global const float *restrict in, int nx, int ny,
                             __global float *restrict out) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny))
    return;
  int c = gr_idx(i, j, nx);
  float w = in[gr_idx(max(i - 1, 0), j, nx)], e = in[gr_idx(min(i + 1, nx - 1), j, nx)];
  float sn = in[gr_idx(i, max(j - 1, 0), nx)], n = in[gr_idx(i, min(j + 1, ny - 1), nx)];
  out[c] = 0.2f * (in[c] + w + e + sn + n);
}
