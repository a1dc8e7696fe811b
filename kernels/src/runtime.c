/* OpenCL runtime of the Graupel core: status and field names, error
 * reporting, device choice and the shared contexts. The checks of callers'
 * inputs are in runtime_checks.c, programs, kernels and buffers in
 * runtime_programs.c. */
#include "graupel/cl_runtime.h"
#include "graupel/memory.h"
#include "runtime_context.h"

#include <ctype.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define GR_ERROR_LEN 16384
#define GR_MAX_SHARED 8

/* The only global mutable state: the table of shared contexts (one per
 * device), and the per-thread text of the latest error. Error text is per
 * thread, not per context, because filters share one context: a handle keeps
 * its own copy with gr_error_keep. */
static pthread_mutex_t gr_shared_lock = PTHREAD_MUTEX_INITIALIZER;
static gr_context *gr_shared[GR_MAX_SHARED];
static _Thread_local char gr_thread_error[GR_ERROR_LEN];

const char *gr_status_string(gr_status st) {
  switch (st) {
  case GR_OK:
    return "GR_OK";
  case GR_ERR_INVALID_ARGUMENT:
    return "GR_ERR_INVALID_ARGUMENT";
  case GR_ERR_NO_PLATFORM:
    return "GR_ERR_NO_PLATFORM";
  case GR_ERR_NO_DEVICE:
    return "GR_ERR_NO_DEVICE";
  case GR_ERR_OPENCL:
    return "GR_ERR_OPENCL";
  case GR_ERR_BUILD:
    return "GR_ERR_BUILD";
  case GR_ERR_OUT_OF_MEMORY:
    return "GR_ERR_OUT_OF_MEMORY";
  case GR_ERR_TOO_LARGE:
    return "GR_ERR_TOO_LARGE";
  case GR_ERR_IO:
    return "GR_ERR_IO";
  case GR_ERR_FORMAT:
    return "GR_ERR_FORMAT";
  case GR_ERR_ABORTED:
    return "GR_ERR_ABORTED";
  }
  return "GR_ERR_UNKNOWN";
}

const char *gr_version_string(void) {
#define GR_STR2(x) #x
#define GR_STR(x) GR_STR2(x)
  return GR_STR(GRAUPEL_VERSION_MAJOR) "." GR_STR(GRAUPEL_VERSION_MINOR) "." GR_STR(
      GRAUPEL_VERSION_PATCH);
}

/* The field vocabulary: array name, components and SI unit of every
 * gr_field, in enum order. VTK arrays, EXR channels and the docs pages use these
 * names and units; "1" is dimensionless. */
static const struct gr_field_row {
  gr_field field; /* checked against the row's index by the tests */
  const char *name;
  int components;
  const char *unit;
} gr_fields[GR_FIELD_COUNT] = {
    {GR_FIELD_ELEVATION, "elevation", 1, "m"},
    {GR_FIELD_SNOW_DEPTH, "snow_depth", 1, "m"},
    {GR_FIELD_SNOW_DENSITY, "snow_density", 1, "kg/m^3"},
    {GR_FIELD_SNOW_SURFACE, "snow_surface", 1, "m"},
    {GR_FIELD_OVERLAP, "overlap", 1, "m"},
    {GR_FIELD_EXPOSURE, "exposure", 1, "1"},
    {GR_FIELD_WATER_DEPTH, "water_depth", 1, "m"},
    {GR_FIELD_WATER_SURFACE, "water_surface", 1, "m"},
    {GR_FIELD_VELOCITY, "velocity", 3, "m/s"},
    {GR_FIELD_DISCHARGE, "discharge", 1, "m^2/s"},
    {GR_FIELD_INFILTRATED, "infiltrated", 1, "m"},
    {GR_FIELD_PERMEABILITY, "permeability", 1, "m/s"},
    {GR_FIELD_RAIN_RATE, "rain_rate", 1, "m/s"},
    {GR_FIELD_CONTACT, "contact", 1, "1"},
};

static const struct gr_field_row *gr_field_row_of(gr_field f) {
  return ((int)f >= 0 && (int)f < GR_FIELD_COUNT) ? &gr_fields[f] : NULL;
}

const char *gr_field_name(gr_field f) {
  const struct gr_field_row *r = gr_field_row_of(f);
  return r ? r->name : NULL;
}

int gr_field_from_name(const char *name) {
  if (!name)
    return -1;
  for (int i = 0; i < GR_FIELD_COUNT; ++i)
    if (strcmp(name, gr_fields[i].name) == 0)
      return (int)gr_fields[i].field;
  return -1;
}

int gr_field_components(gr_field f) {
  const struct gr_field_row *r = gr_field_row_of(f);
  return r ? r->components : 0;
}

const char *gr_field_unit(gr_field f) {
  const struct gr_field_row *r = gr_field_row_of(f);
  return r ? r->unit : NULL;
}

/* ------------------------------------------------------------------ errors */

static void gr_log(const gr_context *ctx, gr_log_level level, const char *msg) {
  if (ctx && ctx->log)
    ctx->log(ctx->log_user, level, msg);
}

gr_status gr_set_error(const gr_context *ctx, gr_status st, const char *fmt, ...) {
  /* Formatted aside first: callers may pass the current error as an argument
   * ("%s", gr_last_error(ctx)) to add context to it. */
  static _Thread_local char scratch[GR_ERROR_LEN];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(scratch, sizeof(scratch), fmt, ap);
  va_end(ap);
  memcpy(gr_thread_error, scratch, sizeof(gr_thread_error));
  /* Not logged as well: the caller gets the status and reports the sentence
   * once (a filter as its one error); the log is for what is not an error. */
  (void)ctx;
  return st;
}

gr_status gr_error_keep(char *dst, size_t len, gr_status st) {
  if (st != GR_OK && dst && len > 0 && dst != gr_thread_error)
    snprintf(dst, len, "%s", gr_thread_error);
  return st;
}

const char *gr_last_error(const gr_context *ctx) {
  (void)ctx; /* kept for compatibility: the text is the calling thread's */
  return gr_thread_error;
}

const char *gr_cl_error_name(cl_int err) {
  switch (err) {
#define GR_CASE(e)                                                                                 \
  case e:                                                                                          \
    return #e;
    GR_CASE(CL_SUCCESS)
    GR_CASE(CL_DEVICE_NOT_FOUND)
    GR_CASE(CL_DEVICE_NOT_AVAILABLE)
    GR_CASE(CL_COMPILER_NOT_AVAILABLE)
    GR_CASE(CL_MEM_OBJECT_ALLOCATION_FAILURE)
    GR_CASE(CL_OUT_OF_RESOURCES)
    GR_CASE(CL_OUT_OF_HOST_MEMORY)
    GR_CASE(CL_PROFILING_INFO_NOT_AVAILABLE)
    GR_CASE(CL_MEM_COPY_OVERLAP)
    GR_CASE(CL_IMAGE_FORMAT_MISMATCH)
    GR_CASE(CL_IMAGE_FORMAT_NOT_SUPPORTED)
    GR_CASE(CL_BUILD_PROGRAM_FAILURE)
    GR_CASE(CL_MAP_FAILURE)
    GR_CASE(CL_MISALIGNED_SUB_BUFFER_OFFSET)
    GR_CASE(CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST)
    GR_CASE(CL_COMPILE_PROGRAM_FAILURE)
    GR_CASE(CL_LINKER_NOT_AVAILABLE)
    GR_CASE(CL_LINK_PROGRAM_FAILURE)
    GR_CASE(CL_DEVICE_PARTITION_FAILED)
    GR_CASE(CL_KERNEL_ARG_INFO_NOT_AVAILABLE)
    GR_CASE(CL_INVALID_VALUE)
    GR_CASE(CL_INVALID_DEVICE_TYPE)
    GR_CASE(CL_INVALID_PLATFORM)
    GR_CASE(CL_INVALID_DEVICE)
    GR_CASE(CL_INVALID_CONTEXT)
    GR_CASE(CL_INVALID_QUEUE_PROPERTIES)
    GR_CASE(CL_INVALID_COMMAND_QUEUE)
    GR_CASE(CL_INVALID_HOST_PTR)
    GR_CASE(CL_INVALID_MEM_OBJECT)
    GR_CASE(CL_INVALID_IMAGE_FORMAT_DESCRIPTOR)
    GR_CASE(CL_INVALID_IMAGE_SIZE)
    GR_CASE(CL_INVALID_SAMPLER)
    GR_CASE(CL_INVALID_BINARY)
    GR_CASE(CL_INVALID_BUILD_OPTIONS)
    GR_CASE(CL_INVALID_PROGRAM)
    GR_CASE(CL_INVALID_PROGRAM_EXECUTABLE)
    GR_CASE(CL_INVALID_KERNEL_NAME)
    GR_CASE(CL_INVALID_KERNEL_DEFINITION)
    GR_CASE(CL_INVALID_KERNEL)
    GR_CASE(CL_INVALID_ARG_INDEX)
    GR_CASE(CL_INVALID_ARG_VALUE)
    GR_CASE(CL_INVALID_ARG_SIZE)
    GR_CASE(CL_INVALID_KERNEL_ARGS)
    GR_CASE(CL_INVALID_WORK_DIMENSION)
    GR_CASE(CL_INVALID_WORK_GROUP_SIZE)
    GR_CASE(CL_INVALID_WORK_ITEM_SIZE)
    GR_CASE(CL_INVALID_GLOBAL_OFFSET)
    GR_CASE(CL_INVALID_EVENT_WAIT_LIST)
    GR_CASE(CL_INVALID_EVENT)
    GR_CASE(CL_INVALID_OPERATION)
    GR_CASE(CL_INVALID_GL_OBJECT)
    GR_CASE(CL_INVALID_BUFFER_SIZE)
    GR_CASE(CL_INVALID_MIP_LEVEL)
    GR_CASE(CL_INVALID_GLOBAL_WORK_SIZE)
    GR_CASE(CL_INVALID_PROPERTY)
#undef GR_CASE
  case -1001:
    return "CL_PLATFORM_NOT_FOUND_KHR";
  }
  return "an unknown OpenCL error";
}

gr_status gr_cl_check(const gr_context *ctx, cl_int err, const char *what) {
  if (err == CL_SUCCESS)
    return GR_OK;
  gr_status st = (err == CL_MEM_OBJECT_ALLOCATION_FAILURE || err == CL_OUT_OF_HOST_MEMORY ||
                  err == CL_OUT_OF_RESOURCES)
                     ? GR_ERR_OUT_OF_MEMORY
                     : GR_ERR_OPENCL;
  return gr_set_error(ctx, st, "%s failed: %s (%d).", what, gr_cl_error_name(err), (int)err);
}

/* ----------------------------------------------------------------- devices */

static void gr_device_string(cl_device_id d, cl_device_info what, char *buf, size_t len) {
  buf[0] = '\0';
  if (clGetDeviceInfo(d, what, len, buf, NULL) != CL_SUCCESS)
    buf[0] = '\0';
  buf[len - 1] = '\0';
}

static void gr_fill_device_info(cl_platform_id p, cl_device_id d, gr_device_info *info) {
  cl_device_type type = 0;
  cl_uint cu = 0;
  cl_ulong mem = 0, alloc = 0;
  memset(info, 0, sizeof(*info));
  gr_device_string(d, CL_DEVICE_NAME, info->name, sizeof(info->name));
  gr_device_string(d, CL_DEVICE_VENDOR, info->vendor, sizeof(info->vendor));
  gr_device_string(d, CL_DEVICE_VERSION, info->version, sizeof(info->version));
  if (clGetPlatformInfo(p, CL_PLATFORM_NAME, sizeof(info->platform), info->platform, NULL) !=
      CL_SUCCESS)
    info->platform[0] = '\0';
  info->platform[sizeof(info->platform) - 1] = '\0';
  clGetDeviceInfo(d, CL_DEVICE_TYPE, sizeof(type), &type, NULL);
  clGetDeviceInfo(d, CL_DEVICE_MAX_COMPUTE_UNITS, sizeof(cu), &cu, NULL);
  clGetDeviceInfo(d, CL_DEVICE_GLOBAL_MEM_SIZE, sizeof(mem), &mem, NULL);
  clGetDeviceInfo(d, CL_DEVICE_MAX_MEM_ALLOC_SIZE, sizeof(alloc), &alloc, NULL);
  info->is_gpu = (type & CL_DEVICE_TYPE_GPU) != 0;
  info->is_cpu = (type & CL_DEVICE_TYPE_CPU) != 0;
  info->compute_units = (int)cu;
  info->global_mem_bytes = mem;
  info->max_alloc_bytes = alloc;
  cl_bool unified = CL_FALSE;
  if (clGetDeviceInfo(d, CL_DEVICE_HOST_UNIFIED_MEMORY, sizeof(unified), &unified, NULL) !=
      CL_SUCCESS)
    unified = CL_FALSE;
  info->host_memory = info->is_cpu || unified == CL_TRUE;
}

/* Visits every device of every platform; stops when visit returns nonzero. */
typedef int (*gr_device_visit)(void *user, cl_platform_id p, cl_device_id d);

static gr_status gr_for_each_device(gr_device_visit visit, void *user) {
  cl_uint np = 0;
  cl_int err = clGetPlatformIDs(0, NULL, &np);
  if (err == -1001 /* CL_PLATFORM_NOT_FOUND_KHR */ || (err == CL_SUCCESS && np == 0))
    return gr_set_error(NULL, GR_ERR_NO_PLATFORM,
                        "No OpenCL platform is installed: install an OpenCL "
                        "driver (for the CPU, Debian's pocl-opencl-icd) and "
                        "check that /etc/OpenCL/vendors lists it.");
  if (err != CL_SUCCESS)
    return gr_cl_check(NULL, err, "Listing the OpenCL platforms");
  cl_platform_id plats[16];
  if (np > 16)
    np = 16;
  err = clGetPlatformIDs(np, plats, NULL);
  if (err != CL_SUCCESS)
    return gr_cl_check(NULL, err, "Listing the OpenCL platforms");
  for (cl_uint p = 0; p < np; ++p) {
    cl_uint nd = 0;
    if (clGetDeviceIDs(plats[p], CL_DEVICE_TYPE_ALL, 0, NULL, &nd) != CL_SUCCESS || nd == 0)
      continue;
    cl_device_id devs[32];
    if (nd > 32)
      nd = 32;
    if (clGetDeviceIDs(plats[p], CL_DEVICE_TYPE_ALL, nd, devs, NULL) != CL_SUCCESS)
      continue;
    for (cl_uint d = 0; d < nd; ++d)
      if (visit(user, plats[p], devs[d]))
        return GR_OK;
  }
  return GR_OK;
}

typedef struct gr_list_state {
  gr_device_info *infos;
  int max, count;
} gr_list_state;

static int gr_list_visit(void *user, cl_platform_id p, cl_device_id d) {
  gr_list_state *s = user;
  if (s->count < s->max)
    gr_fill_device_info(p, d, &s->infos[s->count]);
  s->count++;
  return 0;
}

gr_status gr_device_list(gr_device_info *infos, int max, int *count) {
  if (!count || max < 0 || (max > 0 && !infos))
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_device_list needs a count pointer and room for "
                        "max entries.");
  gr_list_state s = {infos, max, 0};
  gr_status st = gr_for_each_device(gr_list_visit, &s);
  *count = s.count;
  return st;
}

/* Device choice: the request is "gpu", "cpu", "auto" or a name substring,
 * optionally with ":N", the N-th (from 0) device that the request matches in
 * the order clinfo -l lists them: several identical GPUs have one name, and
 * a process that drives them all (graupel-bench --devices, one MPI rank per
 * GPU) needs each by its place. */
typedef struct gr_pick_state {
  const char *want; /* normalised request */
  int nth;          /* the ":N" of the request; 0 without one */
  int gpus, cpus, matches, anys;
  cl_platform_id first_gpu_p, first_cpu_p, first_any_p, match_p;
  cl_device_id first_gpu, first_cpu, first_any, match;
} gr_pick_state;

static int gr_contains_nocase(const char *hay, const char *needle) {
  size_t n = strlen(needle);
  for (; *hay; ++hay) {
    size_t i = 0;
    while (i < n && hay[i] && tolower((unsigned char)hay[i]) == tolower((unsigned char)needle[i]))
      ++i;
    if (i == n)
      return 1;
  }
  return n == 0;
}

static int gr_pick_visit(void *user, cl_platform_id p, cl_device_id d) {
  gr_pick_state *s = user;
  gr_device_info info;
  gr_fill_device_info(p, d, &info);
  if (s->anys++ == s->nth) {
    s->first_any = d;
    s->first_any_p = p;
  }
  if (info.is_gpu && s->gpus++ == s->nth) {
    s->first_gpu = d;
    s->first_gpu_p = p;
  }
  if (info.is_cpu && s->cpus++ == s->nth) {
    s->first_cpu = d;
    s->first_cpu_p = p;
  }
  if (s->want[0] &&
      (gr_contains_nocase(info.name, s->want) || gr_contains_nocase(info.platform, s->want)) &&
      s->matches++ == s->nth) {
    s->match = d;
    s->match_p = p;
  }
  return 0;
}

/* Splits "spec:N" into spec (copied to base) and N; *nth = 0 and base =
 * the whole request when there is no ":digits" ending. */
static void gr_split_request(const char *req, char *base, size_t len, int *nth) {
  *nth = 0;
  snprintf(base, len, "%s", req);
  char *colon = strrchr(base, ':');
  if (!colon || !colon[1] || strlen(colon + 1) > 6)
    return;
  for (const char *c = colon + 1; *c; ++c)
    if (!isdigit((unsigned char)*c))
      return;
  *nth = atoi(colon + 1);
  *colon = '\0';
}

static const char *gr_effective_request(const gr_context_options *opt) {
  const char *req = opt ? opt->device : NULL;
  if (!req || !req[0] || strcmp(req, "auto") == 0) {
    req = getenv("GRAUPEL_DEVICE");
    if (!req || !req[0])
      req = "auto";
  }
  return req;
}

static gr_status gr_pick_device(const gr_context_options *opt, cl_platform_id *pp,
                                cl_device_id *pd) {
  const char *full = gr_effective_request(opt);
  char req[256];
  gr_pick_state s;
  memset(&s, 0, sizeof(s));
  gr_split_request(full, req, sizeof(req), &s.nth);
  s.want = "";
  int want_gpu = strcmp(req, "gpu") == 0 || strcmp(req, "GPU") == 0;
  int want_cpu = strcmp(req, "cpu") == 0 || strcmp(req, "CPU") == 0;
  int want_auto = strcmp(req, "auto") == 0 || req[0] == '\0';
  if (!want_gpu && !want_cpu && !want_auto)
    s.want = req;
  gr_status st = gr_for_each_device(gr_pick_visit, &s);
  if (st != GR_OK)
    return st;
  if (want_gpu) {
    *pd = s.first_gpu;
    *pp = s.first_gpu_p;
  } else if (want_cpu) {
    *pd = s.first_cpu;
    *pp = s.first_cpu_p;
  } else if (want_auto) {
    /* "auto:N": the N-th GPU where there are GPUs, else the N-th CPU device. */
    int gpus = s.gpus > 0, cpus = !gpus && s.cpus > 0;
    *pd = gpus ? s.first_gpu : cpus ? s.first_cpu : s.first_any;
    *pp = gpus ? s.first_gpu_p : cpus ? s.first_cpu_p : s.first_any_p;
  } else {
    *pd = s.match;
    *pp = s.match_p;
  }
  if (!*pd)
    return gr_set_error(NULL, GR_ERR_NO_DEVICE,
                        "No OpenCL device matches the request '%s' (from %s): use 'gpu', "
                        "'cpu', 'auto' or part of a device name that clinfo -l shows, with "
                        "':N' for the N-th such device from 0.",
                        full,
                        (opt && opt->device && opt->device[0] && strcmp(opt->device, "auto"))
                            ? "the device option"
                            : "GRAUPEL_DEVICE");
  return GR_OK;
}

/* ---------------------------------------------------------------- contexts */

void gr_context_options_init(gr_context_options *opt) {
  if (opt)
    memset(opt, 0, sizeof(*opt));
}

static void gr_context_free(gr_context *ctx) {
  for (int i = 0; i < GR_ARG_CACHE; ++i)
    free(ctx->args[i].names);
  for (int i = 0; i < ctx->nprograms; ++i) {
    clReleaseProgram(ctx->programs[i].program);
    free(ctx->programs[i].key);
  }
  free(ctx->programs);
  if (ctx->queue)
    clReleaseCommandQueue(ctx->queue);
  if (ctx->cl)
    clReleaseContext(ctx->cl);
  pthread_mutex_destroy(&ctx->lock);
  free(ctx);
}

static gr_status gr_context_open(const gr_context_options *opt, cl_platform_id p, cl_device_id d,
                                 gr_context **out) {
  cl_int err = CL_SUCCESS;
  gr_context *ctx = calloc(1, sizeof(*ctx));
  if (!ctx)
    return gr_set_error(NULL, GR_ERR_OUT_OF_MEMORY, "Out of host memory while creating a context.");
  pthread_mutex_init(&ctx->lock, NULL);
  ctx->refcount = 1;
  ctx->platform = p;
  ctx->device = d;
  if (opt) {
    ctx->log = opt->log;
    ctx->log_user = opt->log_user;
  }
  gr_device_info info;
  gr_fill_device_info(p, d, &info);
  snprintf(ctx->device_name, sizeof(ctx->device_name), "%s", info.name);
  snprintf(ctx->platform_name, sizeof(ctx->platform_name), "%s", info.platform);
  ctx->is_gpu = info.is_gpu;
  ctx->host_memory = info.host_memory;
  ctx->max_alloc = info.max_alloc_bytes;
  /* A fixed work-group shape for every 2-D launch. Left to the driver, PoCL
   * picks one per global size and JIT-compiles and caches a work-group
   * function for each: slow, and memory that grows with every new grid size.
   * GPUs get square tiles, CPUs rows. */
  size_t max_wg = 0;
  clGetDeviceInfo(d, CL_DEVICE_MAX_WORK_GROUP_SIZE, sizeof(max_wg), &max_wg, NULL);
  ctx->local2d[0] = info.is_gpu ? 16 : 64;
  ctx->local2d[1] = info.is_gpu ? 16 : 1;
  while (max_wg > 0 && ctx->local2d[0] * ctx->local2d[1] > max_wg) {
    if (ctx->local2d[1] > 1)
      ctx->local2d[1] /= 2;
    else
      ctx->local2d[0] /= 2;
  }
  ctx->global_mem = info.global_mem_bytes;

  cl_context_properties props[] = {CL_CONTEXT_PLATFORM, (cl_context_properties)p, 0};
  ctx->cl = clCreateContext(props, 1, &d, NULL, NULL, &err);
  if (err != CL_SUCCESS) {
    gr_status st = gr_cl_check(NULL, err, "Creating the OpenCL context");
    gr_context_free(ctx);
    return st;
  }
  /* clCreateCommandQueue is deprecated in 2.0 but is what 1.2 devices have. */
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
#endif
  ctx->queue = clCreateCommandQueue(ctx->cl, d, 0, &err);
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
  if (err != CL_SUCCESS) {
    gr_status st = gr_cl_check(NULL, err, "Creating the OpenCL command queue");
    gr_context_free(ctx);
    return st;
  }
  char line[400];
  snprintf(line, sizeof(line), "Graupel uses OpenCL device '%s' (%s).", ctx->device_name,
           ctx->platform_name);
  gr_log(ctx, GR_LOG_INFO, line);
  *out = ctx;
  return GR_OK;
}

gr_status gr_context_create(const gr_context_options *opt, gr_context **out) {
  if (!out)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_context_create needs a place for the context.");
  *out = NULL;
  cl_platform_id p = NULL;
  cl_device_id d = NULL;
  gr_status st = gr_pick_device(opt, &p, &d);
  if (st != GR_OK)
    return st;
  return gr_context_open(opt, p, d, out);
}

gr_status gr_context_acquire(const gr_context_options *opt, gr_context **out) {
  if (!out)
    return gr_set_error(NULL, GR_ERR_INVALID_ARGUMENT,
                        "gr_context_acquire needs a place for the context.");
  *out = NULL;
  cl_platform_id p = NULL;
  cl_device_id d = NULL;
  gr_status st = gr_pick_device(opt, &p, &d);
  if (st != GR_OK)
    return st;
  pthread_mutex_lock(&gr_shared_lock);
  for (int i = 0; i < GR_MAX_SHARED; ++i)
    if (gr_shared[i] && gr_shared[i]->device == d) {
      gr_shared[i]->refcount++;
      *out = gr_shared[i];
      pthread_mutex_unlock(&gr_shared_lock);
      return GR_OK;
    }
  int slot = -1;
  for (int i = 0; i < GR_MAX_SHARED && slot < 0; ++i)
    if (!gr_shared[i])
      slot = i;
  if (slot < 0) {
    pthread_mutex_unlock(&gr_shared_lock);
    return gr_set_error(NULL, GR_ERR_TOO_LARGE, "More than %d OpenCL devices are in use at once.",
                        GR_MAX_SHARED);
  }
  st = gr_context_open(opt, p, d, out);
  if (st == GR_OK) {
    (*out)->shared = 1;
    gr_shared[slot] = *out;
  }
  pthread_mutex_unlock(&gr_shared_lock);
  return st;
}

gr_context *gr_context_retain(gr_context *ctx) {
  if (ctx) {
    pthread_mutex_lock(&gr_shared_lock);
    ctx->refcount++;
    pthread_mutex_unlock(&gr_shared_lock);
  }
  return ctx;
}

void gr_context_release(gr_context *ctx) {
  if (!ctx)
    return;
  pthread_mutex_lock(&gr_shared_lock);
  int last = --ctx->refcount == 0;
  if (last && ctx->shared)
    for (int i = 0; i < GR_MAX_SHARED; ++i)
      if (gr_shared[i] == ctx)
        gr_shared[i] = NULL;
  pthread_mutex_unlock(&gr_shared_lock);
  if (last)
    gr_context_free(ctx);
}

int gr_context_refcount(const gr_context *ctx) {
  if (!ctx)
    return 0;
  pthread_mutex_lock(&gr_shared_lock);
  int n = ctx->refcount;
  pthread_mutex_unlock(&gr_shared_lock);
  return n;
}

const char *gr_context_device_name(const gr_context *ctx) {
  return ctx ? ctx->device_name : "";
}
const char *gr_context_platform_name(const gr_context *ctx) {
  return ctx ? ctx->platform_name : "";
}
int gr_context_is_gpu(const gr_context *ctx) {
  return ctx ? ctx->is_gpu : 0;
}
cl_context gr_context_cl(const gr_context *ctx) {
  return ctx ? ctx->cl : NULL;
}
cl_command_queue gr_context_queue(const gr_context *ctx) {
  return ctx ? ctx->queue : NULL;
}
cl_device_id gr_context_device(const gr_context *ctx) {
  return ctx ? ctx->device : NULL;
}

gr_status gr_context_device_info(const gr_context *ctx, gr_device_info *info) {
  if (!ctx || !info)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_context_device_info needs a context and an info.");
  gr_fill_device_info(ctx->platform, ctx->device, info);
  return GR_OK;
}
