#include "vtkTerrainSurfaceFilter.h"
#include "GraupelTerrain.h"

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

vtkTerrainSurfaceFilter::vtkTerrainSurfaceFilter() : CellView(new graupel::TerrainView) {}

vtkTerrainSurfaceFilter::~vtkTerrainSurfaceFilter() {
  delete this->CellView;
}

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

// What RequestData's parts share: the input's height array and the points
// drawn (every stride-th row and column and the last ones).
struct vtkTerrainSurfaceFilter::Surface {
  vtkImageData *input = nullptr;
  vtkDataArray *height = nullptr;
  const char *heightName = nullptr;
  int nx = 0, ny = 0, stride = 1, mx = 0, my = 0;
  std::vector<int> xs, ys;
  vtkIdType n = 0;     // points drawn on top
  double s = 1.0;      // the vertical exaggeration
  double lowest = 0.0; // the lowest height with data
  double spacing[3] = {1.0, 1.0, 1.0};
  vtkIdType Source(int a, int b) const { return xs[a] + static_cast<vtkIdType>(ys[b]) * nx; }
  double Z(int a, int b) const { return s * height->GetComponent(Source(a, b), 0); }
  bool Hole(int a, int b) const { return std::isnan(height->GetComponent(Source(a, b), 0)); }
};

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
  // A raster's heights as cells (ParaView's GDAL Raster Reader): drawn at
  // the cells' centres, no-data cells as holes (GraupelTerrain.h).
  if (!ChooseHeightArray(input, this->HeightArray)) {
    graupel::HeightsChoice choice;
    choice.name = this->HeightArray;
    int association = 0;
    if (graupel::FindHeights(input, choice, &association, nullptr) &&
        association == vtkDataObject::FIELD_ASSOCIATION_CELLS) {
      std::string error;
      input = this->CellView->Get(input, choice, "Terrain Surface", "Input", &error);
      if (!input) {
        vtkErrorMacro(<< error);
        output->Initialize();
        return 1;
      }
    }
  }
  Surface g;
  if (!this->Prepare(input, g) || !this->Lowest(g)) {
    return 1; // said why (or an empty upstream, whose own error did)
  }
  // Each wall has its own copies of the edge points: a crisp edge between
  // the lit top and the walls, whose normals point outwards.
  const vtkIdType wallPoints = this->Skirt ? 4 * (g.mx + g.my) : 0;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(g.n + wallPoints);
  vtkNew<vtkFloatArray> normals;
  normals->SetName("Normals");
  normals->SetNumberOfComponents(3);
  normals->SetNumberOfTuples(g.n + wallPoints);
  vtkPointData *outPD = output->GetPointData();
  outPD->CopyAllocate(input->GetPointData(), g.n + wallPoints);
  vtkNew<vtkCellArray> polys;
  if (!this->TopPoints(g, points, normals, output) ||
      !this->Quads(g, points, normals, output, polys)) {
    return 1; // aborted: the output is empty
  }
  output->SetPoints(points);
  output->SetPolys(polys);
  outPD->SetNormals(normals);
  this->Colour(input, outPD);
  output->GetFieldData()->PassData(input->GetFieldData());
  vtkNew<vtkDoubleArray> factor;
  factor->SetName("vertical_exaggeration");
  factor->InsertNextValue(g.s);
  output->GetFieldData()->AddArray(factor);
  vtkNew<vtkIntArray> drawn;
  drawn->SetName("surface_stride");
  drawn->InsertNextValue(g.stride);
  output->GetFieldData()->AddArray(drawn);
  this->UpdateProgress(1.0);
  return 1;
}

bool vtkTerrainSurfaceFilter::Prepare(vtkImageData *input, Surface &g) {
  int dims[3];
  input->GetDimensions(dims);
  if (input->GetNumberOfPoints() == 0) {
    return false; // an empty upstream (its own error already said why)
  }
  if (dims[2] != 1 || dims[0] < 2 || dims[1] < 2) {
    vtkErrorMacro("Terrain Surface: the input image has " << dims[0] << " x " << dims[1] << " x "
                                                          << dims[2]
                                                          << " points; it needs a 2-D height "
                                                             "field of at least 2 x 2 x 1.");
    return false;
  }
  g.heightName = ChooseHeightArray(input, this->HeightArray);
  if (!g.heightName) {
    if (this->HeightArray.empty()) {
      vtkErrorMacro("Terrain Surface: the input has no point array water_surface, snow_surface "
                    "or elevation; set Height Array to the array of heights.");
    } else {
      vtkErrorMacro("Terrain Surface: the input has no point array '"
                    << this->HeightArray
                    << "' (Height Array); name one of its point arrays or leave it empty.");
    }
    return false;
  }
  g.input = input;
  g.height = input->GetPointData()->GetArray(g.heightName);
  g.nx = dims[0];
  g.ny = dims[1];
  g.s = this->VerticalExaggeration;
  input->GetSpacing(g.spacing);
  // The points drawn: every stride-th row and column and the last ones, so
  // that the surface keeps the terrain's extent with at most MaximumPoints.
  g.stride = SurfaceStride(g.nx, g.ny, this->MaximumPoints);
  g.xs = Samples(g.nx, g.stride);
  g.ys = Samples(g.ny, g.stride);
  g.mx = static_cast<int>(g.xs.size());
  g.my = static_cast<int>(g.ys.size());
  g.n = static_cast<vtkIdType>(g.mx) * g.my;
  // Host memory only: a point's position (3 doubles) and normal (3 floats),
  // its quad's offset and four point ids, a copy of every input point array
  // and the water's display copy. Refused before anything is allocated: a
  // terrain of 20000 x 20000 points would take 34 GB.
  gr_memory_need need = {};
  need.points = static_cast<double>(g.n);
  double perPoint = 3 * sizeof(double) + 3 * sizeof(float) + 5 * sizeof(vtkIdType) + sizeof(float);
  vtkPointData *inArrays = input->GetPointData();
  for (int a = 0; a < inArrays->GetNumberOfArrays(); ++a) {
    if (vtkAbstractArray *array = inArrays->GetAbstractArray(a)) {
      perPoint += static_cast<double>(array->GetDataTypeSize()) * array->GetNumberOfComponents();
    }
  }
  need.host = need.points * perPoint;
  const std::string refusal = graupel::MemoryRefusal(
      nullptr, "Terrain Surface", graupel::GridSubject(g.nx, g.ny, "terrain"), need,
      "resample the terrain to fewer points first (Resample To Image) or show its image instead");
  if (!refusal.empty()) {
    vtkErrorMacro(<< refusal);
    return false;
  }
  std::string text =
      "Terrain Surface: " + std::to_string(g.nx) + " x " + std::to_string(g.ny) + " points";
  if (g.stride > 1) {
    text += ", every " + std::to_string(g.stride) + "th drawn";
  }
  this->SetProgressText(text.c_str());
  this->UpdateProgress(0.0);
  return true;
}

bool vtkTerrainSurfaceFilter::Lowest(Surface &g) {
  // NaN heights are no-data points (a raster's no-data, Rain Runoff outside
  // its domain): no quad or wall touches them. An infinity is an error.
  double lowest = VTK_DOUBLE_MAX;
  for (int b = 0; b < g.my; ++b) {
    for (int a = 0; a < g.mx; ++a) {
      const vtkIdType id = g.Source(a, b);
      const double h = g.height->GetComponent(id, 0);
      if (std::isinf(h)) {
        vtkErrorMacro("Terrain Surface: the height array " << g.heightName << " is " << h
                                                           << " at point " << id
                                                           << "; fill the holes first.");
        return false;
      }
      if (!std::isnan(h)) {
        lowest = std::min(lowest, h);
      }
    }
  }
  if (lowest == VTK_DOUBLE_MAX) {
    vtkErrorMacro("Terrain Surface: the height array " << g.heightName
                                                       << " has no value at all (every point is"
                                                          " NaN, no data).");
    return false;
  }
  g.lowest = lowest;
  return true;
}

bool vtkTerrainSurfaceFilter::Aborted(vtkPolyData *output, const Surface &g, int row, double share,
                                      double done) {
  // Progress every band of rows (about a million points) and the abort
  // looked at there: a large terrain takes seconds.
  const int band = std::max(1, (1 << 20) / g.mx);
  if (row % band != 0) {
    return false;
  }
  this->UpdateProgress(done + share * row / g.my);
  if (!this->GetAbortExecute()) {
    return false;
  }
  output->Initialize();
  vtkWarningMacro("Terrain Surface: the update was aborted; the output is empty.");
  this->ConsumeAbort();
  return true;
}

bool vtkTerrainSurfaceFilter::TopPoints(const Surface &g, vtkPoints *points, vtkFloatArray *normals,
                                        vtkPolyData *output) {
  vtkPointData *inPD = g.input->GetPointData();
  vtkPointData *outPD = output->GetPointData();
  double p[3];
  for (int j = 0; j < g.my; ++j) {
    if (this->Aborted(output, g, j, 0.7, 0.0)) {
      return false;
    }
    for (int i = 0; i < g.mx; ++i) {
      const vtkIdType id = i + static_cast<vtkIdType>(j) * g.mx;
      g.input->GetPoint(g.Source(i, j), p);
      // A no-data point stays at the lowest height: drawn by no quad, it
      // keeps the bounds those of the data.
      p[2] += g.Hole(i, j) ? g.s * g.lowest : g.Z(i, j);
      points->SetPoint(id, p);
      // Central differences inside, one-sided on the edges and beside
      // no-data points: a one-sided normal is the slope of its cell, not
      // half of it.
      const bool here = !g.Hole(i, j);
      const int i0 = i > 0 && here && !g.Hole(i - 1, j) ? i - 1 : i;
      const int i1 = i < g.mx - 1 && here && !g.Hole(i + 1, j) ? i + 1 : i;
      const int j0 = j > 0 && here && !g.Hole(i, j - 1) ? j - 1 : j;
      const int j1 = j < g.my - 1 && here && !g.Hole(i, j + 1) ? j + 1 : j;
      const double gx =
          i1 > i0 ? (g.Z(i1, j) - g.Z(i0, j)) / ((g.xs[i1] - g.xs[i0]) * g.spacing[0]) : 0.0;
      const double gy =
          j1 > j0 ? (g.Z(i, j1) - g.Z(i, j0)) / ((g.ys[j1] - g.ys[j0]) * g.spacing[1]) : 0.0;
      const double len = std::sqrt(gx * gx + gy * gy + 1.0);
      normals->SetTuple3(id, -gx / len, -gy / len, 1.0 / len);
      outPD->CopyData(inPD, g.Source(i, j), id);
    }
  }
  return true;
}

bool vtkTerrainSurfaceFilter::Quads(const Surface &g, vtkPoints *points, vtkFloatArray *normals,
                                    vtkPolyData *output, vtkCellArray *polys) {
  const int mx = g.mx, my = g.my;
  // At most this many: quads touching a no-data point are left out.
  const vtkIdType quads =
      static_cast<vtkIdType>(mx - 1) * (my - 1) + (this->Skirt ? 2 * (mx + my - 2) : 0);
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
    if (this->Aborted(output, g, j, 0.3, 0.7)) {
      return false;
    }
    for (int i = 0; i + 1 < mx; ++i) {
      if (g.Hole(i, j) || g.Hole(i + 1, j) || g.Hole(i, j + 1) || g.Hole(i + 1, j + 1)) {
        continue;
      }
      const vtkIdType a = i + static_cast<vtkIdType>(j) * mx;
      quad(a, a + 1, a + 1 + mx, a + mx); // counter-clockwise seen from above
    }
  }
  if (this->Skirt) {
    // The edges walked counter-clockwise seen from above: south, east,
    // north, west. The outward normal is the walking direction x z.
    struct Edge {
      int i0, j0, di, dj, count;
    };
    const Edge edges[4] = {{0, 0, 1, 0, mx},
                           {mx - 1, 0, 0, 1, my},
                           {mx - 1, my - 1, -1, 0, mx},
                           {0, my - 1, 0, -1, my}};
    vtkPointData *inPD = g.input->GetPointData();
    vtkPointData *outPD = output->GetPointData();
    double p[3];
    g.input->GetPoint(0, p);
    const double base = p[2] + g.s * (g.lowest - this->SkirtDepth);
    vtkIdType next = g.n;
    for (const Edge &e : edges) {
      const double nxw = e.dj, nyw = -e.di;
      for (int k = 0; k < e.count; ++k) {
        const int a = e.i0 + k * e.di, b = e.j0 + k * e.dj;
        const vtkIdType drawn = a + static_cast<vtkIdType>(b) * mx, src = g.Source(a, b);
        const vtkIdType top = next + 2 * k, bottom = top + 1;
        points->GetPoint(drawn, p);
        points->SetPoint(top, p);
        p[2] = base;
        points->SetPoint(bottom, p);
        normals->SetTuple3(top, nxw, nyw, 0.0);
        normals->SetTuple3(bottom, nxw, nyw, 0.0);
        outPD->CopyData(inPD, src, top);
        outPD->CopyData(inPD, src, bottom);
        if (k > 0 && !g.Hole(a, b) && !g.Hole(a - e.di, b - e.dj)) {
          quad(top - 2, top - 1, bottom, top);
        }
      }
      next += 2 * e.count;
    }
  }
  offsets->SetValue(q, 4 * q);
  offsets->SetNumberOfValues(q + 1);
  conn->SetNumberOfValues(4 * q);
  polys->SetData(offsets, conn);
  return true;
}

void vtkTerrainSurfaceFilter::Colour(vtkImageData *input, vtkPointData *outPD) {
  const char *colour = ChooseColorArray(input, this->ColorArray);
  if (!colour) {
    return;
  }
  const std::string name = colour;
  if (name != "water_depth" && name != "max_depth") {
    outPD->SetActiveScalars(colour);
    return;
  }
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
