#include "GraupelMemory.h"

#include <sstream>

namespace graupel {
std::string MemoryRefusal(const gr_context *ctx, const std::string &label,
                          const std::string &subject, const gr_memory_need &need,
                          const std::string &fix) {
  char why[512];
  if (gr_memory_check(ctx, &need, why, sizeof(why)) == GR_OK) {
    return std::string();
  }
  return label + ": " + subject + " " + why + "; " + fix + ".";
}

std::string GridSubject(long long nx, long long ny, const char *what) {
  std::ostringstream s;
  s << "a " << nx << " x " << ny << " " << what;
  return s.str();
}

gr_memory_need WithHostArrays(gr_memory_need need, double points, double bytesPerPoint) {
  need.host += points * bytesPerPoint;
  return need;
}
} // namespace graupel
