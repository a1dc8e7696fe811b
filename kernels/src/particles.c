/* Rain and snowfall particles (seeds 004 and 001): host side of particles.cl. */
#include "graupel/particles.h"
#include "graupel/cl_runtime.h"
#include "particles_shared.h"
#include "runtime_internal.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct gr_particles {
  gr_context *ctx;
  gr_particles_params params;
  cl_kernel rain, snow;
  cl_mem out[GR_PARTICLES_OUTPUT_COUNT];
  int allocated; /* particles the buffers hold */
  int computed;  /* 1 once the outputs hold the current parameters' particles */
  char error[1024];
};

/* The rows of the parameter table, in the order of the sources' properties. */
enum { GR_PA_COUNT, GR_PA_RAIN_RATE, GR_PA_EXPOSURE_TIME, GR_PA_SEED, GR_PA_FLUTTER, GR_PA_ROWS };

/* The one place the ranges are written. Count: the seed's slider spans
 * 2^10 .. 2^20 and its benchmark 2^24 (seed 004); the default
 * is the seed's 2^17. RainRate: Marshall-Palmer's Lambda needs a rate above
 * 0; 500 mm/h is beyond the heaviest cloudburst recorded for an hour.
 * ExposureTime 1/50 s, a film camera's (the seed's streaks stand for
 * motion blur). FlutterAmplitude: the sway of a flake, up to 10 m for
 * storm-blown snow. */
static const gr_param_bound gr_pa_bounds[GR_PA_ROWS] = {
    {"Count", "", 1024.0, 16777216.0, 131072.0, 1.0, 0, 1},
    {"RainRate", "mm/h", 0.0, 500.0, 10.0, 1.0 / 3.6e6, 1, 0},
    {"ExposureTime", "s", 0.0, 10.0, 0.02, 1.0, 0, 0},
    {"Seed", "", (double)INT_MIN, (double)INT_MAX, 0.0, 1.0, 0, 1},
    {"FlutterAmplitude", "m", 0.0, 10.0, 0.3, 1.0, 0, 0},
};

static const char *const gr_pa_names[2][GR_PARTICLES_OUTPUT_COUNT] = {
    {"position", "velocity", "diameter", "streak"}, {"position", "velocity", "size", "streak"}};

int gr_particles_output_components(gr_particles_output o) {
  if ((int)o < 0 || o >= GR_PARTICLES_OUTPUT_COUNT)
    return 0;
  return o == GR_PARTICLES_SIZE ? 1 : 3;
}

const char *gr_particles_output_name(gr_particles_kind kind, gr_particles_output o) {
  if ((kind != GR_PARTICLES_RAIN && kind != GR_PARTICLES_SNOW) || (int)o < 0 ||
      o >= GR_PARTICLES_OUTPUT_COUNT)
    return NULL;
  return gr_pa_names[kind][o];
}

const gr_param_bound *gr_particles_param_bounds(int *count) {
  if (count)
    *count = GR_PA_ROWS;
  return gr_pa_bounds;
}

double gr_particles_marshall_palmer_lambda(double rain_rate_mm_h) {
  return GR_PA_MP_A * pow(rain_rate_mm_h, GR_PA_MP_B);
}

double gr_particles_mean_diameter(double rain_rate_mm_h) {
  double lambda = gr_particles_marshall_palmer_lambda(rain_rate_mm_h);
  double span = GR_PA_DROP_MAX_MM - GR_PA_DROP_MIN_MM, e = exp(-lambda * span);
  return GR_PA_DROP_MIN_MM + 1.0 / lambda - span * e / (1.0 - e);
}

double gr_particles_rain_fall_speed(double diameter_mm) {
  return fmax(GR_PA_ATLAS_A - GR_PA_ATLAS_B * exp(-GR_PA_ATLAS_C * diameter_mm), 0.0);
}

static double gr_pa_get(const gr_particles_params *p, int row) {
  switch (row) {
  case GR_PA_COUNT:
    return p->count;
  case GR_PA_RAIN_RATE:
    return p->rain_rate;
  case GR_PA_EXPOSURE_TIME:
    return p->exposure_time;
  case GR_PA_SEED:
    return p->seed;
  default:
    return p->flutter_amplitude;
  }
}

void gr_particles_params_init(gr_particles_params *p) {
  if (!p)
    return;
  memset(p, 0, sizeof(*p));
  const gr_param_bound *b = gr_pa_bounds;
  p->kind = GR_PARTICLES_RAIN;
  p->count = (int)b[GR_PA_COUNT].default_value;
  p->rain_rate = b[GR_PA_RAIN_RATE].default_value * b[GR_PA_RAIN_RATE].to_core;
  p->exposure_time = b[GR_PA_EXPOSURE_TIME].default_value;
  p->seed = (int)b[GR_PA_SEED].default_value;
  p->flutter_amplitude = b[GR_PA_FLUTTER].default_value;
  const double region[6] = {0.0, 100.0, 0.0, 100.0, 0.0, 50.0};
  memcpy(p->region, region, sizeof(region));
}

gr_status gr_particles_params_validate(const gr_particles_params *p, char *msg, size_t msg_len) {
  char scratch[8];
  if (!msg || !msg_len) {
    msg = scratch;
    msg_len = sizeof(scratch);
  }
  const char *what = "Invalid particle parameters";
  if (!p)
    return gr_params_missing(what, msg, msg_len);
  if (p->kind != GR_PARTICLES_RAIN && p->kind != GR_PARTICLES_SNOW) {
    snprintf(msg, msg_len,
             "Invalid particle parameters: the kind is %d but must be 0 (rain) or 1 (snow).",
             p->kind);
    return GR_ERR_INVALID_ARGUMENT;
  }
  double values[GR_PA_ROWS];
  for (int row = 0; row < GR_PA_ROWS; ++row)
    values[row] = gr_pa_get(p, row);
  if (gr_params_check_table(gr_pa_bounds, NULL, GR_PA_ROWS, values, what, NULL, GR_PARAM_SAY_GOT,
                            msg, msg_len) != GR_OK)
    return GR_ERR_INVALID_ARGUMENT;
  static const char axis[3] = {'x', 'y', 'z'};
  for (int c = 0; c < 3; ++c)
    if (!(fabs(p->wind[c]) <= GR_PARTICLES_MAX_WIND)) {
      snprintf(msg, msg_len,
               "Invalid particle parameters: the wind's %c component is %g m/s but must lie "
               "between %g and %g m/s.",
               axis[c], p->wind[c], -GR_PARTICLES_MAX_WIND, GR_PARTICLES_MAX_WIND);
      return GR_ERR_INVALID_ARGUMENT;
    }
  for (int c = 0; c < 3; ++c) {
    double lo = p->region[2 * c], hi = p->region[2 * c + 1];
    /* The box's size in float must be above 0 too: the kernel divides by it. */
    if (!(isfinite(lo) && isfinite(hi) && hi > lo && (float)hi - (float)lo > 0.0f &&
          fabs(lo) < 1e9 && fabs(hi) < 1e9)) {
      snprintf(msg, msg_len,
               "Invalid particle parameters: the region spans %g to %g m along %c, which has no "
               "size: give a %cmax above %cmin (finite, within 1e9 m).",
               lo, hi, axis[c], axis[c], axis[c]);
      return GR_ERR_INVALID_ARGUMENT;
    }
  }
  return GR_OK;
}

static void gr_pa_release_buffers(gr_particles *s) {
  for (int o = 0; o < GR_PARTICLES_OUTPUT_COUNT; ++o)
    gr_buffer_release(&s->out[o]);
  s->allocated = 0;
}

void gr_particles_destroy(gr_particles *s) {
  if (!s)
    return;
  if (s->rain)
    clReleaseKernel(s->rain);
  if (s->snow)
    clReleaseKernel(s->snow);
  gr_pa_release_buffers(s);
  gr_context_release(s->ctx);
  free(s);
}

static gr_status gr_pa_allocate(gr_particles *s, int count) {
  gr_pa_release_buffers(s);
  gr_status st = GR_OK;
  for (int o = 0; st == GR_OK && o < GR_PARTICLES_OUTPUT_COUNT; ++o)
    st = gr_buffer_create(s->ctx, CL_MEM_READ_WRITE,
                          (size_t)count * (size_t)gr_particles_output_components(o) * sizeof(float),
                          NULL, &s->out[o]);
  if (st == GR_OK)
    s->allocated = count;
  else
    gr_pa_release_buffers(s);
  return st;
}

gr_status gr_particles_memory(const gr_particles_params *p, gr_memory_need *out) {
  if (!p || !out)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_particles_memory needs parameters and a place for the answer.");
  memset(out, 0, sizeof(*out));
  out->points = p->count > 0 ? (double)p->count : 0.0;
  for (int o = 0; o < GR_PARTICLES_OUTPUT_COUNT; ++o) {
    double bytes = out->points * gr_particles_output_components(o) * sizeof(float);
    out->device += bytes; /* gr_pa_allocate */
    out->largest = bytes > out->largest ? bytes : out->largest;
  }
  return GR_OK;
}

gr_status gr_particles_create(gr_context *ctx, const gr_particles_params *p, gr_particles **out) {
  char msg[256];
  if (!ctx || !out)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_particles_create needs a context and a place for the particles.");
  *out = NULL;
  if (gr_particles_params_validate(p, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg);
  gr_memory_need need;
  gr_particles_memory(p, &need);
  if (gr_memory_check(ctx, &need, msg, sizeof(msg)) != GR_OK)
    return gr_set_error(ctx, GR_ERR_TOO_LARGE, "A set of %d particles %s: lower Count.", p->count,
                        msg);
  gr_particles *s = calloc(1, sizeof(*s));
  if (!s)
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  s->ctx = gr_context_retain(ctx);
  s->params = *p;
  cl_program prog = NULL;
  gr_status st = gr_program_get(ctx, "particles", "", &prog);
  if (st == GR_OK)
    st = gr_kernel_create(ctx, prog, "particles_rain", &s->rain);
  if (st == GR_OK)
    st = gr_kernel_create(ctx, prog, "particles_snow", &s->snow);
  if (st == GR_OK)
    st = gr_pa_allocate(s, p->count);
  if (st != GR_OK) {
    gr_particles_destroy(s);
    return st;
  }
  *out = s;
  return GR_OK;
}

gr_status gr_particles_set_params(gr_particles *s, const gr_particles_params *p) {
  char msg[256];
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT, "gr_particles_set_params needs particles.");
  if (gr_particles_params_validate(p, msg, sizeof(msg)) != GR_OK)
    return gr_error_keep(s->error, sizeof(s->error),
                         gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT, "%s", msg));
  s->computed = 0;
  if (p->count != s->allocated) {
    gr_status st = gr_pa_allocate(s, p->count);
    if (st != GR_OK) {
      /* Back to the old count, so the handle stays usable. */
      gr_status back = gr_pa_allocate(s, s->params.count);
      (void)back;
      return gr_error_keep(s->error, sizeof(s->error), st);
    }
  }
  s->params = *p;
  return GR_OK;
}

int gr_particles_count(const gr_particles *s) {
  return s ? s->params.count : 0;
}

gr_status gr_particles_compute(gr_particles *s, double time) {
  if (!s)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT, "gr_particles_compute needs particles.");
  if (!isfinite(time) || fabs(time) > 1e9)
    return gr_error_keep(s->error, sizeof(s->error),
                         gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "The particles' time is %g s but must be a finite number "
                                      "of seconds within 1e9.",
                                      time));
  if (s->allocated != s->params.count)
    return gr_error_keep(s->error, sizeof(s->error),
                         gr_set_error(s->ctx, GR_ERR_OUT_OF_MEMORY,
                                      "The particles have no buffers for %d particles (an "
                                      "earlier allocation failed): set a smaller Count.",
                                      s->params.count));
  const gr_particles_params *p = &s->params;
  gr_context *ctx = s->ctx;
  int rain = p->kind == GR_PARTICLES_RAIN;
  cl_kernel k = rain ? s->rain : s->snow;
  cl_int n = p->count;
  cl_uint seed = (cl_uint)p->seed;
  cl_float t = (cl_float)time, exposure = (cl_float)p->exposure_time;
  cl_float x0 = (cl_float)p->region[0], x1 = (cl_float)p->region[1];
  cl_float y0 = (cl_float)p->region[2], y1 = (cl_float)p->region[3];
  cl_float z0 = (cl_float)p->region[4], z1 = (cl_float)p->region[5];
  cl_float wind_x = (cl_float)p->wind[0], wind_y = (cl_float)p->wind[1];
  cl_float wind_z = (cl_float)p->wind[2];
  cl_mem position = s->out[GR_PARTICLES_POSITION], velocity = s->out[GR_PARTICLES_VELOCITY];
  cl_mem size = s->out[GR_PARTICLES_SIZE], streak = s->out[GR_PARTICLES_STREAK];
  gr_status st = GR_KERNEL_ARG(ctx, k, n);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, seed);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, t);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, x0);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, x1);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, y0);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, y1);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, z0);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, z1);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, wind_x);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, wind_y);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, wind_z);
  /* The wind's drift modulo the box, in double: any time keeps its
   * fraction of the box. */
  cl_float shift_x = (cl_float)fmod(p->wind[0] * time, p->region[1] - p->region[0]);
  cl_float shift_y = (cl_float)fmod(p->wind[1] * time, p->region[3] - p->region[2]);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, shift_x);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, shift_y);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, exposure);
  if (rain) {
    /* Lambda from the rate in mm/h; the truncation's CDF scale in double,
     * sent as floats. */
    double lambda = gr_particles_marshall_palmer_lambda(p->rain_rate * 3.6e6);
    cl_float d_min = (cl_float)GR_PA_DROP_MIN_MM, inv_lambda = (cl_float)(1.0 / lambda);
    cl_float cdf_scale = (cl_float)(-expm1(-lambda * (GR_PA_DROP_MAX_MM - GR_PA_DROP_MIN_MM)));
    if (st == GR_OK)
      st = GR_KERNEL_ARG(ctx, k, d_min);
    if (st == GR_OK)
      st = GR_KERNEL_ARG(ctx, k, inv_lambda);
    if (st == GR_OK)
      st = GR_KERNEL_ARG(ctx, k, cdf_scale);
  } else {
    cl_float amplitude = (cl_float)p->flutter_amplitude;
    if (st == GR_OK)
      st = GR_KERNEL_ARG(ctx, k, amplitude);
  }
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, position);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, velocity);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, size);
  if (st == GR_OK)
    st = GR_KERNEL_ARG(ctx, k, streak);
  if (st == GR_OK)
    st = gr_enqueue_1d(ctx, k, (size_t)n);
  s->computed = st == GR_OK;
  return gr_error_keep(s->error, sizeof(s->error), st);
}

gr_status gr_particles_get_output(gr_particles *s, gr_particles_output o, float *host) {
  if (!s || !host) {
    gr_status st = gr_set_error(s ? s->ctx : NULL, GR_ERR_INVALID_ARGUMENT,
                                "gr_particles_get_output needs particles and room for the output.");
    return s ? gr_error_keep(s->error, sizeof(s->error), st) : st;
  }
  int comps = gr_particles_output_components(o);
  if (!comps)
    return gr_error_keep(s->error, sizeof(s->error),
                         gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "The particles have no output number %d.", (int)o));
  if (!s->computed)
    return gr_error_keep(s->error, sizeof(s->error),
                         gr_set_error(s->ctx, GR_ERR_INVALID_ARGUMENT,
                                      "The particles have not been computed for the current "
                                      "parameters; call gr_particles_compute first."));
  return gr_error_keep(s->error, sizeof(s->error),
                       gr_buffer_read(s->ctx, s->out[o], 0,
                                      (size_t)s->params.count * (size_t)comps * sizeof(float),
                                      host));
}

const char *gr_particles_last_error(const gr_particles *s) {
  return s ? s->error : gr_last_error(NULL);
}
