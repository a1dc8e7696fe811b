// Private to Filters/: the Objects input every simulation filter with
// objects reads (a polydata or a composite of them) and poses, and the
// objects' output it fills (GraupelObjects.cxx).
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

#include "graupel/graupel.h"

#include <functional>
#include <string>
#include <vector>

class vtkInformation;
class vtkInformationVector;
class vtkMultiBlockDataSet;

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

/** One object as a core sees it: its vertices about its centre. */
struct Object {
  std::vector<float> vertices;
  std::vector<int> triangles;
  std::vector<float> uv; // 2 per vertex from the texture coordinates (PerPoint), else empty
  double centre[3];
  double velocity[3]; // m/s: the leaf's `velocity`, else ObjectVelocity
};

/** How the points of an object's polydata become its mesh's vertices. */
enum class Vertices {
  // One vertex per point, unmerged, with its texture coordinates: the snow
  // is handed back per point, and a box's faces keep their own corners (and
  // flat normals), so its top holds a flat cap and its sides none.
  PerPoint,
  // Points at the same place are one vertex: sources such as a box or a
  // capped cylinder repeat corners per face (for their normals), which
  // would leave every edge open.
  Merged
};

/**
 * Reads an Objects input (nullptr: none) into objects, one per leaf
 * (Leaves): vertices about the centre of its bounds, its polygons and
 * strips as triangles, its velocity the leaf's field array `velocity`, else
 * `velocity` (ObjectVelocity). Each mesh must pass gr_mesh_validate with
 * `closed`. Once every mesh is read, temporal takes inputTemporal (the
 * input has time steps: its geometry is the pose), and along a path (not
 * empty) the objects posed by the properties must have a speed
 * (vtkGraupelMotion::CheckPathSpeed). Returns an empty string, or one
 * sentence that starts with `filter` (e.g. "Snow Deformation"); the objects
 * read before it stay.
 */
std::string ReadObjects(const char *filter, vtkDataObject *input, size_t maxObjects,
                        const double velocity[3], Vertices vertices, int closed, bool inputTemporal,
                        const std::vector<double> &path, std::vector<Object> &objects,
                        bool &temporal);

/** o's mesh (views of its arrays) at the identity pose. */
gr_mesh MeshOf(const Object &o);

/**
 * The pose (column-major) of o at time t: a temporal object's geometry is
 * its pose, so it goes back to where it was read; the others move by the
 * properties (vtkGraupelMotion::PoseObject).
 */
void PoseObject(const Object &o, bool temporal, double angularVelocity, const double axis[3],
                const std::vector<double> &path, double t, double m[16]);

/** Object k of the leaf it was read from, at its pose; nullptr after a reported failure. */
using PosedObject = std::function<vtkSmartPointer<vtkPolyData>(size_t k, vtkPolyData *leaf)>;

/**
 * Fills the objects' output from the Objects input's n objects: a polydata
 * output holds the one object (n == 1), a multiblock the input's structure
 * with object k in the leaf it came from. Nothing is filled when the input
 * no longer has n objects (it changed since the state was made). Returns
 * false when `posed` failed; *blocks (if given) is set to the multiblock
 * when the objects went into one, else nullptr.
 */
bool FillObjectsOutput(vtkDataObject *input, vtkDataObject *output, size_t n,
                       const PosedObject &posed, vtkMultiBlockDataSet **blocks = nullptr);

/**
 * For REQUEST_DATA_OBJECT: output `port` follows the Objects input's
 * (input 1) type, a multiblock for a composite, else a polydata.
 */
void MatchObjectsOutput(vtkInformationVector **inInfo, vtkInformationVector *outInfo, int port);

/** The piece an output's request asks for (UPDATE_PIECE_NUMBER), 0 without one. */
int RequestedPiece(vtkInformation *info);
} // namespace graupel

#endif
