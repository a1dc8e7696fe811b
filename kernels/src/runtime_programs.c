/* Graupel core runtime: OpenCL programs (built once per context and options,
 * cached), kernels and their arguments by name, launches, the embedded
 * kernel sources, and device buffers. */
#include "graupel/memory.h"
#include "runtime_context.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------- programs */

/* GRAUPEL_CL_OPTIONS adds build options to every program (for instance
 * -cl-opt-disable while debugging a kernel); they are part of the program
 * cache key, so changing them rebuilds. */
static const char *gr_extra_build_options(void) {
  const char *extra = getenv("GRAUPEL_CL_OPTIONS");
  return extra ? extra : "";
}

static gr_status gr_build(gr_context *ctx, const char *label, const char *source,
                          const char *options, cl_program *out) {
  cl_int err = CL_SUCCESS;
  const char *src[1] = {source};
  cl_program prog = clCreateProgramWithSource(ctx->cl, 1, src, NULL, &err);
  if (err != CL_SUCCESS)
    return gr_cl_check(ctx, err, "Creating an OpenCL program");
  /* FP_CONTRACT stays off inside the sources; -cl-std pins the language. */
  char opts[4096];
  /* -cl-kernel-arg-info: gr_kernel_arg finds arguments by their names. */
  snprintf(opts, sizeof(opts), "-cl-std=CL1.2 -cl-kernel-arg-info %s %s", options ? options : "",
           gr_extra_build_options());
  err = clBuildProgram(prog, 1, &ctx->device, opts, NULL, NULL);
  if (err != CL_SUCCESS) {
    size_t len = 0;
    char *log = NULL;
    clGetProgramBuildInfo(prog, ctx->device, CL_PROGRAM_BUILD_LOG, 0, NULL, &len);
    if (len > 0 && (log = malloc(len + 1)) != NULL) {
      if (clGetProgramBuildInfo(prog, ctx->device, CL_PROGRAM_BUILD_LOG, len, log, NULL) !=
          CL_SUCCESS)
        log[0] = '\0';
      log[len] = '\0';
    }
    gr_status st = gr_set_error(
        ctx, GR_ERR_BUILD, "The OpenCL program '%s' failed to build on '%s' (%s). Build log:\n%s",
        label, ctx->device_name, gr_cl_error_name(err),
        log && log[0] ? log : "(the driver gave no log)");
    free(log);
    clReleaseProgram(prog);
    return st;
  }
  *out = prog;
  return GR_OK;
}

gr_status gr_program_build_source(gr_context *ctx, const char *source, const char *options,
                                  cl_program *out) {
  if (!ctx || !source || !out)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_program_build_source needs a context, a source "
                        "and a place for the program.");
  *out = NULL;
  return gr_build(ctx, "(user source)", source, options, out);
}

gr_status gr_program_get(gr_context *ctx, const char *name, const char *options, cl_program *out) {
  if (!ctx || !name || !out)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_program_get needs a context, a name and a place "
                        "for the program.");
  *out = NULL;
  const char *source = gr_kernel_source_find(name);
  if (!source)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "No kernel source named '%s' is built into Graupel.", name);
  if (!options)
    options = "";
  const char *extra = gr_extra_build_options();
  size_t klen = strlen(name) + strlen(options) + strlen(extra) + 3;
  char *key = malloc(klen);
  if (!key)
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  snprintf(key, klen, "%s\n%s\n%s", name, options, extra);

  /* Build under the lock so two filters don't build the same program. */
  pthread_mutex_lock(&ctx->lock);
  for (int i = 0; i < ctx->nprograms; ++i)
    if (strcmp(ctx->programs[i].key, key) == 0) {
      *out = ctx->programs[i].program;
      pthread_mutex_unlock(&ctx->lock);
      free(key);
      return GR_OK;
    }
  pthread_mutex_unlock(&ctx->lock);

  cl_program prog = NULL;
  gr_status st = gr_build(ctx, name, source, options, &prog);
  if (st != GR_OK) {
    free(key);
    return st;
  }
  pthread_mutex_lock(&ctx->lock);
  for (int i = 0; i < ctx->nprograms; ++i)
    if (strcmp(ctx->programs[i].key, key) == 0) { /* another thread won */
      *out = ctx->programs[i].program;
      pthread_mutex_unlock(&ctx->lock);
      clReleaseProgram(prog);
      free(key);
      return GR_OK;
    }
  if (ctx->nprograms == ctx->capacity) {
    int cap = ctx->capacity ? 2 * ctx->capacity : 16;
    gr_program_entry *grown = realloc(ctx->programs, (size_t)cap * sizeof(*grown));
    if (!grown) {
      pthread_mutex_unlock(&ctx->lock);
      clReleaseProgram(prog);
      free(key);
      return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
    }
    ctx->programs = grown;
    ctx->capacity = cap;
  }
  ctx->programs[ctx->nprograms].key = key;
  ctx->programs[ctx->nprograms].program = prog;
  ctx->nprograms++;
  pthread_mutex_unlock(&ctx->lock);
  *out = prog;
  return GR_OK;
}

gr_status gr_kernel_create(gr_context *ctx, cl_program prog, const char *name, cl_kernel *out) {
  cl_int err = CL_SUCCESS;
  if (!ctx || !prog || !name || !out)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_kernel_create needs a context, a program and a "
                        "kernel name.");
  *out = clCreateKernel(prog, name, &err);
  if (err != CL_SUCCESS) {
    *out = NULL;
    return gr_set_error(ctx, GR_ERR_OPENCL, "The kernel '%s' could not be created: %s.", name,
                        gr_cl_error_name(err));
  }
  return GR_OK;
}

static void gr_kernel_name(cl_kernel k, char *buf, size_t len) {
  buf[0] = '\0';
  if (clGetKernelInfo(k, CL_KERNEL_FUNCTION_NAME, len, buf, NULL) != CL_SUCCESS)
    snprintf(buf, len, "(unnamed)");
  buf[len - 1] = '\0';
}

gr_status gr_kernel_args(gr_context *ctx, cl_kernel k, ...) {
  va_list ap;
  va_start(ap, k);
  for (cl_uint i = 0;; ++i) {
    size_t size = va_arg(ap, size_t);
    if (size == 0)
      break;
    const void *value = va_arg(ap, const void *);
    cl_int err = clSetKernelArg(k, i, size, value);
    if (err != CL_SUCCESS) {
      va_end(ap);
      char kname[128];
      gr_kernel_name(k, kname, sizeof(kname));
      return gr_set_error(ctx, GR_ERR_OPENCL, "Setting argument %u of kernel '%s' failed: %s.", i,
                          kname, gr_cl_error_name(err));
    }
  }
  va_end(ap);
  return GR_OK;
}

/* The name of argument i of k into buf; a CL error code on failure. */
static cl_int gr_arg_name(cl_kernel k, cl_uint i, char *buf, size_t len) {
  size_t got = 0;
  buf[0] = '\0';
  cl_int err = clGetKernelArgInfo(k, i, CL_KERNEL_ARG_NAME, len, buf, &got);
  buf[len - 1] = '\0';
  return err;
}

/* Reads every argument name of k into a fresh entry (names NULL on failure). */
static cl_int gr_arg_entry_read(cl_kernel k, gr_arg_entry *e) {
  cl_uint n = 0;
  e->kernel = k;
  e->nargs = 0;
  e->names = NULL;
  cl_int err = clGetKernelInfo(k, CL_KERNEL_NUM_ARGS, sizeof(n), &n, NULL);
  if (err != CL_SUCCESS)
    return err;
  size_t total = 0;
  for (cl_uint i = 0; i < n; ++i) {
    size_t len = 0;
    err = clGetKernelArgInfo(k, i, CL_KERNEL_ARG_NAME, 0, NULL, &len);
    if (err != CL_SUCCESS)
      return err;
    total += len + 1;
  }
  char **names = malloc((size_t)n * sizeof(char *) + total + 1);
  if (!names)
    return CL_OUT_OF_HOST_MEMORY;
  char *p = (char *)(names + n);
  for (cl_uint i = 0; i < n; ++i) {
    size_t len = 0;
    err = clGetKernelArgInfo(k, i, CL_KERNEL_ARG_NAME, 0, NULL, &len);
    if (err == CL_SUCCESS)
      err = clGetKernelArgInfo(k, i, CL_KERNEL_ARG_NAME, len + 1, p, NULL);
    if (err != CL_SUCCESS) {
      free(names);
      return err;
    }
    p[len] = '\0';
    names[i] = p;
    p += len + 1;
  }
  e->nargs = n;
  e->names = names;
  return CL_SUCCESS;
}

static int gr_arg_entry_find(const gr_arg_entry *e, const char *name) {
  for (cl_uint i = 0; e->names && i < e->nargs; ++i)
    if (strcmp(e->names[i], name) == 0)
      return (int)i;
  return -1;
}

/* Index of the argument called name, or -1 (*err says why when it is an
 * OpenCL failure rather than an unknown name). */
static int gr_arg_index(gr_context *ctx, cl_kernel k, const char *name, cl_int *err) {
  char check[256];
  int index = -1;
  *err = CL_SUCCESS;
  pthread_mutex_lock(&ctx->lock);
  for (int i = 0; i < GR_ARG_CACHE; ++i)
    if (ctx->args[i].kernel == k && ctx->args[i].names) {
      index = gr_arg_entry_find(&ctx->args[i], name);
      break;
    }
  pthread_mutex_unlock(&ctx->lock);
  if (index >= 0 && gr_arg_name(k, (cl_uint)index, check, sizeof(check)) == CL_SUCCESS &&
      strcmp(check, name) == 0)
    return index;

  /* A miss, or a stale entry: read the kernel's names again. */
  gr_arg_entry fresh;
  *err = gr_arg_entry_read(k, &fresh);
  if (*err != CL_SUCCESS)
    return -1;
  index = gr_arg_entry_find(&fresh, name);
  pthread_mutex_lock(&ctx->lock);
  int slot = -1;
  for (int i = 0; i < GR_ARG_CACHE && slot < 0; ++i)
    if (ctx->args[i].kernel == k || !ctx->args[i].names)
      slot = i;
  if (slot < 0) {
    slot = ctx->next_arg;
    ctx->next_arg = (ctx->next_arg + 1) % GR_ARG_CACHE;
  }
  free(ctx->args[slot].names);
  ctx->args[slot] = fresh;
  pthread_mutex_unlock(&ctx->lock);
  return index;
}

gr_status gr_kernel_arg(gr_context *ctx, cl_kernel k, const char *name, size_t size,
                        const void *value) {
  if (!ctx || !k || !name)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_kernel_arg needs a context, a kernel and an argument name.");
  cl_int err = CL_SUCCESS;
  int index = gr_arg_index(ctx, k, name, &err);
  if (index >= 0) {
    err = clSetKernelArg(k, (cl_uint)index, size, value);
    if (err == CL_SUCCESS)
      return GR_OK;
  }
  char kname[128];
  gr_kernel_name(k, kname, sizeof(kname));
  if (err == CL_KERNEL_ARG_INFO_NOT_AVAILABLE)
    return gr_set_error(ctx, GR_ERR_OPENCL,
                        "The kernel '%s' has no argument names (argument '%s' was asked for): "
                        "build its program with -cl-kernel-arg-info, as gr_program_get does.",
                        kname, name);
  if (err != CL_SUCCESS)
    return gr_set_error(ctx, GR_ERR_OPENCL, "Setting argument '%s' of kernel '%s' failed: %s (%d).",
                        name, kname, gr_cl_error_name(err), (int)err);
  return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                      "The kernel '%s' has no argument named '%s': use a name from the kernel's "
                      "source.",
                      kname, name);
}

gr_status gr_enqueue_2d(gr_context *ctx, cl_kernel k, size_t x0, size_t y0, size_t nx, size_t ny,
                        const size_t *local) {
  size_t offset[2] = {x0, y0};
  size_t global[2] = {nx, ny};
  if (!local)
    local = ctx->local2d;
  if (local) {
    global[0] = (nx + local[0] - 1) / local[0] * local[0];
    global[1] = (ny + local[1] - 1) / local[1] * local[1];
  }
  cl_int err = clEnqueueNDRangeKernel(ctx->queue, k, 2, offset, global, local, 0, NULL, NULL);
  return gr_cl_check(ctx, err, "Enqueueing a kernel");
}

gr_status gr_enqueue_1d(gr_context *ctx, cl_kernel k, size_t n) {
  if (n == 0)
    return GR_OK;
  size_t local = 64, global = (n + local - 1) / local * local;
  cl_int err = clEnqueueNDRangeKernel(ctx->queue, k, 1, NULL, &global, &local, 0, NULL, NULL);
  return gr_cl_check(ctx, err, "Enqueueing a kernel");
}

gr_status gr_finish(gr_context *ctx) {
  return gr_cl_check(ctx, clFinish(ctx->queue), "Waiting for the device");
}

/* ------------------------------------------------------- embedded sources */

/* Generated at build time from the files in cl/ by EmbedKernels.cmake. */
extern const gr_kernel_source gr_embedded_kernels[];
extern const int gr_embedded_kernel_count;

int gr_kernel_source_count(void) {
  return gr_embedded_kernel_count;
}

const gr_kernel_source *gr_kernel_source_at(int i) {
  return (i >= 0 && i < gr_embedded_kernel_count) ? &gr_embedded_kernels[i] : NULL;
}

const char *gr_kernel_source_find(const char *name) {
  for (int i = 0; name && i < gr_embedded_kernel_count; ++i)
    if (strcmp(gr_embedded_kernels[i].name, name) == 0)
      return gr_embedded_kernels[i].text;
  return NULL;
}

/* ----------------------------------------------------------------- buffers */

gr_status gr_buffer_create(gr_context *ctx, cl_mem_flags flags, size_t size, const void *host,
                           cl_mem *out) {
  if (!ctx || !out || size == 0)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "A device buffer needs a context and a size above 0.");
  *out = NULL;
  if ((cl_ulong)size > ctx->max_alloc || (cl_ulong)size > ctx->global_mem)
    return gr_set_error(ctx, GR_ERR_TOO_LARGE,
                        "The grid needs a buffer of %.1f MiB but the device '%s' allows at "
                        "most %.1f MiB per buffer: use a smaller grid or another device.",
                        (double)size / 1048576.0, ctx->device_name,
                        (double)ctx->max_alloc / 1048576.0);
  if (ctx->host_memory && size >= GR_BUFFER_CHECKED) {
    /* The buffer is host memory: refuse what the process cannot get rather
     * than let the kernel's overcommit hand out pages that are not there. */
    gr_memory_info mem;
    if (gr_memory_query(NULL, &mem) == GR_OK && (double)size > (double)mem.host_available) {
      char need[32], have[32];
      gr_memory_format((double)size, need, sizeof(need));
      gr_memory_format((double)mem.host_available, have, sizeof(have));
      return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY,
                          "A device buffer of %s does not fit: the device '%s' keeps its "
                          "buffers in host memory and this process can use %s; use a smaller "
                          "grid.",
                          need, ctx->device_name, have);
    }
  }
  cl_int err = CL_SUCCESS;
  if (host)
    flags |= CL_MEM_COPY_HOST_PTR;
  /* Where buffers are host memory, allocate them now: PoCL otherwise
   * allocates at the buffer's first use and, when that fails, asserts
   * (pocl_create_migration_commands: p->mem_ptr != NULL) and aborts the
   * process; with CL_MEM_ALLOC_HOST_PTR clCreateBuffer itself fails with
   * CL_OUT_OF_HOST_MEMORY. The buffer is the same one allocation either
   * way (4 x 2 GB filled take 8.3 GB resident). */
  if (ctx->host_memory && !(flags & CL_MEM_USE_HOST_PTR))
    flags |= CL_MEM_ALLOC_HOST_PTR;
  *out = clCreateBuffer(ctx->cl, flags, size, (void *)host, &err);
  if (err != CL_SUCCESS) {
    *out = NULL;
    return gr_cl_check(ctx, err, "Allocating a device buffer");
  }
  return GR_OK;
}

gr_status gr_buffer_write(gr_context *ctx, cl_mem buf, size_t offset, size_t size,
                          const void *host) {
  cl_int err = clEnqueueWriteBuffer(ctx->queue, buf, CL_TRUE, offset, size, host, 0, NULL, NULL);
  return gr_cl_check(ctx, err, "Uploading a field to the device");
}

gr_status gr_buffer_read(gr_context *ctx, cl_mem buf, size_t offset, size_t size, void *host) {
  cl_int err = clEnqueueReadBuffer(ctx->queue, buf, CL_TRUE, offset, size, host, 0, NULL, NULL);
  return gr_cl_check(ctx, err, "Reading a field back from the device");
}

void gr_buffer_release(cl_mem *buf) {
  if (buf && *buf) {
    clReleaseMemObject(*buf);
    *buf = NULL;
  }
}
