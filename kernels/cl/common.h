/* Helpers shared by every Graupel kernel. Inlined into each program when the
 * sources are embedded, so that the host never looks for files at run time. */
#ifndef GRAUPEL_CL_COMMON_H
#define GRAUPEL_CL_COMMON_H

/* No silent fused multiply-adds: CPU (PoCL) and GPU results must agree to
 * rounding, and reruns must match bit for bit. Where a kernel wants an FMA it
 * writes fma() explicitly. */
#pragma OPENCL FP_CONTRACT OFF

/* Helpers must inline: a call left inside the work-item loop stops CPU
 * compilers (PoCL) from vectorising a kernel across work-items. */
#define GR_INLINE inline __attribute__((always_inline))

/* Row-major index of point (i, j) on an nx-wide grid (i fastest). */
GR_INLINE int gr_idx(int i, int j, int nx) {
  return j * nx + i;
}

/* True when the work-item (i, j) lies on the grid; kernels are launched over
 * sizes rounded up to the work-group size. */
GR_INLINE bool gr_inside(int i, int j, int nx, int ny) {
  return i < nx && j < ny;
}

/* 32-bit integer hash with full avalanche (multiply-xorshift rounds); used
 * for lattice gradients and per-cell random numbers. */
GR_INLINE uint gr_hash_u32(uint x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}

GR_INLINE uint gr_hash3(int a, int b, uint c) {
  uint h = gr_hash_u32((uint)a * 0x9e3779b1U);
  h = gr_hash_u32(h ^ ((uint)b * 0x85ebca77U));
  return gr_hash_u32(h ^ (c * 0xc2b2ae3dU));
}

#endif
