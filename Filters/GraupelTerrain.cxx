#include "GraupelTerrain.h"

#include "graupel/raster_io.h"

#include "vtkAlgorithm.h"
#include "vtkAlgorithmOutput.h"
#include "vtkCellData.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStringArray.h"
#include "vtkUnsignedCharArray.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>

namespace graupel {

namespace {

bool OneComponent(vtkDataArray *a) {
  return a && a->GetNumberOfComponents() == 1 && a->GetName() &&
         std::strncmp(a->GetName(), "vtk", 3) != 0;
}

// The only one-component array of attrs that is not VTK's own, or nullptr.
vtkDataArray *OnlyScalar(vtkDataSetAttributes *attrs) {
  vtkDataArray *only = nullptr;
  for (int k = 0; k < attrs->GetNumberOfArrays(); ++k) {
    vtkDataArray *a = attrs->GetArray(k);
    if (OneComponent(a)) {
      if (only) {
        return nullptr;
      }
      only = a;
    }
  }
  return only;
}

// The CRS ParaView's GDAL reader keeps, when Graupel's own is absent.
std::string ForeignCrs(vtkDataObject *data) {
  vtkFieldData *fd = data ? data->GetFieldData() : nullptr;
  if (!fd || fd->GetAbstractArray("graupel_crs")) {
    return std::string();
  }
  auto *mp = vtkStringArray::SafeDownCast(fd->GetAbstractArray("MAP_PROJECTION"));
  return mp && mp->GetNumberOfValues() > 0 ? mp->GetValue(0) : std::string();
}

// Metres per unit of a foreign CRS (1 without one); false with a sentence
// part in *why when it is in degrees or unreadable.
bool ForeignUnits(vtkDataObject *data, double *unit, std::string *wkt, std::string *why) {
  *unit = 1.0;
  const std::string crs = ForeignCrs(data);
  if (crs.empty()) {
    return true;
  }
  gr_raster_crs c;
  char err[512] = "";
  if (gr_raster_crs_describe(crs.c_str(), &c, err, sizeof err) != GR_OK) {
    *why = "has a coordinate reference system GDAL cannot read, so its units are not known (" +
           std::string(err) + ")";
    return false;
  }
  const bool ok = !c.geographic;
  if (!ok) {
    *why = "is in geographic coordinates (" + crs +
           "): its spacing is in degrees, not metres. Open the file with Graupel's GIS "
           "Raster Reader, which reprojects it to the UTM zone of its centre, or reproject "
           "it first (gdalwarp -t_srs with a projected CRS in metres)";
  }
  *unit = c.metres_per_unit;
  if (wkt) {
    *wkt = c.wkt ? c.wkt : "";
  }
  gr_raster_crs_free(&c);
  return ok;
}

} // namespace

HeightsChoice ChosenHeights(vtkAlgorithm *alg) {
  HeightsChoice c;
  // Read without creating: vtkAlgorithm::GetInputArrayInformation makes the
  // entry (and modifies the algorithm) when there is none.
  vtkInformationVector *arrays =
      alg ? alg->GetInformation()->Get(vtkAlgorithm::INPUT_ARRAYS_TO_PROCESS()) : nullptr;
  vtkInformation *info = arrays && arrays->GetNumberOfInformationObjects() > 0
                             ? arrays->GetInformationObject(0)
                             : nullptr;
  if (info && info->Has(vtkDataObject::FIELD_NAME())) {
    const char *name = info->Get(vtkDataObject::FIELD_NAME());
    c.name = name ? name : "";
  }
  if (!c.name.empty() && info->Has(vtkDataObject::FIELD_ASSOCIATION())) {
    const int a = info->Get(vtkDataObject::FIELD_ASSOCIATION());
    if (a == vtkDataObject::FIELD_ASSOCIATION_POINTS ||
        a == vtkDataObject::FIELD_ASSOCIATION_CELLS) {
      c.association = a;
    } else if (a != vtkDataObject::FIELD_ASSOCIATION_POINTS_THEN_CELLS) {
      c = HeightsChoice(); // a table's column or field data: not heights
    }
  }
  return c;
}

HeightsChoice EffectiveHeights(vtkDataSet *data, const HeightsChoice &choice, bool *replaced) {
  *replaced = false;
  if (choice.name.empty() || choice.name == "elevation" || !data ||
      (data->GetPointData()->GetNumberOfArrays() == 0 &&
       data->GetCellData()->GetNumberOfArrays() == 0)) {
    return choice;
  }
  int association = 0;
  if (FindHeights(data, choice, &association, nullptr)) {
    return choice;
  }
  *replaced = true;
  return HeightsChoice();
}

vtkDataArray *FindHeights(vtkDataSet *data, const HeightsChoice &choice, int *association,
                          std::string *why) {
  const int P = vtkDataObject::FIELD_ASSOCIATION_POINTS, C = vtkDataObject::FIELD_ASSOCIATION_CELLS;
  if (!data) {
    if (why) {
      *why = "has no data";
    }
    return nullptr;
  }
  vtkPointData *pd = data->GetPointData();
  vtkCellData *cd = data->GetCellData();
  auto found = [&](vtkDataArray *a, int assoc) {
    *association = assoc;
    return a;
  };
  if (!choice.name.empty() && choice.name != "elevation") {
    const char *n = choice.name.c_str();
    if (choice.association != C && OneComponent(pd->GetArray(n))) {
      return found(pd->GetArray(n), P);
    }
    if (choice.association != P && OneComponent(cd->GetArray(n))) {
      return found(cd->GetArray(n), C);
    }
    if (why) {
      *why = "has no one-component " +
             std::string(choice.association == C   ? "cell "
                         : choice.association == P ? "point "
                                                   : "") +
             "array '" + choice.name + "' (its Height Array)";
    }
    return nullptr;
  }
  vtkDataArray *a = nullptr;
  if (OneComponent(a = pd->GetArray("elevation"))) {
    return found(a, P);
  }
  if (OneComponent(a = cd->GetArray("elevation"))) {
    return found(a, C);
  }
  if (OneComponent(a = pd->GetScalars()) || (a = OnlyScalar(pd))) {
    return found(a, P);
  }
  if (OneComponent(a = cd->GetScalars()) || (a = OnlyScalar(cd))) {
    return found(a, C);
  }
  if (why) {
    *why = "has no array 'elevation' (point or cell data), nor active or single scalars to "
           "take as heights";
  }
  return nullptr;
}

bool HeightsAreCells(vtkAlgorithm *alg, int port) {
  if (!alg || port < 0 || port >= alg->GetNumberOfInputPorts() ||
      alg->GetNumberOfInputConnections(port) < 1) {
    return false;
  }
  const HeightsChoice chosen = ChosenHeights(alg);
  auto *in = vtkDataSet::SafeDownCast(alg->GetInputDataObject(port, 0));
  const bool empty = !in || (in->GetPointData()->GetNumberOfArrays() == 0 &&
                             in->GetCellData()->GetNumberOfArrays() == 0);
  vtkInformation *inInfo = alg->GetInputInformation(port, 0);
  const bool temporal = inInfo && inInfo->Has(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
  // A producer that announces its active scalars as point data (Graupel's
  // sources and readers, vtkDataObject::SetPointDataActiveScalarInfo) and
  // none as cell data gives point heights: nothing to run to find out.
  const bool announcedPoints =
      inInfo &&
      vtkDataObject::GetActiveFieldInformation(inInfo, vtkDataObject::FIELD_ASSOCIATION_POINTS,
                                               vtkDataSetAttributes::SCALARS) &&
      !vtkDataObject::GetActiveFieldInformation(inInfo, vtkDataObject::FIELD_ASSOCIATION_CELLS,
                                                vtkDataSetAttributes::SCALARS);
  if (empty && announcedPoints) {
    return chosen.association == vtkDataObject::FIELD_ASSOCIATION_CELLS;
  }
  if (empty && chosen.association < 0 && !temporal) {
    // A first update: the input has not run yet, so what its arrays are is
    // not known before it does. Run it now, once (not a series in time,
    // whose frames the filter asks for one by one: a cell raster series
    // takes one more update, announced by RequestData).
    vtkAlgorithmOutput *conn = alg->GetInputConnection(port, 0);
    if (conn && conn->GetProducer()) {
      conn->GetProducer()->Update(conn->GetIndex());
      in = vtkDataSet::SafeDownCast(alg->GetInputDataObject(port, 0));
    }
  }
  if (!in || (in->GetPointData()->GetNumberOfArrays() == 0 &&
              in->GetCellData()->GetNumberOfArrays() == 0)) {
    return chosen.association == vtkDataObject::FIELD_ASSOCIATION_CELLS;
  }
  bool replaced = false;
  const HeightsChoice c = EffectiveHeights(in, chosen, &replaced);
  int association = vtkDataObject::FIELD_ASSOCIATION_POINTS;
  return FindHeights(in, c, &association, nullptr) &&
         association == vtkDataObject::FIELD_ASSOCIATION_CELLS;
}

void CellCentreInformation(vtkInformation *inInfo, vtkInformationVector *outInfo) {
  using SDDP = vtkStreamingDemandDrivenPipeline;
  if (!inInfo || !inInfo->Has(SDDP::WHOLE_EXTENT())) {
    return;
  }
  int in[6];
  inInfo->Get(SDDP::WHOLE_EXTENT(), in);
  double origin[3] = {0.0, 0.0, 0.0}, spacing[3] = {1.0, 1.0, 1.0};
  if (inInfo->Has(vtkDataObject::ORIGIN())) {
    inInfo->Get(vtkDataObject::ORIGIN(), origin);
  }
  if (inInfo->Has(vtkDataObject::SPACING())) {
    inInfo->Get(vtkDataObject::SPACING(), spacing);
  }
  double unit = 1.0;
  std::string why;
  ForeignUnits(vtkDataObject::GetData(inInfo), &unit, nullptr, &why);
  int cells[6] = {in[0], in[1], in[2], in[3], in[4], in[5]};
  for (int a = 0; a < 2; ++a) {
    if (cells[2 * a + 1] > cells[2 * a]) {
      --cells[2 * a + 1];
      origin[a] += 0.5 * spacing[a];
    }
  }
  for (int a = 0; a < 2; ++a) {
    origin[a] *= unit;
    spacing[a] *= unit;
  }
  for (int i = 0; i < outInfo->GetNumberOfInformationObjects(); ++i) {
    vtkInformation *info = outInfo->GetInformationObject(i);
    if (!info->Has(SDDP::WHOLE_EXTENT())) {
      continue;
    }
    int out[6];
    info->Get(SDDP::WHOLE_EXTENT(), out);
    if (std::memcmp(out, in, sizeof in) != 0) {
      continue;
    }
    info->Set(SDDP::WHOLE_EXTENT(), cells, 6);
    info->Set(vtkDataObject::ORIGIN(), origin, 3);
    info->Set(vtkDataObject::SPACING(), spacing, 3);
  }
}

namespace {

// An image of input's structure, as cell centres when cells, in metres.
vtkSmartPointer<vtkImageData> Structure(vtkImageData *input, bool cells, double unit) {
  auto view = vtkSmartPointer<vtkImageData>::New();
  int e[6];
  input->GetExtent(e);
  double origin[3], spacing[3];
  input->GetOrigin(origin);
  input->GetSpacing(spacing);
  for (int a = 0; cells && a < 2; ++a) {
    if (e[2 * a + 1] > e[2 * a]) {
      --e[2 * a + 1];
      origin[a] += 0.5 * spacing[a];
    }
  }
  for (int a = 0; a < 2; ++a) {
    origin[a] *= unit;
    spacing[a] *= unit;
  }
  view->SetExtent(e);
  view->SetOrigin(origin);
  view->SetSpacing(spacing);
  return view;
}

// Every array of from except VTK's ghosts and `except`, by reference.
void PassArrays(vtkDataSetAttributes *from, vtkDataSetAttributes *to, const char *except) {
  for (int k = 0; k < from->GetNumberOfArrays(); ++k) {
    vtkAbstractArray *a = from->GetAbstractArray(k);
    const char *name = a ? a->GetName() : nullptr;
    if (!name || std::strcmp(name, vtkDataSetAttributes::GhostArrayName()) == 0 ||
        (except && std::strcmp(name, except) == 0)) {
      continue;
    }
    to->AddArray(a);
  }
}

} // namespace

vtkImageData *TerrainView::Get(vtkImageData *input, const HeightsChoice &choice,
                               const std::string &label, const char *inputName,
                               std::string *error) {
  int association = vtkDataObject::FIELD_ASSOCIATION_POINTS;
  vtkDataArray *heights = FindHeights(input, choice, &association, nullptr);
  if (!heights) {
    return input;
  }
  // The same input (object and time) and heights: the view built for them.
  std::ostringstream key;
  key << heights->GetName() << ' ' << association;
  if (this->View && this->Source == input && this->SourceTime == input->GetMTime() &&
      this->Key == key.str()) {
    return this->View;
  }
  double unit = 1.0;
  std::string wkt, why;
  if (!ForeignUnits(input, &unit, &wkt, &why)) {
    *error = label + "'s " + inputName + " " + why + ".";
    return nullptr;
  }
  const bool cells = association == vtkDataObject::FIELD_ASSOCIATION_CELLS;
  vtkUnsignedCharArray *ghosts = cells ? input->GetCellGhostArray() : input->GetPointGhostArray();
  const unsigned char hidden = cells
                                   ? static_cast<unsigned char>(vtkDataSetAttributes::HIDDENCELL)
                                   : static_cast<unsigned char>(vtkDataSetAttributes::HIDDENPOINT);
  auto *noDataArray =
      vtkDoubleArray::SafeDownCast(input->GetFieldData()->GetArray("NO_DATA_VALUE"));
  const double noData = noDataArray && noDataArray->GetNumberOfTuples() > 0
                            ? noDataArray->GetValue(0)
                            : std::numeric_limits<double>::quiet_NaN();
  if (!cells && !ghosts && unit == 1.0 && wkt.empty() && !std::isfinite(noData)) {
    return input; // point heights as they are: the filter reads the chosen array itself
  }
  vtkSmartPointer<vtkImageData> view = Structure(input, cells, unit);
  PassArrays(cells ? static_cast<vtkDataSetAttributes *>(input->GetCellData())
                   : input->GetPointData(),
             view->GetPointData(), "elevation");
  if (!cells) {
    PassArrays(input->GetCellData(), view->GetCellData(), nullptr);
  }
  const vtkIdType n = heights->GetNumberOfTuples();
  vtkNew<vtkFloatArray> elevation;
  elevation->SetName("elevation");
  elevation->SetNumberOfTuples(n);
  float *z = elevation->GetPointer(0);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (vtkIdType i = 0; i < n; ++i) {
    const double v = heights->GetComponent(i, 0);
    const bool none =
        (ghosts && (ghosts->GetValue(i) & hidden)) || (std::isfinite(noData) && v == noData);
    z[i] = none ? nan : static_cast<float>(v);
  }
  view->GetPointData()->AddArray(elevation);
  view->GetPointData()->SetActiveScalars("elevation");
  view->GetFieldData()->ShallowCopy(input->GetFieldData());
  if (!wkt.empty()) {
    vtkNew<vtkStringArray> crs;
    crs->SetName("graupel_crs");
    crs->InsertNextValue(wkt);
    view->GetFieldData()->AddArray(crs);
  }
  this->View = view;
  this->Source = input;
  this->SourceTime = input->GetMTime();
  this->Key = key.str();
  return view;
}

vtkImageData *TerrainView::Other(vtkImageData *input, const int terrainDims[3]) {
  int dims[3];
  input->GetDimensions(dims);
  if (dims[0] != terrainDims[0] || dims[1] != terrainDims[1] ||
      input->GetCellData()->GetNumberOfArrays() == 0) {
    return input;
  }
  if (this->View && this->Source == input && this->SourceTime == input->GetMTime() &&
      this->Key == "other") {
    return this->View;
  }
  double unit = 1.0;
  std::string why;
  ForeignUnits(input, &unit, nullptr, &why);
  vtkSmartPointer<vtkImageData> view = Structure(input, true, unit);
  PassArrays(input->GetCellData(), view->GetPointData(), nullptr);
  view->GetFieldData()->ShallowCopy(input->GetFieldData());
  this->View = view;
  this->Source = input;
  this->SourceTime = input->GetMTime();
  this->Key = "other";
  return view;
}

void TerrainView::Clear() {
  this->View = nullptr;
  this->Source = nullptr;
  this->SourceTime = 0;
  this->Key.clear();
}

std::string NoHeightsSentence(const std::string &label, const char *inputName,
                              const std::string &why) {
  return label + "'s " + inputName + " " + why +
         "; choose the array of heights (m) as its Height Array, or name it elevation (e.g. "
         "with a Calculator whose Result Array Name is elevation).";
}

} // namespace graupel
