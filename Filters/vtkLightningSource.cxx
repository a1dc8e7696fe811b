#include "vtkLightningSource.h"

#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkDataSet.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include "graupel/sky.h"

#include "GraupelMemory.h"
#include "GraupelParameterTable.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkLightningSource);

GRAUPEL_TABLE_SETTER(vtkLightningSource, ControlPoints, int, gr_sky_param_bounds)
GRAUPEL_TABLE_SETTER(vtkLightningSource, Strands, int, gr_sky_param_bounds)
GRAUPEL_TABLE_SETTER(vtkLightningSource, Jitter, double, gr_sky_param_bounds)
GRAUPEL_TABLE_SETTER(vtkLightningSource, FlickerRate, double, gr_sky_param_bounds)

vtkLightningSource::vtkLightningSource() {
  this->SetNumberOfInputPorts(1);
  gr_lightning_params p;
  gr_lightning_params_init(&p);
  this->ControlPoints = p.control_points;
  this->Strands = p.strands;
  this->Jitter = p.jitter;
  this->Seed = p.seed;
  this->Variant = p.variant;
  this->FlickerRate = p.flicker_rate;
  std::copy(p.start, p.start + 3, this->Start);
  std::copy(p.end, p.end + 3, this->End);
}

int vtkLightningSource::FillInputPortInformation(int, vtkInformation *info) {
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkDataSet");
  info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
  return 1;
}

int vtkLightningSource::FillOutputPortInformation(int, vtkInformation *info) {
  info->Set(vtkDataObject::DATA_TYPE_NAME(), "vtkPolyData");
  return 1;
}

int vtkLightningSource::RequestInformation(vtkInformation *, vtkInformationVector **,
                                           vtkInformationVector *outputVector) {
  vtkInformation *outInfo = outputVector->GetInformationObject(0);
  // A flickering bolt depends on time: the pipeline re-executes for a new
  // time only when the source advertises times.
  outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
  outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_RANGE());
  if (this->FlickerRate > 0.0) {
    if (!(this->Duration >= 0.0) || !std::isfinite(this->Duration)) {
      vtkErrorMacro("Lightning: Duration is " << this->Duration
                                              << " s but must be finite and at least 0.");
      return 0;
    }
    double range[2] = {0.0, this->Duration};
    outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), range, 2);
  }
  return 1;
}

int vtkLightningSource::RequestData(vtkInformation *, vtkInformationVector **inputVector,
                                    vtkInformationVector *outputVector) {
  vtkInformation *outInfo = outputVector->GetInformationObject(0);
  vtkPolyData *output = vtkPolyData::GetData(outInfo);
  output->Initialize();
  const double t = outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP())
                       ? outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP())
                       : 0.0;
  gr_lightning_params p;
  gr_lightning_params_init(&p);
  p.control_points = this->ControlPoints;
  p.strands = this->Strands;
  p.jitter = this->Jitter;
  p.seed = this->Seed;
  p.variant = this->Variant;
  p.flicker_rate = this->FlickerRate;
  p.time = t;
  const int shape = gr_lightning_shape(&p);
  std::copy(this->Start, this->Start + 3, p.start);
  std::copy(this->End, this->End + 3, p.end);

  vtkDataSet *terrain =
      this->GetNumberOfInputConnections(0) > 0 ? vtkDataSet::GetData(inputVector[0], 0) : nullptr;
  if (terrain) {
    const vtkIdType n = terrain->GetNumberOfPoints();
    if (n < 1) {
      vtkErrorMacro("Lightning: the terrain input has no points; connect a terrain with points, "
                    "or disconnect it to strike at End.");
      return 0;
    }
    double bounds[6];
    terrain->GetBounds(bounds);
    // A flat image with `elevation` (Procedural Terrain, the EXR reader)
    // stands for the surface z + elevation.
    vtkImageData *image = vtkImageData::SafeDownCast(terrain);
    vtkDataArray *elevation = image ? this->TerrainHeights(image) // the Height Array
                                    : terrain->GetPointData()->GetArray("elevation");
    const bool lifted = elevation && elevation->GetNumberOfComponents() == 1 &&
                        bounds[5] == bounds[4] && vtkImageData::SafeDownCast(terrain);
    const vtkIdType k = static_cast<vtkIdType>(
        gr_lightning_strike_index(this->Seed, this->Variant, static_cast<long>(n)));
    terrain->GetPoint(k, p.end);
    if (lifted) {
      double range[2];
      elevation->GetRange(range, 0);
      const double z = elevation->GetComponent(k, 0);
      if (!std::isfinite(z) || !std::isfinite(range[0]) || !std::isfinite(range[1])) {
        vtkErrorMacro("Lightning: the terrain's `elevation` holds NaN or infinite values; fix "
                      "the terrain before striking it.");
        return 0;
      }
      p.end[2] += z;
      bounds[4] += range[0];
      bounds[5] += range[1];
    }
    gr_lightning_start_over(this->Seed, shape, bounds, p.end, p.start);
  }

  char msg[256];
  if (gr_lightning_params_validate(&p, msg, sizeof(msg)) != GR_OK) {
    vtkErrorMacro("Lightning: " << msg);
    return 0;
  }
  const long npoints = gr_lightning_point_count(&p);
  // Host memory only (the bolt is made on the host): per point its position
  // (3 doubles), intensity, strand and connectivity; at most 510 050 points.
  gr_memory_need need = {};
  need.points = static_cast<double>(npoints);
  need.host = need.points * (3 * sizeof(double) + sizeof(float) + sizeof(int) + sizeof(vtkIdType));
  if (!this->ReportError(graupel::MemoryRefusal(nullptr, "Lightning",
                                                "a bolt of " + std::to_string(npoints) + " points",
                                                need, "lower ControlPoints or Strands"))) {
    return 0;
  }
  vtkNew<vtkDoubleArray> xyz;
  xyz->SetNumberOfComponents(3);
  xyz->SetNumberOfTuples(npoints);
  vtkNew<vtkFloatArray> intensity;
  intensity->SetName("intensity");
  intensity->SetNumberOfTuples(npoints);
  vtkNew<vtkIntArray> strand;
  strand->SetName("strand");
  strand->SetNumberOfTuples(npoints);
  if (gr_lightning_generate(&p, xyz->GetPointer(0), intensity->GetPointer(0), strand->GetPointer(0),
                            msg, sizeof(msg)) != GR_OK) {
    vtkErrorMacro("Lightning: " << msg);
    return 0;
  }
  vtkNew<vtkPoints> points;
  points->SetData(xyz);
  // One polyline per strand: the layout of sky.h (main strand, then each
  // branch's points in order).
  vtkNew<vtkCellArray> lines;
  const int m = gr_lightning_branch_points(p.control_points);
  std::vector<vtkIdType> ids(static_cast<size_t>(std::max(p.control_points, m)));
  for (int s = 0; s <= p.strands; ++s) {
    const vtkIdType first = s == 0 ? 0 : p.control_points + static_cast<vtkIdType>(s - 1) * m;
    const int count = s == 0 ? p.control_points : m;
    for (int j = 0; j < count; ++j) {
      ids[static_cast<size_t>(j)] = first + j;
    }
    lines->InsertNextCell(count, ids.data());
  }
  output->SetPoints(points);
  output->SetLines(lines);
  output->GetPointData()->AddArray(strand);
  output->GetPointData()->SetScalars(intensity);
  vtkNew<vtkIntArray> shapeArray;
  shapeArray->SetName("shape");
  shapeArray->InsertNextValue(shape);
  output->GetFieldData()->AddArray(shapeArray);
  output->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), t);
  return 1;
}

void vtkLightningSource::PrintSelf(ostream &os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  os << indent << "ControlPoints: " << this->ControlPoints << "\n";
  os << indent << "Strands: " << this->Strands << "\n";
  os << indent << "Jitter: " << this->Jitter << "\n";
  os << indent << "Seed: " << this->Seed << "\n";
  os << indent << "Variant: " << this->Variant << "\n";
  os << indent << "FlickerRate: " << this->FlickerRate << "\n";
  os << indent << "Duration: " << this->Duration << "\n";
  os << indent << "Start: " << this->Start[0] << " " << this->Start[1] << " " << this->Start[2]
     << "\n";
  os << indent << "End: " << this->End[0] << " " << this->End[1] << " " << this->End[2] << "\n";
}
