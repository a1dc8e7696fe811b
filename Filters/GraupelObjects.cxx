#include "GraupelObjects.h"

#include "vtkCellArray.h"
#include "vtkIdList.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMultiBlockDataSet.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include "vtkGraupelMotion.h"

#include <array>
#include <map>
#include <sstream>

namespace graupel {

namespace {

// The object's centre (its bounds' middle) and velocity: the filter's, or
// the block's field array 'velocity'. An error message, or empty.
std::string ReadMotion(const char *filter, size_t k, vtkPolyData *pd, const double velocity[3],
                       Object &o) {
  double b[6];
  pd->GetBounds(b);
  for (int c = 0; c < 3; ++c) {
    o.centre[c] = 0.5 * (b[2 * c] + b[2 * c + 1]);
    o.velocity[c] = velocity[c];
  }
  vtkDataArray *v = pd->GetFieldData()->GetArray("velocity");
  if (v) {
    if (v->GetNumberOfComponents() != 3 || v->GetNumberOfTuples() < 1) {
      std::ostringstream msg;
      msg << filter << "'s Objects block " << k
          << " has a field array 'velocity' that is not one 3-component "
          << "value (m/s); give it 3 components or remove it.";
      return msg.str();
    }
    v->GetTuple(0, o.velocity);
  }
  return std::string();
}

// Vertices::Merged: points at the same place become one vertex, relative
// to the centre; vertexOf maps each point to its vertex.
void ReadMergedVertices(vtkPolyData *pd, Object &o, std::vector<int> &vertexOf) {
  const vtkIdType n = pd->GetNumberOfPoints();
  std::map<std::array<double, 3>, int> merged;
  for (vtkIdType i = 0; i < n; ++i) {
    std::array<double, 3> p;
    pd->GetPoint(i, p.data());
    auto found = merged.emplace(p, static_cast<int>(merged.size()));
    vertexOf[static_cast<size_t>(i)] = found.first->second;
    if (found.second) {
      for (int c = 0; c < 3; ++c) {
        o.vertices.push_back(static_cast<float>(p[static_cast<size_t>(c)] - o.centre[c]));
      }
    }
  }
}

// One vertex per point, relative to the centre, and the texture
// coordinates where the points have them.
void ReadPointVertices(vtkPolyData *pd, Object &o, std::vector<int> &vertexOf) {
  const vtkIdType n = pd->GetNumberOfPoints();
  o.vertices.resize(3 * static_cast<size_t>(n));
  for (vtkIdType i = 0; i < n; ++i) {
    double p[3];
    pd->GetPoint(i, p);
    for (int c = 0; c < 3; ++c) {
      o.vertices[3 * static_cast<size_t>(i) + c] = static_cast<float>(p[c] - o.centre[c]);
    }
    vertexOf[static_cast<size_t>(i)] = static_cast<int>(i);
  }
  // Texture coordinates (the first two components) give the object an
  // accumulation texture.
  if (vtkDataArray *tc = pd->GetPointData()->GetTCoords()) {
    if (tc->GetNumberOfComponents() >= 2 && tc->GetNumberOfTuples() == n) {
      o.uv.resize(2 * static_cast<size_t>(n));
      for (vtkIdType i = 0; i < n; ++i) {
        for (int c = 0; c < 2; ++c) {
          o.uv[2 * static_cast<size_t>(i) + c] = static_cast<float>(tc->GetComponent(i, c));
        }
      }
    }
  }
}

// Polygons as fans, strips with alternating winding: the triangles the
// core takes, without a dependency on VTK's filters.
void ReadTriangles(vtkPolyData *pd, const std::vector<int> &vertexOf, Object &o) {
  const vtkIdType n = pd->GetNumberOfPoints();
  // An id out of range becomes -1, which gr_mesh_validate names.
  auto vertex = [&](vtkIdType id) {
    return id >= 0 && id < n ? vertexOf[static_cast<size_t>(id)] : -1;
  };
  vtkNew<vtkIdList> ids;
  vtkCellArray *polys = pd->GetPolys();
  for (polys->InitTraversal(); polys->GetNextCell(ids);) {
    for (vtkIdType j = 2; j < ids->GetNumberOfIds(); ++j) {
      o.triangles.insert(o.triangles.end(),
                         {vertex(ids->GetId(0)), vertex(ids->GetId(j - 1)), vertex(ids->GetId(j))});
    }
  }
  vtkCellArray *strips = pd->GetStrips();
  for (strips->InitTraversal(); strips->GetNextCell(ids);) {
    for (vtkIdType j = 2; j < ids->GetNumberOfIds(); ++j) {
      const int a = vertex(ids->GetId(j - 2));
      const int b1 = vertex(ids->GetId(j - 1));
      const int c = vertex(ids->GetId(j));
      if (j % 2 == 0) {
        o.triangles.insert(o.triangles.end(), {a, b1, c});
      } else {
        o.triangles.insert(o.triangles.end(), {b1, a, c});
      }
    }
  }
}

// Block k of count as one object, its mesh validated. An error message, or
// empty.
std::string ReadObject(const char *filter, size_t k, size_t count, vtkPolyData *pd,
                       const double velocity[3], Vertices vertices, int closed, Object &o) {
  std::string error = ReadMotion(filter, k, pd, velocity, o);
  if (!error.empty()) {
    return error;
  }
  std::vector<int> vertexOf(static_cast<size_t>(pd->GetNumberOfPoints()));
  if (vertices == Vertices::Merged) {
    ReadMergedVertices(pd, o, vertexOf);
  } else {
    ReadPointVertices(pd, o, vertexOf);
  }
  ReadTriangles(pd, vertexOf, o);
  const gr_mesh mesh = MeshOf(o);
  char invalid[512];
  if (gr_mesh_validate(&mesh, closed, invalid, sizeof(invalid)) != GR_OK) {
    std::ostringstream msg;
    msg << filter << "'s Objects" << (count > 1 ? " block " + std::to_string(k) : std::string())
        << ": " << invalid;
    return msg.str();
  }
  return std::string();
}

} // namespace

std::string ReadObjects(const char *filter, vtkDataObject *input, size_t maxObjects,
                        const double velocity[3], Vertices vertices, int closed, bool inputTemporal,
                        const std::vector<double> &path, std::vector<Object> &objects,
                        bool &temporal) {
  objects.clear();
  std::ostringstream msg;
  bool other = false;
  const std::vector<vtkPolyData *> leaves = Leaves(input, &other);
  if (other) {
    msg << filter
        << "'s Objects must be vtkPolyData or a multiblock of them; "
           "convert the other blocks with Extract Surface.";
    return msg.str();
  }
  if (leaves.size() > maxObjects) {
    msg << filter << "'s Objects has " << leaves.size() << " blocks; at most " << maxObjects
        << " objects are simulated. Merge some.";
    return msg.str();
  }
  for (size_t k = 0; k < leaves.size(); ++k) {
    Object o;
    const std::string error =
        ReadObject(filter, k, leaves.size(), leaves[k], velocity, vertices, closed, o);
    if (!error.empty()) {
      return error;
    }
    objects.push_back(std::move(o));
  }
  temporal = inputTemporal;
  if (path.empty() || temporal) {
    return std::string();
  }
  for (size_t k = 0; k < objects.size(); ++k) {
    const std::string error = vtkGraupelMotion::CheckPathSpeed(filter, k, objects[k].velocity);
    if (!error.empty()) {
      return error;
    }
  }
  return std::string();
}

gr_mesh MeshOf(const Object &o) {
  gr_mesh mesh = {};
  mesh.vertices = o.vertices.data();
  mesh.nvertices = static_cast<int>(o.vertices.size() / 3);
  mesh.triangles = o.triangles.data();
  mesh.ntriangles = static_cast<int>(o.triangles.size() / 3);
  for (int i = 0; i < 16; ++i) {
    mesh.transform[i] = (i % 5 == 0) ? 1.0 : 0.0;
  }
  return mesh;
}

void PoseObject(const Object &o, bool temporal, double angularVelocity, const double axis[3],
                const std::vector<double> &path, double t, double m[16]) {
  if (temporal) {
    // The geometry is the pose: back to where it was read.
    for (int i = 0; i < 16; ++i) {
      m[i] = (i % 5 == 0) ? 1.0 : 0.0;
    }
    for (int c = 0; c < 3; ++c) {
      m[12 + c] = o.centre[c];
    }
    return;
  }
  vtkGraupelMotion::PoseObject(o.centre, o.velocity, angularVelocity, axis, path, t, m);
}

bool FillObjectsOutput(vtkDataObject *input, vtkDataObject *output, size_t n,
                       const PosedObject &posed, vtkMultiBlockDataSet **blocks) {
  if (blocks) {
    *blocks = nullptr;
  }
  bool other = false;
  const std::vector<vtkPolyData *> leaves = Leaves(input, &other);
  if (leaves.size() != n) {
    return true; // the objects changed since the state was made; nothing to pose
  }
  if (auto *pd = vtkPolyData::SafeDownCast(output)) {
    if (n == 1) {
      vtkSmartPointer<vtkPolyData> one = posed(0, leaves[0]);
      if (!one) {
        return false;
      }
      pd->ShallowCopy(one);
    }
    return true;
  }
  auto *mb = vtkMultiBlockDataSet::SafeDownCast(output);
  auto *in = vtkCompositeDataSet::SafeDownCast(input);
  if (!mb || !in) {
    return true;
  }
  mb->CopyStructure(in);
  vtkSmartPointer<vtkCompositeDataIterator> it;
  it.TakeReference(in->NewIterator());
  size_t k = 0;
  for (it->InitTraversal(); !it->IsDoneWithTraversal() && k < n; it->GoToNextItem()) {
    auto *leaf = vtkPolyData::SafeDownCast(it->GetCurrentDataObject());
    if (!leaf || leaf->GetNumberOfPoints() == 0) {
      continue;
    }
    vtkSmartPointer<vtkPolyData> one = posed(k, leaf);
    if (!one) {
      return false;
    }
    mb->SetDataSet(it, one);
    ++k;
  }
  if (blocks) {
    *blocks = mb;
  }
  return true;
}

void MatchObjectsOutput(vtkInformationVector **inInfo, vtkInformationVector *outInfo, int port) {
  vtkInformation *objInfo = inInfo[1]->GetInformationObject(0);
  vtkDataObject *objects = objInfo ? objInfo->Get(vtkDataObject::DATA_OBJECT()) : nullptr;
  const bool composite = vtkCompositeDataSet::SafeDownCast(objects) != nullptr;
  vtkInformation *info = outInfo->GetInformationObject(port);
  vtkDataObject *current = info->Get(vtkDataObject::DATA_OBJECT());
  const bool fits =
      current && (composite ? current->IsA("vtkMultiBlockDataSet") : current->IsA("vtkPolyData"));
  if (!fits) {
    vtkSmartPointer<vtkDataObject> made;
    if (composite) {
      made = vtkSmartPointer<vtkMultiBlockDataSet>::New();
    } else {
      made = vtkSmartPointer<vtkPolyData>::New();
    }
    info->Set(vtkDataObject::DATA_OBJECT(), made);
  }
}

int RequestedPiece(vtkInformation *info) {
  return info->Has(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER())
             ? info->Get(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER())
             : 0;
}

} // namespace graupel
