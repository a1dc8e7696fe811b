/**
 * @file memory.h
 * @brief How much memory there is, and whether a grid's buffers fit in it.
 *
 * A grid that does not fit must be refused before anything is allocated:
 * OpenCL drivers allocate a buffer lazily, when a command first uses it, and
 * PoCL (whose buffers are host memory) then asserts and aborts the process
 * instead of returning an error. So every core states what a grid needs
 * (gr_<core>_memory, a gr_memory_need), checks it with gr_memory_check in
 * its create, and a caller that adds host copies of its own (a VTK filter's
 * output arrays) adds them to the need and checks before it starts.
 *
 * Sizes are bytes. In sentences they are written in decimal units (1 GB =
 * 1e9 bytes), as `free` and the GUI's memory inspector count.
 */
#ifndef GRAUPEL_MEMORY_H
#define GRAUPEL_MEMORY_H

#include "graupel/runtime.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A figure that cannot be read (or a limit that is not set): the largest value. */
#define GR_MEMORY_UNLIMITED 18446744073709551615ULL

/** What memory there is now for new buffers and arrays. */
typedef struct gr_memory_info {
  /**
   * What this process can still allocate on the host: the smaller of
   * host_free and address_space_left.
   */
  unsigned long long host_available;
  /** MemAvailable of /proc/meminfo: what the machine can give without swapping. */
  unsigned long long host_free;
  /**
   * The address-space limit (RLIMIT_AS, `ulimit -v`, `prlimit --as`) less
   * what the process maps already (VmSize); GR_MEMORY_UNLIMITED without a
   * limit.
   */
  unsigned long long address_space_left;
  /** The device's CL_DEVICE_GLOBAL_MEM_SIZE (0 when no context was given). */
  unsigned long long device_global;
  /** The device's CL_DEVICE_MAX_MEM_ALLOC_SIZE: the largest single buffer. */
  unsigned long long device_max_alloc;
  /**
   * 1 when the device's buffers are host memory (a CPU device such as
   * PoCL's, or a GPU that shares the host's memory): they count against
   * host_available, and device_global is only the driver's guess (PoCL
   * advertises a fraction of the machine's memory and enforces none of it).
   */
  int device_uses_host_memory;
} gr_memory_info;

/**
 * Reads what there is: the host's figures always, the device's when ctx is
 * given (NULL: host only). GR_OK, or GR_ERR_INVALID_ARGUMENT without out.
 */
GR_API gr_status gr_memory_query(const gr_context *ctx, gr_memory_info *out);

/**
 * What a grid (or a set of particles, a bolt) needs. Doubles, so that an
 * absurd request is a large number rather than an overflow.
 */
typedef struct gr_memory_need {
  double device;  /**< bytes of every device buffer together */
  double largest; /**< the largest single device buffer */
  double host;    /**< host bytes besides: the core's own arrays, the caller's copies */
  double points;  /**< the points these are for (the sentence's "bytes a point"); 0: not said */
  /**
   * A simulation's checkpoint: the bytes gr_<core>_state_save writes (0 for
   * other cores). Not counted by gr_memory_check: a caller that saves the
   * state adds it to host.
   */
  double state;
} gr_memory_need;

/** Adds b to a (device, host, points and state add up; largest is the larger). */
GR_API void gr_memory_need_add(gr_memory_need *a, const gr_memory_need *b);

/**
 * GR_OK when need fits what gr_memory_query(ctx) reports: its largest
 * buffer within the device's largest allocation; and, on a device whose
 * buffers are host memory (or with no ctx), device plus host within
 * host_available; on another device, device within device_global and host
 * within host_available. Otherwise GR_ERR_TOO_LARGE, and the reason as a
 * clause that follows a subject ("a 40000 x 40000 grid ") written to msg:
 * "needs 12.8 GB (8 bytes a point) but this process can use 9.6 GB" (with
 * "(its address-space limit)" when that is what binds), "needs 150.0 GB of
 * device memory (…) but the device 'NVIDIA H200' has 140.4 GB", or "needs
 * one buffer of 6.4 GB but the device '…' allows at most 2.1 GB in one
 * buffer". Records no error itself: the caller makes the sentence.
 */
GR_API gr_status gr_memory_check(const gr_context *ctx, const gr_memory_need *need, char *msg,
                                 size_t msg_len);

/** Writes bytes as "12.8 GB", "640.0 MB" or "12 kB" (decimal units) to buf. */
GR_API void gr_memory_format(double bytes, char *buf, size_t len);

#ifdef __cplusplus
}
#endif

#endif
