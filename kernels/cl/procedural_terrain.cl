/* Procedural terrain (seed 001's terrain, after libnoise): 2-D gradient noise
 * summed over octaves as fBm, billow or (inverted) ridged multifractal. The
 * normalisation is documented in graupel/procedural_terrain.h. */
#include "common.h"
#include "noise.h"
#include "procedural_terrain_shared.h"

/* Per-octave set-up computed by the host in double (graupel/procedural_terrain.h):
 * for octave o, point i of a piece starting at global index i0 lies at
 * lattice coordinate lat_o + frac_o + (i0 + i)*step_o,
 * where lat_o is the integer part of the grid origin in that octave's lattice
 * units and frac_o its fraction. Splitting the origin this way keeps full
 * float precision far from (0, 0), so distant tiles are as detailed as near
 * ones. table[4o..4o+3] = (frac_x, frac_y, step_x, step_y), amp[o] = octave
 * weight (p^o, or lambda^(-oH) for ridged), lattice[2o..2o+1] = (lat_x,
 * lat_y). Scalar arrays rather than float4/int2: vector-typed values inside
 * the work-item loop stop PoCL's vectoriser. */
__kernel void procedural_terrain_generate(__global float *restrict elevation, int nx, int ny,
                                          int i0, int j0, __global const float *restrict table,
                                          __global const float *restrict amp,
                                          __global const int *restrict lattice, uint seed, int kind,
                                          int octaves, float offset, float gain, int invert,
                                          float height_scale) {
  int i = get_global_id(0), j = get_global_id(1);
  if (!gr_inside(i, j, nx, ny))
    return;
    /* The host compiles one variant per noise type and octave count, so the
     * loop below has a constant trip count: unrolled, it is straight-line code
     * that CPU compilers (PoCL) vectorise across work-items. */
#ifdef GR_TERRAIN_OCTAVES
  octaves = GR_TERRAIN_OCTAVES;
#endif
#ifdef GR_TERRAIN_KIND
  kind = GR_TERRAIN_KIND;
#endif
  float sum = 0.0f, norm = 0.0f;
  float weight = 1.0f; /* ridged: the previous octave's weight */
#ifdef GR_TERRAIN_OCTAVES
#pragma unroll
#endif
  for (int o = 0; o < octaves; ++o) {
    __global const float *row = table + GR_PT_TABLE_STRIDE * o;
    float x = row[0] + (float)(i0 + i) * row[2];
    float y = row[1] + (float)(j0 + j) * row[3];
    float fx = floor(x), fy = floor(y);
    __global const int *cell = lattice + GR_PT_LATTICE_STRIDE * o;
    float g =
        gr_gradient_noise(cell[0] + (int)fx, cell[1] + (int)fy, x - fx, y - fy, seed + (uint)o);
    float a = amp[o];
    if (kind == GR_PT_KIND_RIDGED) {
      float s = offset - fabs(g);
      s = s * s * weight;
      weight = clamp(s * gain, 0.0f, 1.0f);
      sum += s * a;
      norm += offset * offset * a;
    } else {
      float v = kind == GR_PT_KIND_BILLOW ? 2.0f * fabs(g) - 1.0f : g;
      sum += v * a;
      norm += a;
    }
  }
  float n;
  if (kind == GR_PT_KIND_RIDGED) {
    n = norm > 0.0f ? sum / norm : 0.0f;
    if (invert)
      n = 1.0f - n;
  } else {
    n = norm > 0.0f ? 0.5f * (sum / norm + 1.0f) : 0.5f;
  }
  elevation[gr_idx(i, j, nx)] = height_scale * clamp(n, 0.0f, 1.0f);
}
