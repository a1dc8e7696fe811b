// Private to Filters/: the memory check every source and filter makes
// before it allocates (the core's query and sentence, kernels/.../memory.h).
#ifndef GraupelMemory_h
#define GraupelMemory_h

#include "graupel/memory.h"

#include <string>

namespace graupel {
/**
 * Empty when need fits what there is for ctx's device and this process
 * (gr_memory_check; ctx nullptr: host memory only), else the one sentence
 * that refuses it: "<label>: <subject> needs 12.8 GB (8 bytes a point) but
 * this process can use 9.6 GB; <fix>." subject is what is too large ("a
 * 40000 x 40000 grid", GridSubject), fix says how to make it smaller.
 */
std::string MemoryRefusal(const gr_context *ctx, const std::string &label,
                          const std::string &subject, const gr_memory_need &need,
                          const std::string &fix);

/** "a 40000 x 40000 grid" (what: "grid", "image", ...). */
std::string GridSubject(long long nx, long long ny, const char *what = "grid");

/** need with the host arrays of points points of bytesPerPoint bytes added. */
gr_memory_need WithHostArrays(gr_memory_need need, double points, double bytesPerPoint);
} // namespace graupel

#endif
