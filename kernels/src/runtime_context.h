/* Private to the runtime's files (runtime.c, runtime_programs.c): what a
 * gr_context holds, its program cache and its cache of kernel argument
 * names. The cores see a context only through cl_runtime.h. */
#ifndef GRAUPEL_RUNTIME_CONTEXT_H
#define GRAUPEL_RUNTIME_CONTEXT_H

#include "graupel/cl_runtime.h"

#include <pthread.h>

/* Kernels whose argument names a context remembers; beyond this the oldest
 * entry is reused, so a long session that creates kernels without end keeps
 * a fixed amount of memory. */
#define GR_ARG_CACHE 64
/* Buffers from this size on are checked against the memory the process can
 * get (two /proc reads); smaller ones cannot matter. */
#define GR_BUFFER_CHECKED ((size_t)1 << 20)

typedef struct gr_program_entry {
  char *key; /* name + '\n' + options */
  cl_program program;
} gr_program_entry;

/* The argument names of one kernel, in index order. An entry is only a hint:
 * a released kernel's handle may come back for another kernel, so a hit is
 * confirmed by asking the kernel for the name at the cached index. */
typedef struct gr_arg_entry {
  cl_kernel kernel;
  cl_uint nargs;
  char **names; /* nargs strings in one allocation after the pointers */
} gr_arg_entry;

struct gr_context {
  int refcount; /* guarded by gr_shared_lock */
  int shared;
  cl_platform_id platform;
  cl_device_id device;
  cl_context cl;
  cl_command_queue queue;
  char device_name[128];
  char platform_name[128];
  int is_gpu;
  int host_memory; /* the device's buffers are host memory (gr_device_info) */
  cl_ulong max_alloc, global_mem;
  size_t local2d[2]; /* default work-group shape for 2-D kernels */
  gr_log_fn log;
  void *log_user;
  pthread_mutex_t lock;       /* guards programs and the argument cache */
  gr_program_entry *programs; /* grows: one entry per (source, options) */
  int nprograms, capacity;
  gr_arg_entry args[GR_ARG_CACHE];
  int next_arg; /* the entry replaced when the cache is full */
};

#endif
