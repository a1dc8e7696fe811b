/* The practical bandwidth limit of a device: a plain float4 copy. The
 * benchmark reports every core's traffic as a fraction of this. */
#include "common.h"

__kernel void bench_copy(__global const float4 *src, __global float4 *dst, int n4) {
  int i = get_global_id(0);
  if (i < n4)
    dst[i] = src[i];
}
