/* Rain (seed 004) and snowfall (seed 001) particles at a time t, each a pure
 * function of (seed, t, index): the model is in graupel/particles.h. One
 * work-item per particle; no state is read, so any time may be asked for in
 * any order. */
#include "common.h"
#include "particles_shared.h"

#define GR_PA_TWO_PI 6.28318530717958647692f

/* The hashes of particle `index`: base mixes (seed, index) once; a stream of
 * the particle's whole existence hashes (base, stream), a stream of one of
 * its lives (base, life, stream). Counter-based: nothing depends on the
 * order of evaluation. */
GR_INLINE uint gr_pa_base(uint seed, uint index) {
  return gr_hash_u32(gr_hash_u32(seed ^ 0x9e3779b9U) ^ index);
}

GR_INLINE uint gr_pa_stream(uint base, uint stream) {
  return gr_hash_u32(base ^ (stream * 0xc2b2ae3dU));
}

GR_INLINE uint gr_pa_life_stream(uint base, int life, uint stream) {
  return gr_hash_u32(gr_hash_u32(base ^ ((uint)life * 0x85ebca77U)) ^ (stream * 0xc2b2ae3dU));
}

/* A uniform number in [0, 1) from the top 24 bits of h: every value is a
 * float exactly, and 1 is never reached. */
GR_INLINE float gr_pa_unit(uint h) {
  return (float)(h >> 8) * 0x1.0p-24f;
}

/* a wrapped into [lo, hi] (hi = lo + w): the box is periodic in x and y. */
GR_INLINE float gr_pa_wrap(float a, float lo, float hi, float w) {
  float r = a - w * floor(a / w);
  return clamp(lo + r, lo, hi);
}

/* Where a particle falling at s m/s (negative: rising) is at time t: c =
 * phase + s t / height counts the lives it has crossed; returns the life's
 * number and the depth below the top (m). */
GR_INLINE int gr_pa_life(float phase, float s, float t, float height, float inv_height,
                         float *depth) {
  float c = phase + s * t * inv_height;
  float k = clamp(floor(c), -1073741824.0f, 1073741824.0f);
  /* Exact: k and c share their leading bits. */
  float f = clamp(c - k, 0.0f, 1.0f);
  *depth = f * height;
  return (int)k;
}

/* n particles; t in s; the box [x0, x1] x [y0, y1] x [z0, z1]; wind (m/s);
 * shift_x, shift_y: the wind's drift wind t reduced modulo the box's width
 * and length (by the host, in double). A life's (x, y) is a hashed point
 * plus that drift: a uniform point of the periodic box shifted is uniform,
 * so a respawned particle appears anywhere, and between two times of one
 * life it moves by exactly the wind's drift, however slowly it falls.
 * exposure (s). d_min (mm), inv_lambda (mm) and cdf_scale (1 - exp(-Lambda
 * (d_max - d_min))) define the truncated Marshall-Palmer sampling. */
__kernel void particles_rain(int n, uint seed, float t, float x0, float x1, float y0, float y1,
                             float z0, float z1, float wind_x, float wind_y, float wind_z,
                             float shift_x, float shift_y, float exposure, float d_min,
                             float inv_lambda, float cdf_scale, __global float *restrict position,
                             __global float *restrict velocity, __global float *restrict size,
                             __global float *restrict streak) {
  int i = get_global_id(0);
  if (i >= n)
    return;
  uint base = gr_pa_base(seed, (uint)i);
  /* Inverse CDF of the truncated exponential. */
  float u = gr_pa_unit(gr_pa_stream(base, GR_PA_STREAM_SIZE));
  float d = d_min - log1p(0.0f - u * cdf_scale) * inv_lambda;
  float v = fmax(GR_PA_FLOAT(GR_PA_ATLAS_A) -
                     GR_PA_FLOAT(GR_PA_ATLAS_B) * exp(-GR_PA_FLOAT(GR_PA_ATLAS_C) * d),
                 0.0f);
  float height = z1 - z0, w = x1 - x0, l = y1 - y0;
  float phase = gr_pa_unit(gr_pa_stream(base, GR_PA_STREAM_PHASE));
  float depth;
  int life = gr_pa_life(phase, v - wind_z, t, height, 1.0f / height, &depth);
  float sx = gr_pa_unit(gr_pa_life_stream(base, life, GR_PA_STREAM_X)) * w;
  float sy = gr_pa_unit(gr_pa_life_stream(base, life, GR_PA_STREAM_Y)) * l;
  float vz = wind_z - v;
  vstore3((float3)(gr_pa_wrap(sx + shift_x, x0, x1, w), gr_pa_wrap(sy + shift_y, y0, y1, l),
                   fmax(z1 - depth, z0)),
          i, position);
  vstore3((float3)(wind_x, wind_y, vz), i, velocity);
  size[i] = d;
  vstore3((float3)(wind_x * exposure, wind_y * exposure, vz * exposure), i, streak);
}

/* As particles_rain; amplitude: FlutterAmplitude (m). */
__kernel void particles_snow(int n, uint seed, float t, float x0, float x1, float y0, float y1,
                             float z0, float z1, float wind_x, float wind_y, float wind_z,
                             float shift_x, float shift_y, float exposure, float amplitude,
                             __global float *restrict position, __global float *restrict velocity,
                             __global float *restrict size, __global float *restrict streak) {
  int i = get_global_id(0);
  if (i >= n)
    return;
  uint base = gr_pa_base(seed, (uint)i);
  const float v_lo = GR_PA_FLOAT(GR_PA_SNOW_SPEED_MIN), v_hi = GR_PA_FLOAT(GR_PA_SNOW_SPEED_MAX);
  const float s_lo = GR_PA_FLOAT(GR_PA_SNOW_SIZE_MIN), s_hi = GR_PA_FLOAT(GR_PA_SNOW_SIZE_MAX);
  const float f_lo = GR_PA_FLOAT(GR_PA_FLUTTER_FREQ_MIN);
  const float f_hi = GR_PA_FLOAT(GR_PA_FLUTTER_FREQ_MAX);
  float v = v_lo + gr_pa_unit(gr_pa_stream(base, GR_PA_STREAM_SPEED)) * (v_hi - v_lo);
  float d = s_lo + gr_pa_unit(gr_pa_stream(base, GR_PA_STREAM_SIZE)) * (s_hi - s_lo);
  float a = amplitude * (0.5f + 0.5f * gr_pa_unit(gr_pa_stream(base, GR_PA_STREAM_FLUTTER_A)));
  float freq = f_lo + gr_pa_unit(gr_pa_stream(base, GR_PA_STREAM_FLUTTER_F)) * (f_hi - f_lo);
  float phi = gr_pa_unit(gr_pa_stream(base, GR_PA_STREAM_FLUTTER_PHI));
  float dir = GR_PA_TWO_PI * gr_pa_unit(gr_pa_stream(base, GR_PA_STREAM_FLUTTER_DIR));
  float dir_x = cos(dir), dir_y = sin(dir);
  /* The sway's angle in turns, reduced before the sine so that a late time
   * keeps its fraction of a turn. Its change over the exposure, a (sin ang -
   * sin(ang - 2 half_arc)) = 2 a cos(ang - half_arc) sin(half_arc), is computed as that
   * product: a difference of two sines would lose it to rounding. */
  float turns = freq * t + phi;
  float ang = GR_PA_TWO_PI * (turns - floor(turns));
  float half_arc = 0.5f * GR_PA_TWO_PI * freq * exposure;
  float sway = a * sin(ang), sway_v = a * GR_PA_TWO_PI * freq * cos(ang);
  float ds = 2.0f * a * cos(ang - half_arc) * sin(half_arc);
  float height = z1 - z0, w = x1 - x0, l = y1 - y0;
  float phase = gr_pa_unit(gr_pa_stream(base, GR_PA_STREAM_PHASE));
  float depth;
  int life = gr_pa_life(phase, v - wind_z, t, height, 1.0f / height, &depth);
  float sx = gr_pa_unit(gr_pa_life_stream(base, life, GR_PA_STREAM_X)) * w;
  float sy = gr_pa_unit(gr_pa_life_stream(base, life, GR_PA_STREAM_Y)) * l;
  float vz = wind_z - v;
  vstore3((float3)(gr_pa_wrap(sx + shift_x + sway * dir_x, x0, x1, w),
                   gr_pa_wrap(sy + shift_y + sway * dir_y, y0, y1, l), fmax(z1 - depth, z0)),
          i, position);
  vstore3((float3)(wind_x + sway_v * dir_x, wind_y + sway_v * dir_y, vz), i, velocity);
  size[i] = d;
  vstore3((float3)(wind_x * exposure + ds * dir_x, wind_y * exposure + ds * dir_y, vz * exposure),
          i, streak);
}
