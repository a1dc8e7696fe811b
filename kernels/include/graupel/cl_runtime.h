/**
 * @file cl_runtime.h
 * @brief Checked OpenCL helpers the cores are built on.
 *
 * For code that runs its own kernels on a Graupel context: the cores, the
 * benchmark and the tests. Every helper records a sentence as the calling
 * thread's latest error (gr_last_error) when it fails; a core copies it into
 * its handle with gr_error_keep.
 */
#ifndef GRAUPEL_CL_RUNTIME_H
#define GRAUPEL_CL_RUNTIME_H

#ifndef CL_TARGET_OPENCL_VERSION
#define CL_TARGET_OPENCL_VERSION 120
#endif
#include <CL/cl.h>

#include "graupel/runtime.h"

#ifdef __cplusplus
extern "C" {
#endif

/**
 * The last mesh an object passed gr_mesh_validate with: a copy of its
 * vertices and triangles. A simulation checks its objects every step, but
 * a moving object is the same mesh under a new transform; gr_mesh_check
 * then compares the arrays (a memcmp) and checks the transform alone
 * instead of every triangle and edge again. Zeroed to start; free with
 * gr_mesh_memo_free.
 */
typedef struct gr_mesh_memo {
  float *vertices;
  int *triangles;
  int nvertices, ntriangles, closed;
} gr_mesh_memo;

/**
 * gr_mesh_validate(m, closed, ..), the same answer and sentence, at the cost
 * of a comparison when m's vertices and triangles equal the memo's (and it
 * was checked at least as strictly); a mesh that passes becomes the memo
 * (when its copy cannot be allocated the memo is only emptied).
 */
GR_API gr_status gr_mesh_check(gr_mesh_memo *memo, const gr_mesh *m, int closed, char *msg,
                               size_t msg_len);

GR_API void gr_mesh_memo_free(gr_mesh_memo *memo);

/**
 * The contract of a core that splits a domain into strips of whole rows
 * (graupel.h's pieces, along y only), checked on grid g: non-negative
 * global sizes and ghost, whole rows (i0 = 0, nx = global_nx), the strip
 * within the domain, and, where it has a neighbour, a ring of at least
 * `need` rows (need_for says why, e.g. "for BlurRadius 2") and rows enough
 * to fill it. `core` names the core in the sentences ("snow accumulation"),
 * split_why adds to the first (e.g. " (its ledger adds whole rows)", or
 * ""). On success *ring_s and *ring_n get the ring toward each side (0
 * where the strip ends the domain); otherwise a sentence goes to msg.
 */
GR_API gr_status gr_grid_strip_check(const gr_grid *g, const char *core, const char *split_why,
                                     int need, const char *need_for, int *ring_s, int *ring_n,
                                     char *msg, size_t msg_len);

/** Name of an OpenCL error code, e.g. "CL_OUT_OF_RESOURCES". */
GR_API const char *gr_cl_error_name(cl_int err);

GR_API cl_context gr_context_cl(const gr_context *ctx);
GR_API cl_command_queue gr_context_queue(const gr_context *ctx);
GR_API cl_device_id gr_context_device(const gr_context *ctx);

/**
 * Records a formatted sentence as the calling thread's latest error, passes
 * it to the context's log callback (when ctx has one; ctx may be NULL) and
 * returns st. The arguments may include gr_last_error's own text.
 */
GR_API gr_status gr_set_error(const gr_context *ctx, gr_status st, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/**
 * Checks an OpenCL return code: GR_OK for CL_SUCCESS, otherwise records
 * "<what> failed: <CL error name>." and returns GR_ERR_OPENCL (or
 * GR_ERR_OUT_OF_MEMORY for allocation failures).
 */
GR_API gr_status gr_cl_check(const gr_context *ctx, cl_int err, const char *what);

/**
 * The program for an embedded kernel source ("procedural_terrain", "bench", ...),
 * built once per context and options and cached there. The program stays
 * owned by the context: do not release it. A failed build gives GR_ERR_BUILD
 * and the build log in gr_last_error.
 */
GR_API gr_status gr_program_get(gr_context *ctx, const char *name, const char *options,
                                cl_program *out);

/**
 * Builds a program from the given source (not cached; caller releases).
 * Used for user kernels and tests; the build log is in the error on failure.
 */
GR_API gr_status gr_program_build_source(gr_context *ctx, const char *source, const char *options,
                                         cl_program *out);

/** A kernel by name from a program (caller releases with clReleaseKernel). */
GR_API gr_status gr_kernel_create(gr_context *ctx, cl_program prog, const char *name,
                                  cl_kernel *out);

/**
 * A device buffer of size bytes, checked against the device's largest
 * allocation and global memory (GR_ERR_TOO_LARGE). host may be NULL; when
 * given, the buffer is initialised from it (CL_MEM_COPY_HOST_PTR). On a
 * device whose buffers are host memory (gr_device_info.host_memory) the
 * buffer is allocated at once (CL_MEM_ALLOC_HOST_PTR), so that a failed
 * allocation is this call's GR_ERR_OUT_OF_MEMORY and not an abort inside the
 * driver at the buffer's first use, and one of 1 MiB or more that exceeds
 * what the process can get (gr_memory_query) is refused with a sentence.
 * A core checks its whole grid first (memory.h); this is the backstop.
 */
GR_API gr_status gr_buffer_create(gr_context *ctx, cl_mem_flags flags, size_t size,
                                  const void *host, cl_mem *out);

/** Blocking write and read of a whole buffer region. */
GR_API gr_status gr_buffer_write(gr_context *ctx, cl_mem buf, size_t offset, size_t size,
                                 const void *host);
GR_API gr_status gr_buffer_read(gr_context *ctx, cl_mem buf, size_t offset, size_t size,
                                void *host);

/** Releases a buffer and zeroes the handle; a zero handle is fine. */
GR_API void gr_buffer_release(cl_mem *buf);

/**
 * Sets the argument of kernel k that the kernel's source calls name.
 * Programs are built with -cl-kernel-arg-info and the name-to-index table is
 * cached per kernel, so a lookup is cheap. An unknown name or a failed
 * clSetKernelArg is reported with the kernel's and the argument's names and
 * the OpenCL error name.
 */
GR_API gr_status gr_kernel_arg(gr_context *ctx, cl_kernel k, const char *name, size_t size,
                               const void *value);
/** gr_kernel_arg for an argument named like the variable: GR_KERNEL_ARG(ctx, k, nx). */
#define GR_KERNEL_ARG(ctx, k, var) gr_kernel_arg((ctx), (k), #var, sizeof(var), &(var))

/**
 * Per-handle errors: gr_set_error records its sentence for the calling
 * thread; a core's failing entry point ends with
 *   return gr_error_keep(s->error, sizeof(s->error), st);
 * which copies the thread's sentence into the handle's own buffer (so two
 * handles on one shared context never see each other's messages) and
 * returns st.
 */
GR_API gr_status gr_error_keep(char *dst, size_t len, gr_status st);

/**
 * The check every core's field validator shares: n values (rows of nx) of
 * the field called name, each finite and within [lo, hi]. On the first
 * that is not (or values NULL with n > 0) writes one sentence into msg
 * ("The field 'x' has the value v at point (i, j): rule.") and returns
 * GR_ERR_INVALID_ARGUMENT; GR_OK otherwise. Records no error itself.
 */
GR_API gr_status gr_field_check_range(const char *name, const float *values, size_t n, size_t nx,
                                      double lo, double hi, const char *rule, char *msg,
                                      size_t msg_len);

/**
 * Sets a kernel's arguments in order: pairs of (size_t size, const void
 * *value), ended by a size of 0. Reports which argument failed.
 */
GR_API gr_status gr_kernel_args(gr_context *ctx, cl_kernel k, ...);

/**
 * Enqueues a 2-D kernel over the nx by ny work-items starting at (x0, y0)
 * (get_global_id includes the start). The work-group shape is local, or the
 * context's default when local is NULL (16 x 16 on GPUs, 64 x 1 on CPUs); the
 * size is rounded up to it, so kernels guard their own bounds. Does not wait.
 */
GR_API gr_status gr_enqueue_2d(gr_context *ctx, cl_kernel k, size_t x0, size_t y0, size_t nx,
                               size_t ny, const size_t *local);

/**
 * Enqueues a 1-D kernel over n work-items (groups of 64, the size rounded
 * up to them: kernels guard their own bounds). For per-item kernels
 * (triangles, mesh points, a flat run of cells): a 2-D launch of n x 1
 * takes the GPUs' 16 x 16 groups and runs every item 16 times. Does not
 * wait.
 */
GR_API gr_status gr_enqueue_1d(gr_context *ctx, cl_kernel k, size_t n);

/** Waits for the context's queue to drain. */
GR_API gr_status gr_finish(gr_context *ctx);

/**
 * The embedded kernel sources: name and text, with every kernels/cl header
 * they include inlined (recursively, each once per source).
 */
typedef struct gr_kernel_source {
  const char *name;
  const char *text;
} gr_kernel_source;
/** Number of embedded sources; gr_kernel_source_at(i) for i below it. */
GR_API int gr_kernel_source_count(void);
GR_API const gr_kernel_source *gr_kernel_source_at(int i);
GR_API const char *gr_kernel_source_find(const char *name);

#ifdef __cplusplus
}
#endif

#endif
