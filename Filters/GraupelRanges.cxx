#include "GraupelRanges.h"

#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkDataSet.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkInformation.h"
#include "vtkInformationDoubleVectorKey.h"
#include "vtkInformationInformationVectorKey.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkPointData.h"

#include <cmath>
#include <limits>
#include <vector>

namespace {
// Per component [min, max] over finite values, and the magnitude's range
// over tuples whose components are all finite (VTK skips NaN tuples for the
// magnitude; an infinity sends the whole array back to VTK).
template <typename T>
bool Ranges(const T *v, long long tuples, int nc, std::vector<double> &comp, double norm[2]) {
  comp.assign(2 * static_cast<size_t>(nc), 0.0);
  for (int c = 0; c < nc; ++c) {
    comp[2 * c] = std::numeric_limits<double>::infinity();
    comp[2 * c + 1] = -std::numeric_limits<double>::infinity();
  }
  norm[0] = std::numeric_limits<double>::infinity();
  norm[1] = -std::numeric_limits<double>::infinity();
  if (nc == 1) {
    // The common case, kept in a loop the compiler vectorises: NaN fails
    // both comparisons, so it changes neither bound.
    T lo = std::numeric_limits<T>::infinity(), hi = -std::numeric_limits<T>::infinity();
    for (long long i = 0; i < tuples; ++i) {
      const T x = v[i];
      lo = x < lo ? x : lo;
      hi = x > hi ? x : hi;
    }
    if (std::isinf(lo) || std::isinf(hi)) {
      return false; // an infinity, or no finite value at all
    }
    comp[0] = norm[0] = lo;
    comp[1] = norm[1] = hi;
    return true;
  }
  for (long long i = 0; i < tuples; ++i) {
    const T *t = v + i * nc;
    double sq = 0.0;
    bool finite = true;
    for (int c = 0; c < nc; ++c) {
      const double x = t[c];
      if (std::isnan(x)) {
        finite = false;
        continue;
      }
      if (std::isinf(x)) {
        return false;
      }
      comp[2 * c] = x < comp[2 * c] ? x : comp[2 * c];
      comp[2 * c + 1] = x > comp[2 * c + 1] ? x : comp[2 * c + 1];
      sq += x * x;
    }
    if (finite) {
      const double m = std::sqrt(sq);
      norm[0] = m < norm[0] ? m : norm[0];
      norm[1] = m > norm[1] ? m : norm[1];
    }
  }
  for (int c = 0; c < nc; ++c) {
    if (!(comp[2 * c] <= comp[2 * c + 1])) {
      return false; // a component with no finite value
    }
  }
  return norm[0] <= norm[1];
}

void Store(vtkInformation *info, vtkInformationInformationVectorKey *key,
           const std::vector<double> &comp, int nc) {
  vtkNew<vtkInformationVector> per;
  per->SetNumberOfInformationObjects(nc);
  for (int c = 0; c < nc; ++c) {
    per->GetInformationObject(c)->Set(vtkDataArray::COMPONENT_RANGE(), comp.data() + 2 * c, 2);
  }
  info->Set(key, per);
}

void CacheAll(vtkFieldData *fd) {
  for (int i = 0; fd && i < fd->GetNumberOfArrays(); ++i) {
    graupel::CacheRange(fd->GetArray(i));
  }
}
} // namespace

namespace graupel {
bool CacheRange(vtkDataArray *array) {
  if (!array || array->GetNumberOfTuples() == 0) {
    return false;
  }
  // Already cached (an input's array passed on): Modified() would have
  // removed these keys had its values changed since.
  vtkInformation *cache = array->HasInformation() ? array->GetInformation() : nullptr;
  if (cache && cache->Has(vtkDataArray::PER_COMPONENT()) &&
      cache->Has(vtkDataArray::PER_FINITE_COMPONENT())) {
    return true;
  }
  const int nc = array->GetNumberOfComponents();
  const long long tuples = array->GetNumberOfTuples();
  std::vector<double> comp;
  double norm[2];
  bool ok = false;
  if (auto *f = vtkFloatArray::SafeDownCast(array)) {
    ok = Ranges(f->GetPointer(0), tuples, nc, comp, norm);
  } else if (auto *d = vtkDoubleArray::SafeDownCast(array)) {
    ok = Ranges(d->GetPointer(0), tuples, nc, comp, norm);
  }
  if (!ok) {
    return false;
  }
  // No infinity was seen, so the range and the finite range are one.
  vtkInformation *info = array->GetInformation();
  Store(info, vtkDataArray::PER_COMPONENT(), comp, nc);
  Store(info, vtkDataArray::PER_FINITE_COMPONENT(), comp, nc);
  if (nc > 1) {
    info->Set(vtkDataArray::L2_NORM_RANGE(), norm, 2);
    info->Set(vtkDataArray::L2_NORM_FINITE_RANGE(), norm, 2);
  }
  return true;
}

void CacheRanges(vtkDataObject *data) {
  if (auto *ds = vtkDataSet::SafeDownCast(data)) {
    CacheAll(ds->GetPointData());
    CacheAll(ds->GetCellData());
  }
}
} // namespace graupel
