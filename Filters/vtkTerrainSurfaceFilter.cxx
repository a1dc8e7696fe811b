#include "vtkTerrainSurfaceFilter.h"

#include "vtkAbstractArray.h"
#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include "GraupelMemory.h"
#include "vtkGraupelAlgorithm.h" // GRAUPEL_VTK_ABORT_OUTPUT

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkTerrainSurfaceFilter);

namespace {
// The order in which the data choose: the topmost surface the data have
// (water over snow over ground), and the quantity each filter is about.
const char *const HeightChoices[] = {"water_surface", "snow_surface", "elevation"};
const char *const ColorChoices[] = {"water_depth", "snow_depth", "cover_class", "shadow",
                                    "elevation"};

// The stride that draws at most `most` points of an nx x ny grid (every
// point for 0, or when they are no more).
int SurfaceStride(int nx, int ny, vtkIdType most) {
  const double points = static_cast<double>(nx) * ny;
  if (most <= 0 || points <= static_cast<double>(most)) {
    return 1;
  }
  int stride = static_cast<int>(std::ceil(std::sqrt(points / static_cast<double>(most))));
  auto drawn = [&](int k) {
    return (static_cast<double>((nx - 1 + k - 1) / k) + 1.0) *
           (static_cast<double>((ny - 1 + k - 1) / k) + 1.0);
  };
  while (drawn(stride) > static_cast<double>(most)) {
    ++stride;
  }
  return stride;
}

// 0, stride, 2 stride, ... and n - 1: the drawn indices along one axis.
std::vector<int> Samples(int n, int stride) {
  std::vector<int> at;
  for (int k = 0; k < n - 1; k += stride) {
    at.push_back(k);
  }
  at.push_back(n - 1);
  return at;
}

vtkPointData *InputPointData(vtkDataObject *input) {
  auto *image = vtkImageData::SafeDownCast(input);
  return image ? image->GetPointData() : nullptr;
}

template <size_t N>
const char *Choose(vtkDataObject *input, const std::string &wanted, const char *const (&list)[N]) {
  vtkPointData *pd = InputPointData(input);
  if (!pd) {
    return nullptr;
  }
  if (!wanted.empty()) {
    vtkDataArray *a = pd->GetArray(wanted.c_str());
    return a ? a->GetName() : nullptr;
  }
  for (const char *name : list) {
    if (vtkDataArray *a = pd->GetArray(name)) {
      if (a->GetNumberOfComponents() == 1) {
        return a->GetName();
      }
    }
  }
  return nullptr;
}
} // namespace

void vtkTerrainSurfaceFilter::SetHeightArray(const char *name) {
  std::string value = name ? name : "";
  if (value != this->HeightArray) {
    this->HeightArray = value;
    this->Modified();
  }
}

void vtkTerrainSurfaceFilter::SetColorArray(const char *name) {
  std::string value = name ? name : "";
  if (value != this->ColorArray) {
    this->ColorArray = value;
    this->Modified();
  }
}

const char *vtkTerrainSurfaceFilter::ChooseHeightArray(vtkDataObject *input,
                                                       const std::string &wanted) {
  return Choose(input, wanted, HeightChoices);
}

const char *vtkTerrainSurfaceFilter::ChooseColorArray(vtkDataObject *input,
                                                      const std::string &wanted) {
  return Choose(input, wanted, ColorChoices);
}

int vtkTerrainSurfaceFilter::FillInputPortInformation(int, vtkInformation *info) {
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkImageData");
  return 1;
}

int vtkTerrainSurfaceFilter::RequestUpdateExtent(vtkInformation *,
                                                 vtkInformationVector **inputVector,
                                                 vtkInformationVector *) {
  // The whole field: the normals of the edge points need their neighbours.
  vtkInformation *inInfo = inputVector[0]->GetInformationObject(0);
  if (inInfo) {
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER(), 0);
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES(), 1);
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS(), 0);
    if (inInfo->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT())) {
      inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(),
                  inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()), 6);
    }
  }
  return 1;
}

int vtkTerrainSurfaceFilter::RequestData(vtkInformation *, vtkInformationVector **inputVector,
                                         vtkInformationVector *outputVector) {
  vtkImageData *input = vtkImageData::GetData(inputVector[0]);
  vtkPolyData *output = vtkPolyData::GetData(outputVector);
  if (!input || !output) {
    return 1;
  }
  if (this->GetAbortExecute()) {
    // Aborted while the Render that asked for it lasts (see ConsumeAbort).
    output->Initialize();
    this->ConsumeAbort();
    return 1;
  }
  int dims[3];
  input->GetDimensions(dims);
  if (input->GetNumberOfPoints() == 0) {
    return 1; // an empty upstream (its own error already said why)
  }
  if (dims[2] != 1 || dims[0] < 2 || dims[1] < 2) {
    vtkErrorMacro("Terrain Surface: the input image has " << dims[0] << " x " << dims[1] << " x "
                                                          << dims[2]
                                                          << " points; it needs a 2-D height "
                                                             "field of at least 2 x 2 x 1.");
    return 1;
  }
  const char *heightName = ChooseHeightArray(input, this->HeightArray);
  if (!heightName) {
    if (this->HeightArray.empty()) {
      vtkErrorMacro("Terrain Surface: the input has no point array water_surface, snow_surface "
                    "or elevation; set Height Array to the array of heights.");
    } else {
      vtkErrorMacro("Terrain Surface: the input has no point array '"
                    << this->HeightArray
                    << "' (Height Array); name one of its point arrays or leave it empty.");
    }
    return 1;
  }
  vtkDataArray *height = input->GetPointData()->GetArray(heightName);
  const int nx = dims[0], ny = dims[1];
  // The points drawn: every stride-th row and column and the last ones, so
  // that the surface keeps the terrain's extent with at most MaximumPoints.
  const int stride = SurfaceStride(nx, ny, this->MaximumPoints);
  const std::vector<int> xs = Samples(nx, stride), ys = Samples(ny, stride);
  const int mx = static_cast<int>(xs.size()), my = static_cast<int>(ys.size());
  const vtkIdType n = static_cast<vtkIdType>(mx) * my;
  auto source = [&](int a, int b) { return xs[a] + static_cast<vtkIdType>(ys[b]) * nx; };
  // Host memory only: a point's position (3 doubles) and normal (3 floats),
  // its quad's offset and four point ids, a copy of every input point array
  // and the water's display copy. Refused before anything is allocated: a
  // terrain of 20000 x 20000 points would take 34 GB.
  gr_memory_need need = {};
  need.points = static_cast<double>(n);
  double perPoint = 3 * sizeof(double) + 3 * sizeof(float) + 5 * sizeof(vtkIdType) + sizeof(float);
  vtkPointData *inArrays = input->GetPointData();
  for (int a = 0; a < inArrays->GetNumberOfArrays(); ++a) {
    if (vtkAbstractArray *array = inArrays->GetAbstractArray(a)) {
      perPoint += static_cast<double>(array->GetDataTypeSize()) * array->GetNumberOfComponents();
    }
  }
  need.host = need.points * perPoint;
  const std::string refusal = graupel::MemoryRefusal(
      nullptr, "Terrain Surface", graupel::GridSubject(nx, ny, "terrain"), need,
      "resample the terrain to fewer points first (Resample To Image) or show its image instead");
  if (!refusal.empty()) {
    vtkErrorMacro(<< refusal);
    return 1;
  }
  std::string text =
      "Terrain Surface: " + std::to_string(nx) + " x " + std::to_string(ny) + " points";
  if (stride > 1) {
    text += ", every " + std::to_string(stride) + "th drawn";
  }
  this->SetProgressText(text.c_str());
  this->UpdateProgress(0.0);
  // NaN heights are no-data points (a raster's no-data, Rain Runoff outside
  // its domain): no quad or wall touches them. An infinity is an error.
  double lowest = VTK_DOUBLE_MAX;
  for (int b = 0; b < my; ++b) {
    for (int a = 0; a < mx; ++a) {
      const vtkIdType id = source(a, b);
      const double h = height->GetComponent(id, 0);
      if (std::isinf(h)) {
        vtkErrorMacro("Terrain Surface: the height array " << heightName << " is " << h
                                                           << " at point " << id
                                                           << "; fill the holes first.");
        return 1;
      }
      if (!std::isnan(h)) {
        lowest = std::min(lowest, h);
      }
    }
  }
  if (lowest == VTK_DOUBLE_MAX) {
    vtkErrorMacro("Terrain Surface: the height array " << heightName
                                                       << " has no value at all (every point is"
                                                          " NaN, no data).");
    return 1;
  }

  const double s = this->VerticalExaggeration;
  double spacing[3];
  input->GetSpacing(spacing);
  const bool skirt = this->Skirt;
  // Each wall has its own copies of the edge points: a crisp edge between
  // the lit top and the walls, whose normals point outwards.
  const vtkIdType wallPoints = skirt ? 4 * (mx + my) : 0;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(n + wallPoints);
  vtkNew<vtkFloatArray> normals;
  normals->SetName("Normals");
  normals->SetNumberOfComponents(3);
  normals->SetNumberOfTuples(n + wallPoints);
  vtkPointData *inPD = input->GetPointData();
  vtkPointData *outPD = output->GetPointData();
  outPD->CopyAllocate(inPD, n + wallPoints);

  auto z = [&](int a, int b) { return s * height->GetComponent(source(a, b), 0); };
  auto hole = [&](int a, int b) { return std::isnan(height->GetComponent(source(a, b), 0)); };
  // Progress every band of rows (about a million points) and the abort
  // looked at there: a large terrain takes seconds.
  const int band = std::max(1, (1 << 20) / mx);
  auto aborted = [&](int row, double share, double done) {
    if (row % band != 0) {
      return false;
    }
    this->UpdateProgress(done + share * row / my);
    if (!this->GetAbortExecute()) {
      return false;
    }
    output->Initialize();
    vtkWarningMacro("Terrain Surface: the update was aborted; the output is empty.");
    this->ConsumeAbort();
    return true;
  };
  double p[3];
  for (int j = 0; j < my; ++j) {
    if (aborted(j, 0.7, 0.0)) {
      return 1;
    }
    for (int i = 0; i < mx; ++i) {
      const vtkIdType id = i + static_cast<vtkIdType>(j) * mx;
      input->GetPoint(source(i, j), p);
      // A no-data point stays at the lowest height: drawn by no quad, it
      // keeps the bounds those of the data.
      p[2] += hole(i, j) ? s * lowest : z(i, j);
      points->SetPoint(id, p);
      // Central differences inside, one-sided on the edges and beside
      // no-data points: a one-sided normal is the slope of its cell, not
      // half of it.
      const bool here = !hole(i, j);
      const int i0 = i > 0 && here && !hole(i - 1, j) ? i - 1 : i;
      const int i1 = i < mx - 1 && here && !hole(i + 1, j) ? i + 1 : i;
      const int j0 = j > 0 && here && !hole(i, j - 1) ? j - 1 : j;
      const int j1 = j < my - 1 && here && !hole(i, j + 1) ? j + 1 : j;
      const double gx = i1 > i0 ? (z(i1, j) - z(i0, j)) / ((xs[i1] - xs[i0]) * spacing[0]) : 0.0;
      const double gy = j1 > j0 ? (z(i, j1) - z(i, j0)) / ((ys[j1] - ys[j0]) * spacing[1]) : 0.0;
      const double len = std::sqrt(gx * gx + gy * gy + 1.0);
      normals->SetTuple3(id, -gx / len, -gy / len, 1.0 / len);
      outPD->CopyData(inPD, source(i, j), id);
    }
  }

  // At most this many: quads touching a no-data point are left out.
  const vtkIdType quads =
      static_cast<vtkIdType>(mx - 1) * (my - 1) + (skirt ? 2 * (mx + my - 2) : 0);
  vtkNew<vtkIdTypeArray> offsets, conn;
  offsets->SetNumberOfValues(quads + 1);
  conn->SetNumberOfValues(4 * quads);
  vtkIdType q = 0;
  auto quad = [&](vtkIdType a, vtkIdType b, vtkIdType c, vtkIdType d) {
    offsets->SetValue(q, 4 * q);
    conn->SetValue(4 * q, a);
    conn->SetValue(4 * q + 1, b);
    conn->SetValue(4 * q + 2, c);
    conn->SetValue(4 * q + 3, d);
    ++q;
  };
  for (int j = 0; j + 1 < my; ++j) {
    if (aborted(j, 0.3, 0.7)) {
      return 1;
    }
    for (int i = 0; i + 1 < mx; ++i) {
      if (hole(i, j) || hole(i + 1, j) || hole(i, j + 1) || hole(i + 1, j + 1)) {
        continue;
      }
      const vtkIdType a = i + static_cast<vtkIdType>(j) * mx;
      quad(a, a + 1, a + 1 + mx, a + mx); // counter-clockwise seen from above
    }
  }

  if (skirt) {
    // The edges walked counter-clockwise seen from above: south, east,
    // north, west. The outward normal is the walking direction x z.
    struct Edge {
      int i0, j0, di, dj, count;
    };
    const Edge edges[4] = {{0, 0, 1, 0, mx},
                           {mx - 1, 0, 0, 1, my},
                           {mx - 1, my - 1, -1, 0, mx},
                           {0, my - 1, 0, -1, my}};
    input->GetPoint(0, p);
    const double base = p[2] + s * (lowest - this->SkirtDepth);
    vtkIdType next = n;
    for (const Edge &e : edges) {
      const double nxw = e.dj, nyw = -e.di;
      for (int k = 0; k < e.count; ++k) {
        const int a = e.i0 + k * e.di, b = e.j0 + k * e.dj;
        const vtkIdType drawn = a + static_cast<vtkIdType>(b) * mx, src = source(a, b);
        const vtkIdType top = next + 2 * k, bottom = top + 1;
        points->GetPoint(drawn, p);
        points->SetPoint(top, p);
        p[2] = base;
        points->SetPoint(bottom, p);
        normals->SetTuple3(top, nxw, nyw, 0.0);
        normals->SetTuple3(bottom, nxw, nyw, 0.0);
        outPD->CopyData(inPD, src, top);
        outPD->CopyData(inPD, src, bottom);
        if (k > 0 && !hole(a, b) && !hole(a - e.di, b - e.dj)) {
          quad(top - 2, top - 1, bottom, top);
        }
      }
      next += 2 * e.count;
    }
  }
  offsets->SetValue(q, 4 * q);
  offsets->SetNumberOfValues(q + 1);
  conn->SetNumberOfValues(4 * q);
  vtkNew<vtkCellArray> polys;
  polys->SetData(offsets, conn);

  output->SetPoints(points);
  output->SetPolys(polys);
  outPD->SetNormals(normals);
  if (const char *colour = ChooseColorArray(input, this->ColorArray)) {
    const std::string name = colour;
    if (name == "water_depth" || name == "max_depth") {
      // A log scale has no place for 0: VTK's texture colouring maps it to
      // the bottom of the range, painting dry ground as the thinnest water.
      // Dry points (under the wetting depth) become NaN, drawn in the map's
      // NaN colour (the ground's); the input's array stays as it was.
      vtkDataArray *depth = outPD->GetArray(colour);
      vtkNew<vtkFloatArray> shown;
      shown->SetName("water_depth_display");
      shown->SetNumberOfTuples(depth->GetNumberOfTuples());
      for (vtkIdType id = 0; id < depth->GetNumberOfTuples(); ++id) {
        const double d = depth->GetComponent(id, 0);
        shown->SetValue(id, d >= this->WettingDepth ? static_cast<float>(d)
                                                    : std::numeric_limits<float>::quiet_NaN());
      }
      outPD->AddArray(shown);
      outPD->SetActiveScalars("water_depth_display");
    } else {
      outPD->SetActiveScalars(colour);
    }
  }
  output->GetFieldData()->PassData(input->GetFieldData());
  vtkNew<vtkDoubleArray> factor;
  factor->SetName("vertical_exaggeration");
  factor->InsertNextValue(s);
  output->GetFieldData()->AddArray(factor);
  vtkNew<vtkIntArray> drawn;
  drawn->SetName("surface_stride");
  drawn->InsertNextValue(stride);
  output->GetFieldData()->AddArray(drawn);
  this->UpdateProgress(1.0);
  return 1;
}

void vtkTerrainSurfaceFilter::ConsumeAbort() {
  // vtkGraupelAlgorithm::AbortRequested's protocol: the abort consumed, the
  // output marked aborted, so that the executive empties it and the next
  // request builds the surface again (on VTK 9.1, Modified()).
#if GRAUPEL_VTK_ABORT_OUTPUT
  this->AbortExecute = 0;
  this->SetAbortOutput(true);
#else
  this->SetAbortExecute(0);
  this->Modified();
#endif
}

void vtkTerrainSurfaceFilter::PrintSelf(ostream &os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  os << indent << "VerticalExaggeration: " << this->VerticalExaggeration << "\n";
  os << indent << "HeightArray: " << this->HeightArray << "\n";
  os << indent << "ColorArray: " << this->ColorArray << "\n";
  os << indent << "Skirt: " << this->Skirt << "\n";
  os << indent << "SkirtDepth: " << this->SkirtDepth << "\n";
  os << indent << "WettingDepth: " << this->WettingDepth << "\n";
  os << indent << "MaximumPoints: " << this->MaximumPoints << "\n";
}
