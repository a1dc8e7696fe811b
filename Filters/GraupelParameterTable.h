// Private to Filters/: setters that clamp to a core's parameter table
// (gr_<core>_param_bounds), the one place a filter's ranges come from.
#ifndef GraupelParameterTable_h
#define GraupelParameterTable_h

#include "graupel/graupel.h"

#include <cmath>
#include <sstream>
#include <string>

namespace graupel {
/** The row of property in the table that bounds returns; nullptr when it has none. */
inline const gr_param_bound *TableRow(const gr_param_bound *(*bounds)(int *),
                                      const char *property) {
  int count = 0;
  const gr_param_bound *table = bounds(&count);
  return gr_param_find(table, count, property);
}

/**
 * The default of property from its table row: the one place a default is
 * written (py.param_bounds checks that the row exists and that the XML and
 * docs pages agree with it).
 */
inline double TableDefault(const gr_param_bound *(*bounds)(int *), const char *property) {
  const gr_param_bound *row = TableRow(bounds, property);
  return row ? row->default_value : std::nan("");
}

/** value clamped by the table row of property (unchanged when the table has no such row). */
inline double ClampToTable(const gr_param_bound *(*bounds)(int *), const char *property,
                           double value) {
  int count = 0;
  const gr_param_bound *table = bounds(&count);
  const gr_param_bound *row = gr_param_find(table, count, property);
  return row ? gr_param_clamp(row, value) : value;
}

/**
 * Empty when row accepts value (in the property's units; no row accepts
 * all), else the sentence "<filter>: <name> must be from <min> to <max>
 * <unit>; it is <value> <unit>. Set it within that range."
 */
inline std::string OutOfRange(const char *filter, const char *name, const gr_param_bound *row,
                              double value) {
  if (!row || gr_param_accepts(row, value * row->to_core)) {
    return std::string();
  }
  const char *unit = (row->unit && *row->unit) ? row->unit : "";
  const char *space = *unit ? " " : "";
  std::ostringstream msg;
  msg << filter << ": " << name << " must be " << (row->min_open ? "above " : "from ") << row->min
      << space << unit << (row->min_open ? " and up to " : " to ") << row->max << space << unit
      << "; it is " << value << space << unit << ". Set it within that range.";
  return msg.str();
}
} // namespace graupel

/**
 * Defines cls::Set<name>(type), clamped by the table that bounds returns; a
 * value moved into the range is noted (vtkGraupelAlgorithm::NoteSetting) so
 * that the next update says so in one warning.
 */
#define GRAUPEL_TABLE_SETTER(cls, name, type, bounds)                                              \
  void cls::Set##name(type value) {                                                                \
    const type v =                                                                                 \
        static_cast<type>(graupel::ClampToTable(bounds, #name, static_cast<double>(value)));       \
    int count_ = 0;                                                                                \
    const gr_param_bound *table_ = bounds(&count_);                                                \
    if (const gr_param_bound *row_ = gr_param_find(table_, count_, #name)) {                       \
      this->NoteSetting(#name, static_cast<double>(value), static_cast<double>(v),                 \
                        static_cast<double>(this->name), row_->unit, row_->min, row_->max);        \
    }                                                                                              \
    if (!(this->name == v) ||                                                                      \
        std::isnan(static_cast<double>(this->name)) != std::isnan(static_cast<double>(v))) {       \
      this->name = v;                                                                              \
      this->Modified();                                                                            \
    }                                                                                              \
  }

/**
 * Defines cls::Set<name>(type), clamped to [lo, hi] (for properties without
 * a core table row), noted as GRAUPEL_TABLE_SETTER notes.
 */
#define GRAUPEL_CLAMP_SETTER(cls, name, type, lo, hi, unit)                                        \
  void cls::Set##name(type value) {                                                                \
    const type v = value < (lo) ? (lo) : (value > (hi) ? (hi) : value);                            \
    this->NoteSetting(#name, static_cast<double>(value), static_cast<double>(v),                   \
                      static_cast<double>(this->name), unit, static_cast<double>(lo),              \
                      static_cast<double>(hi));                                                    \
    if (!(this->name == v)) {                                                                      \
      this->name = v;                                                                              \
      this->Modified();                                                                            \
    }                                                                                              \
  }

#endif
