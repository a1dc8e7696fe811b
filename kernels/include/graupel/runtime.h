/**
 * @file runtime.h
 * @brief OpenCL device choice and the (shared) Graupel context.
 *
 * A context owns one OpenCL device, its queue and the programs built for it.
 * Filters share one context per device through gr_context_acquire (reference
 * counted); a benchmark or test may create a private one.
 */
#ifndef GRAUPEL_RUNTIME_H
#define GRAUPEL_RUNTIME_H

#include "graupel/graupel.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct gr_context gr_context;

/** Severity of a log line. */
typedef enum gr_log_level { GR_LOG_INFO = 0, GR_LOG_WARNING = 1 } gr_log_level;
/** The core never prints; it reports through this optional callback. */
typedef void (*gr_log_fn)(void *user, gr_log_level level, const char *message);

typedef struct gr_context_options {
  /**
   * Which device: "gpu", "cpu", a case-insensitive substring of the device
   * or platform name, or NULL / "" / "auto" for the default. When NULL or
   * "auto", the environment variable GRAUPEL_DEVICE is read; failing that the
   * first GPU is taken, else the first CPU device, else any device. A
   * ":N" ending ("gpu:1", "auto:1", "H200:1") takes the N-th (from 0) of the
   * devices the rest would choose from, in clinfo -l's order: identical
   * GPUs share a name, so a process that drives several takes each by its
   * place.
   */
  const char *device;
  gr_log_fn log;
  void *log_user;
} gr_context_options;

/** Zeroes the options: automatic device, no log. */
GR_API void gr_context_options_init(gr_context_options *opt);

/** Creates a private context (reference count 1). */
GR_API gr_status gr_context_create(const gr_context_options *opt, gr_context **out);

/**
 * Returns the process-wide context for the device the options select,
 * creating it on first use, with its reference count raised. Thread safe.
 * The log callback of the call that created it is kept.
 */
GR_API gr_status gr_context_acquire(const gr_context_options *opt, gr_context **out);

/** Adds a reference. */
GR_API gr_context *gr_context_retain(gr_context *ctx);
/** Drops a reference; the last one frees everything. NULL is fine. */
GR_API void gr_context_release(gr_context *ctx);
/** Current reference count (for tests). */
GR_API int gr_context_refcount(const gr_context *ctx);

/**
 * Detail of the calling thread's latest error: the OpenCL error name, the
 * build log, the limit exceeded. The text is per thread, whatever ctx is (ctx
 * is kept for compatibility; NULL is fine), so that handles sharing one
 * context never see each other's messages: a handle's own latest error comes
 * from its core's gr_<core>_last_error. Never NULL; "" when there was none.
 */
GR_API const char *gr_last_error(const gr_context *ctx);

/** Name of the device this context runs on, e.g. "NVIDIA H100 80GB HBM3". */
GR_API const char *gr_context_device_name(const gr_context *ctx);
/** Platform name, e.g. "Portable Computing Language". */
GR_API const char *gr_context_platform_name(const gr_context *ctx);
/** 1 when the context's device is a GPU. */
GR_API int gr_context_is_gpu(const gr_context *ctx);

typedef struct gr_device_info {
  char name[128];
  char vendor[128];
  char platform[128];
  char version[128];
  int is_gpu, is_cpu;
  int compute_units;
  unsigned long long global_mem_bytes;
  unsigned long long max_alloc_bytes;
  /** 1 when its buffers are host memory (a CPU device, or CL_DEVICE_HOST_UNIFIED_MEMORY). */
  int host_memory;
} gr_device_info;

/**
 * Lists the OpenCL devices of every platform. Fills at most max entries and
 * stores the total number in *count (so max = 0 asks for the count only).
 */
GR_API gr_status gr_device_list(gr_device_info *infos, int max, int *count);

/** The device behind a context. */
GR_API gr_status gr_context_device_info(const gr_context *ctx, gr_device_info *info);

#ifdef __cplusplus
}
#endif

#endif
