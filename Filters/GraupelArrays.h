// Private to Filters/: the array conversions every simulation filter makes
// between VTK data and a core.
#ifndef GraupelArrays_h
#define GraupelArrays_h

#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkNew.h"
#include "vtkSmartPointer.h"

#include "graupel/graupel.h"

#include <sstream>
#include <string>

namespace graupel {
/** The array as float32 (a copy when it is stored otherwise), or nullptr. */
inline vtkSmartPointer<vtkFloatArray> AsFloat(vtkDataArray *a) {
  if (!a) {
    return nullptr;
  }
  if (auto *f = vtkFloatArray::SafeDownCast(a)) {
    return f;
  }
  auto f = vtkSmartPointer<vtkFloatArray>::New();
  f->DeepCopy(a);
  return f;
}

/** One double value as a named field-data array (a ledger entry). */
inline void AddValue(vtkFieldData *fd, const char *name, double value) {
  vtkNew<vtkDoubleArray> a;
  a->SetName(name);
  a->InsertNextValue(value);
  fd->AddArray(a);
}

/** A terrain array for a core: its field and its values as float32. */
struct Upload {
  gr_field field;
  vtkSmartPointer<vtkFloatArray> values;
};

/**
 * Empty when u holds one value per point of the terrain's npoints, else
 * the sentence "<filter>'s Input array '<name>' has ... or remove it."
 */
inline std::string CheckPerPoint(const char *filter, const Upload &u, size_t npoints) {
  if (u.values->GetNumberOfComponents() == 1 &&
      static_cast<size_t>(u.values->GetNumberOfTuples()) == npoints) {
    return std::string();
  }
  std::ostringstream msg;
  msg << filter << "'s Input array '" << gr_field_name(u.field) << "' has "
      << u.values->GetNumberOfTuples() << " tuples of " << u.values->GetNumberOfComponents()
      << " component(s); it must have one value per point (" << npoints
      << "): resample it onto the terrain's grid or remove it.";
  return msg.str();
}
} // namespace graupel

#endif
