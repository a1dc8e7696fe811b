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
} // namespace graupel

#endif
