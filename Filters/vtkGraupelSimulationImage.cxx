// vtkGraupelSimulation's image output: the terrain's geometry with one float
// array per core output, each read as the core's own points and, in a split
// run, assembled into the requested rows from the neighbouring ranks
// (FillImage), and the core's grid of a terrain (TerrainGrid).
#include "vtkGraupelSimulation.h"

#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include "graupel/graupel.h"

#include "GraupelPieces.h"

#include <algorithm>
#include <string>
#include <vector>

int vtkGraupelSimulation::FillImage(vtkDataObject *outputObject, vtkInformation *outInfo,
                                    const int *fields, int count,
                                    const std::function<int(int, float *)> &read,
                                    const std::function<const char *()> &detail) {
  std::vector<ImageArray> arrays;
  for (int k = 0; k < count; ++k) {
    const int field = fields[k];
    const gr_field f = static_cast<gr_field>(field);
    arrays.push_back({gr_field_name(f), gr_field_components(f),
                      [&read, field](float *values) { return read(field, values); }});
  }
  return this->FillImage(outputObject, outInfo, arrays, detail);
}

int vtkGraupelSimulation::FillImage(vtkDataObject *outputObject, vtkInformation *outInfo,
                                    const std::vector<ImageArray> &arrays,
                                    const std::function<const char *()> &detail) {
  vtkImageData *output = vtkImageData::SafeDownCast(outputObject);
  vtkImageData *input = vtkImageData::GetData(this->GetInputInformation(0, 0));
  if (!output || !input || arrays.empty()) {
    return 0;
  }
  int extent[6];
  if (outInfo && outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT())) {
    outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), extent);
  } else {
    input->GetExtent(extent);
  }
  int dims[3];
  input->GetDimensions(dims);
  const int *inExtent = input->GetExtent();
  graupel::Pieces &pieces = *this->PieceLayout;
  // The core's own points: the whole grid, or a split run's own rows.
  const int ownRows = pieces.IsSplit() ? pieces.GetOwnRows() : dims[1];
  const vtkIdType n = static_cast<vtkIdType>(dims[0]) * ownRows;
  // The rows handed out: the whole grid's, or the requested rows (some of
  // them a neighbouring rank's) of a split run. Cropped to the request below.
  int rows[2] = {inExtent[2], inExtent[3]};
  if (pieces.IsSplit()) {
    rows[0] = extent[2];
    rows[1] = extent[3];
  }
  vtkNew<vtkImageData> whole;
  whole->SetExtent(inExtent[0], inExtent[1], rows[0], rows[1], inExtent[4], inExtent[5]);
  whole->SetOrigin(input->GetOrigin());
  whole->SetSpacing(input->GetSpacing());
  const vtkIdType handedOut = static_cast<vtkIdType>(dims[0]) * (rows[1] - rows[0] + 1);
  const std::string label = this->GetSimulationLabel();
  std::vector<float> assembled;
  for (const ImageArray &array : arrays) {
    const int components = array.components;
    vtkNew<vtkFloatArray> a;
    a->SetName(array.name.c_str());
    a->SetNumberOfComponents(components);
    if (components < 1 || !a->Allocate(std::max(n, handedOut) * components)) {
      vtkErrorMacro(<< label << ": out of host memory for the output fields.");
      return 0;
    }
    a->SetNumberOfTuples(n);
    const int st = array.read(a->GetPointer(0));
    if (st != GR_OK) {
      return this->ReportFailure(st, (label + " could not read its fields back").c_str(), detail());
    }
    if (pieces.IsSplit()) {
      std::string why;
      if (!pieces.Rows(a->GetPointer(0), dims[0], components, rows[0] - inExtent[2],
                       rows[1] - inExtent[2], assembled, why)) {
        vtkErrorMacro(<< label << " could not assemble its piece from the neighbouring ranks: "
                      << why << ".");
        return 0;
      }
      a->SetNumberOfTuples(static_cast<vtkIdType>(assembled.size()) / components);
      std::copy(assembled.begin(), assembled.end(), a->GetPointer(0));
    }
    whole->GetPointData()->AddArray(a);
  }
  whole->GetPointData()->SetActiveScalars(arrays.front().name.c_str());
  output->ShallowCopy(whole);
  output->Crop(extent);
  if (this->PieceRing > 0) {
    // What this rank simulated, ring included: the split a user can see.
    vtkNew<vtkDoubleArray> cells;
    cells->SetName("piece_cells");
    cells->InsertNextValue(static_cast<double>(
        pieces.IsSplit() ? pieces.GetPieceCells() : static_cast<vtkIdType>(dims[0]) * dims[1]));
    output->GetFieldData()->AddArray(cells);
  }
  return 1;
}

void vtkGraupelSimulation::TerrainGrid(vtkImageData *terrain, gr_grid *grid) {
  *grid = gr_grid{};
  int dims[3];
  terrain->GetDimensions(dims);
  grid->nx = dims[0];
  grid->ny = dims[1];
  grid->dx = terrain->GetSpacing()[0];
  grid->dy = terrain->GetSpacing()[1];
  grid->x0 = terrain->GetOrigin()[0];
  grid->y0 = terrain->GetOrigin()[1];
}
