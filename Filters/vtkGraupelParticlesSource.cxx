#include "vtkGraupelParticlesSource.h"

#include "vtkCellArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include "graupel/particles.h"

#include "GraupelMemory.h"
#include "GraupelParameterTable.h"

#include <cmath>
#include <string>

GRAUPEL_TABLE_SETTER(vtkGraupelParticlesSource, Count, int, gr_particles_param_bounds)
GRAUPEL_TABLE_SETTER(vtkGraupelParticlesSource, Seed, int, gr_particles_param_bounds)
GRAUPEL_TABLE_SETTER(vtkGraupelParticlesSource, ExposureTime, double, gr_particles_param_bounds)

vtkGraupelParticlesSource::vtkGraupelParticlesSource() {
  gr_particles_params p;
  gr_particles_params_init(&p);
  this->Count = p.count;
  this->Seed = p.seed;
  this->ExposureTime = p.exposure_time;
  for (int c = 0; c < 6; ++c) {
    this->Region[c] = p.region[c];
  }
}

vtkGraupelParticlesSource::~vtkGraupelParticlesSource() {
  gr_particles_destroy(this->Core);
}

int vtkGraupelParticlesSource::FillInputPortInformation(int, vtkInformation *info) {
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkImageData");
  info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
  return 1;
}

int vtkGraupelParticlesSource::FillOutputPortInformation(int, vtkInformation *info) {
  info->Set(vtkDataObject::DATA_TYPE_NAME(), "vtkPolyData");
  return 1;
}

int vtkGraupelParticlesSource::RequestInformation(vtkInformation *, vtkInformationVector **,
                                                  vtkInformationVector *outputVector) {
  vtkInformation *outInfo = outputVector->GetInformationObject(0);
  if (!outInfo->Has(vtkStreamingDemandDrivenPipeline::TIME_STEPS()) &&
      !outInfo->Has(vtkStreamingDemandDrivenPipeline::TIME_RANGE())) {
    const double range[2] = {0.0, 60.0};
    outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), range, 2);
  }
  return 1;
}

int vtkGraupelParticlesSource::RequestUpdateExtent(vtkInformation *,
                                                   vtkInformationVector **inputVector,
                                                   vtkInformationVector *) {
  // The whole terrain: its bounds are the region.
  vtkInformation *inInfo = inputVector[0]->GetNumberOfInformationObjects()
                               ? inputVector[0]->GetInformationObject(0)
                               : nullptr;
  if (inInfo && inInfo->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT())) {
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(),
                inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()), 6);
  }
  return 1;
}

bool vtkGraupelParticlesSource::CoreParams(vtkImageData *terrain, gr_particles_params *p) {
  const char *label = this->GetLabel();
  gr_particles_params_init(p);
  p->count = this->Count;
  p->seed = this->Seed;
  p->exposure_time = this->ExposureTime;
  for (int c = 0; c < 3; ++c) {
    p->wind[c] = this->Wind[c];
  }
  for (int c = 0; c < 6; ++c) {
    p->region[c] = this->Region[c];
  }
  if (terrain) {
    if (terrain->GetNumberOfPoints() < 1) {
      vtkErrorMacro(<< label
                    << "'s Input is an empty image; connect a terrain with points, or "
                       "disconnect it and give the Region.");
      return false;
    }
    double b[6];
    terrain->GetBounds(b);
    double lo = b[4], hi = b[5];
    vtkDataArray *elevation = this->TerrainHeights(terrain); // the Height Array
    if (elevation && elevation->GetNumberOfComponents() == 1) {
      double range[2];
      elevation->GetRange(range, 0);
      lo = range[0];
      hi = range[1];
    }
    p->region[0] = b[0];
    p->region[1] = b[1];
    p->region[2] = b[2];
    p->region[3] = b[3];
    p->region[4] = lo;
    p->region[5] = hi + (this->Region[5] - this->Region[4]);
  }
  this->FillParameters(p);
  char msg[512];
  if (gr_particles_params_validate(p, msg, sizeof(msg)) != GR_OK) {
    vtkErrorMacro(<< label << (terrain ? " (region from the Input's bounds)" : "") << ": " << msg);
    return false;
  }
  return true;
}

int vtkGraupelParticlesSource::Compute(gr_context *ctx, const gr_particles_params &p, double time,
                                       vtkPoints *points, vtkSmartPointer<vtkFloatArray> *arrays) {
  const char *label = this->GetLabel();
  // The core's outputs (unless a core of this Count holds them already), their
  // host copies and one vertex cell a particle (offset and connectivity).
  gr_memory_need need;
  gr_particles_memory(&p, &need);
  const double copies = need.device;
  if (this->Core && this->CoreContext == ctx && gr_particles_count(this->Core) == p.count) {
    need.device = need.largest = 0.0;
  }
  need.host += copies;
  if (!this->ReportError(graupel::MemoryRefusal(
          ctx, label, "a set of " + std::to_string(p.count) + " particles",
          graupel::WithHostArrays(need, p.count, 2.0 * sizeof(vtkIdType)), "lower Count"))) {
    return 0;
  }
  gr_status st = GR_OK;
  if (this->Core && this->CoreContext == ctx) {
    st = gr_particles_set_params(this->Core, &p);
  } else {
    gr_particles_destroy(this->Core);
    this->Core = nullptr;
    st = gr_particles_create(ctx, &p, &this->Core);
    this->CoreContext = this->Core ? ctx : nullptr;
  }
  if (st == GR_OK) {
    st = gr_particles_compute(this->Core, time);
  }
  const vtkIdType n = p.count;
  for (int o = 0; o < GR_PARTICLES_OUTPUT_COUNT && st == GR_OK; ++o) {
    const auto out = static_cast<gr_particles_output>(o);
    if (o == GR_PARTICLES_POSITION) {
      arrays[o] = vtkFloatArray::SafeDownCast(points->GetData());
    } else {
      arrays[o] = vtkSmartPointer<vtkFloatArray>::New();
      arrays[o]->SetName(gr_particles_output_name(static_cast<gr_particles_kind>(p.kind), out));
    }
    arrays[o]->SetNumberOfComponents(gr_particles_output_components(out));
    if (!arrays[o]->Allocate(n * arrays[o]->GetNumberOfComponents())) {
      vtkErrorMacro(<< label << ": out of host memory for " << n
                    << " particles; use a smaller Count.");
      return 0;
    }
    arrays[o]->SetNumberOfTuples(n);
    st = gr_particles_get_output(this->Core, out, arrays[o]->GetPointer(0));
  }
  if (st != GR_OK) {
    std::string why = gr_particles_last_error(this->Core);
    if (this->Core == nullptr) {
      why = gr_particles_last_error(nullptr);
    }
    gr_particles_destroy(this->Core);
    this->Core = nullptr;
    this->CoreContext = nullptr;
    return this->ReportFailure(
        st, (std::string(label) + " could not compute the particles").c_str(), why.c_str());
  }
  return 1;
}

int vtkGraupelParticlesSource::RequestData(vtkInformation *, vtkInformationVector **inputVector,
                                           vtkInformationVector *outputVector) {
  const char *label = this->GetLabel();
  vtkInformation *outInfo = outputVector->GetInformationObject(0);
  vtkPolyData *output = vtkPolyData::GetData(outInfo);
  output->Initialize();
  const double time = outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP())
                          ? outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP())
                          : 0.0;
  vtkImageData *terrain = inputVector[0]->GetNumberOfInformationObjects()
                              ? vtkImageData::GetData(inputVector[0])
                              : nullptr;
  gr_particles_params p;
  if (!this->CoreParams(terrain, &p)) {
    return 0;
  }
  if (!std::isfinite(time)) {
    vtkErrorMacro(<< label << ": the requested time is not a finite number of seconds.");
    return 0;
  }
  gr_context *ctx = this->GetContext();
  if (!ctx) {
    return 0;
  }
  vtkNew<vtkPoints> points;
  points->SetDataTypeToFloat();
  vtkSmartPointer<vtkFloatArray> arrays[GR_PARTICLES_OUTPUT_COUNT];
  if (!this->Compute(ctx, p, time, points, arrays)) {
    return 0;
  }
  // One vertex per point: offsets 0..n, connectivity 0..n-1.
  const vtkIdType n = p.count;
  vtkNew<vtkIdTypeArray> offsets, connectivity;
  offsets->SetNumberOfTuples(n + 1);
  connectivity->SetNumberOfTuples(n);
  for (vtkIdType i = 0; i < n; ++i) {
    offsets->SetValue(i, i);
    connectivity->SetValue(i, i);
  }
  offsets->SetValue(n, n);
  vtkNew<vtkCellArray> verts;
  verts->SetData(offsets, connectivity);
  output->SetPoints(points);
  output->SetVerts(verts);
  vtkPointData *pd = output->GetPointData();
  pd->AddArray(arrays[GR_PARTICLES_VELOCITY]);
  pd->AddArray(arrays[GR_PARTICLES_SIZE]);
  pd->AddArray(arrays[GR_PARTICLES_STREAK]);
  pd->SetActiveScalars(arrays[GR_PARTICLES_SIZE]->GetName());
  pd->SetActiveVectors("streak");
  vtkNew<vtkDoubleArray> t;
  t->SetName("time");
  t->InsertNextValue(time);
  output->GetFieldData()->AddArray(t);
  output->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), time);
  this->AddDeviceFieldData(output);
  return 1;
}

void vtkGraupelParticlesSource::PrintSelf(ostream &os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Count: " << this->Count << "\n";
  os << indent << "Seed: " << this->Seed << "\n";
  os << indent << "ExposureTime: " << this->ExposureTime << "\n";
  os << indent << "Wind: " << this->Wind[0] << " " << this->Wind[1] << " " << this->Wind[2] << "\n";
  os << indent << "Region:";
  for (int c = 0; c < 6; ++c) {
    os << " " << this->Region[c];
  }
  os << "\n";
}
