// Private to Filters/: the Objects input every simulation filter with
// objects reads (a polydata or a composite of them) and poses.
#ifndef GraupelObjects_h
#define GraupelObjects_h

#include "vtkCellData.h"
#include "vtkCompositeDataIterator.h"
#include "vtkCompositeDataSet.h"
#include "vtkDataArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"

#include <vector>

namespace graupel {
// The leaves of an Objects input in order: the polydata itself, or every
// non-empty leaf of a composite.
inline std::vector<vtkPolyData *> Leaves(vtkDataObject *objects, bool *other) {
  std::vector<vtkPolyData *> leaves;
  *other = false;
  if (auto *cd = vtkCompositeDataSet::SafeDownCast(objects)) {
    vtkSmartPointer<vtkCompositeDataIterator> it;
    it.TakeReference(cd->NewIterator());
    for (it->InitTraversal(); !it->IsDoneWithTraversal(); it->GoToNextItem()) {
      auto *pd = vtkPolyData::SafeDownCast(it->GetCurrentDataObject());
      if (pd && pd->GetNumberOfPoints() > 0) {
        leaves.push_back(pd);
      } else if (!pd && it->GetCurrentDataObject()) {
        *other = true;
      }
    }
  } else if (auto *pd = vtkPolyData::SafeDownCast(objects)) {
    if (pd->GetNumberOfPoints() > 0) {
      leaves.push_back(pd); // an empty polydata is no object
    }
  } else if (objects) {
    *other = true;
  }
  return leaves;
}

// Vectors (normals) turned by the pose's rotation.
inline vtkSmartPointer<vtkDataArray> Turned(vtkDataArray *v, const double m[16]) {
  if (!v || v->GetNumberOfComponents() != 3) {
    return v;
  }
  auto out = vtkSmartPointer<vtkFloatArray>::New();
  out->SetName(v->GetName());
  out->SetNumberOfComponents(3);
  out->SetNumberOfTuples(v->GetNumberOfTuples());
  for (vtkIdType i = 0; i < v->GetNumberOfTuples(); ++i) {
    double a[3];
    v->GetTuple(i, a);
    out->SetTuple3(i, m[0] * a[0] + m[4] * a[1] + m[8] * a[2],
                   m[1] * a[0] + m[5] * a[1] + m[9] * a[2],
                   m[2] * a[0] + m[6] * a[1] + m[10] * a[2]);
  }
  return out;
}

// A copy of pd's geometry moved by the pose: world = M (p - centre).
inline vtkSmartPointer<vtkPolyData> Posed(vtkPolyData *pd, const double centre[3],
                                          const double m[16]) {
  auto out = vtkSmartPointer<vtkPolyData>::New();
  out->ShallowCopy(pd);
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  const vtkIdType n = pd->GetNumberOfPoints();
  points->SetNumberOfPoints(n);
  for (vtkIdType i = 0; i < n; ++i) {
    double p[3];
    pd->GetPoint(i, p);
    const double x = p[0] - centre[0], y = p[1] - centre[1], z = p[2] - centre[2];
    points->SetPoint(i, m[0] * x + m[4] * y + m[8] * z + m[12],
                     m[1] * x + m[5] * y + m[9] * z + m[13],
                     m[2] * x + m[6] * y + m[10] * z + m[14]);
  }
  out->SetPoints(points);
  if (vtkDataArray *normals = pd->GetPointData()->GetNormals()) {
    out->GetPointData()->SetNormals(Turned(normals, m));
  }
  if (vtkDataArray *normals = pd->GetCellData()->GetNormals()) {
    out->GetCellData()->SetNormals(Turned(normals, m));
  }
  vtkNew<vtkFieldData> fd;
  fd->ShallowCopy(pd->GetFieldData());
  out->SetFieldData(fd);
  return out;
}
} // namespace graupel

#endif
