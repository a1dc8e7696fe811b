// Private to Filters/: setters that clamp to a core's parameter table
// (gr_<core>_param_bounds), the one place a filter's ranges come from.
#ifndef GraupelParameterTable_h
#define GraupelParameterTable_h

#include "graupel/graupel.h"

#include <cmath>

namespace graupel {
/** value clamped by the table row of property (unchanged when the table has no such row). */
inline double ClampToTable(const gr_param_bound *(*bounds)(int *), const char *property,
                           double value) {
  int count = 0;
  const gr_param_bound *table = bounds(&count);
  const gr_param_bound *row = gr_param_find(table, count, property);
  return row ? gr_param_clamp(row, value) : value;
}
} // namespace graupel

/** Defines cls::Set<name>(type), clamped by the table that bounds returns. */
#define GRAUPEL_TABLE_SETTER(cls, name, type, bounds)                                              \
  void cls::Set##name(type value) {                                                                \
    const type v =                                                                                 \
        static_cast<type>(graupel::ClampToTable(bounds, #name, static_cast<double>(value)));       \
    if (!(this->name == v) ||                                                                      \
        std::isnan(static_cast<double>(this->name)) != std::isnan(static_cast<double>(v))) {       \
      this->name = v;                                                                              \
      this->Modified();                                                                            \
    }                                                                                              \
  }

#endif
