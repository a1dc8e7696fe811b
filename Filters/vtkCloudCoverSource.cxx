#include "vtkCloudCoverSource.h"

#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkUnsignedCharArray.h"

#include "graupel/cl_runtime.h"
#include "graupel/sky.h"

#include "GraupelMemory.h"
#include "GraupelParameterTable.h"

#include <algorithm>
#include <cmath>
#include <string>

vtkStandardNewMacro(vtkCloudCoverSource);

GRAUPEL_TABLE_SETTER(vtkCloudCoverSource, Cover, double, gr_sky_param_bounds)
GRAUPEL_TABLE_SETTER(vtkCloudCoverSource, Scale, double, gr_sky_param_bounds)
GRAUPEL_TABLE_SETTER(vtkCloudCoverSource, Sharpness, double, gr_sky_param_bounds)
GRAUPEL_TABLE_SETTER(vtkCloudCoverSource, WindSpeed, double, gr_sky_param_bounds)
GRAUPEL_TABLE_SETTER(vtkCloudCoverSource, WindDirection, double, gr_sky_param_bounds)
GRAUPEL_TABLE_SETTER(vtkCloudCoverSource, Resolution, int, gr_sky_param_bounds)
GRAUPEL_TABLE_SETTER(vtkCloudCoverSource, Size, double, gr_sky_param_bounds)

vtkCloudCoverSource::vtkCloudCoverSource() {
  this->SetNumberOfInputPorts(0);
  gr_cloud_cover_params p;
  gr_cloud_cover_params_init(&p);
  this->Cover = p.cover;
  this->Scale = p.scale;
  this->Sharpness = p.sharpness;
  this->WindSpeed = p.wind_speed;
  this->WindDirection = p.wind_direction;
  this->Resolution = p.resolution;
  this->Size = p.size;
  this->Seed = p.seed;
}

namespace {
gr_cloud_cover_params ParamsOf(const vtkCloudCoverSource *s) {
  gr_cloud_cover_params p;
  gr_cloud_cover_params_init(&p);
  auto *src = const_cast<vtkCloudCoverSource *>(s);
  p.cover = src->GetCover();
  p.scale = src->GetScale();
  p.sharpness = src->GetSharpness();
  p.wind_speed = src->GetWindSpeed();
  p.wind_direction = src->GetWindDirection();
  p.resolution = src->GetResolution();
  p.size = src->GetSize();
  p.seed = src->GetSeed();
  return p;
}
} // namespace

int vtkCloudCoverSource::RequestInformation(vtkInformation *, vtkInformationVector **,
                                            vtkInformationVector *outputVector) {
  vtkInformation *outInfo = outputVector->GetInformationObject(0);
  const gr_cloud_cover_params p = ParamsOf(this);
  char msg[256];
  if (gr_cloud_cover_params_validate(&p, msg, sizeof(msg)) != GR_OK) {
    vtkErrorMacro("Cloud Cover: " << msg);
    return 0;
  }
  if (!std::isfinite(this->Altitude) || !(this->Duration >= 0.0) ||
      !std::isfinite(this->Duration)) {
    vtkErrorMacro("Cloud Cover: Altitude (" << this->Altitude << " m) must be finite and Duration ("
                                            << this->Duration << " s) finite and at least 0.");
    return 0;
  }
  gr_grid g;
  gr_cloud_cover_grid(&p, &g);
  int extent[6] = {0, g.nx - 1, 0, g.ny - 1, 0, 0};
  double spacing[3] = {g.dx, g.dy, 1.0};
  double origin[3] = {g.x0, g.y0, this->Altitude};
  outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  outInfo->Set(vtkDataObject::SPACING(), spacing, 3);
  outInfo->Set(vtkDataObject::ORIGIN(), origin, 3);
  double range[2] = {0.0, this->Duration};
  outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), range, 2);
  outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
  vtkDataObject::SetPointDataActiveScalarInfo(outInfo, VTK_FLOAT, 1);
  return 1;
}

int vtkCloudCoverSource::RequestData(vtkInformation *, vtkInformationVector **,
                                     vtkInformationVector *outputVector) {
  vtkInformation *outInfo = outputVector->GetInformationObject(0);
  vtkImageData *output = vtkImageData::GetData(outInfo);
  output->Initialize();
  if (this->AbortRequested("Cloud Cover", false)) {
    return 1;
  }
  const double t = outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP())
                       ? outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP())
                       : 0.0;
  const gr_cloud_cover_params p = ParamsOf(this);
  char msg[256];
  if (gr_cloud_cover_params_validate(&p, msg, sizeof(msg)) != GR_OK) {
    vtkErrorMacro("Cloud Cover: " << msg);
    return 0;
  }
  gr_context *ctx = this->GetContext();
  if (!ctx) {
    return 0;
  }
  // The core's buffers and the output's cloud (a float) and sky_rgb (3 bytes).
  gr_memory_need need;
  gr_cloud_cover_memory(&p, &need);
  const double pixels = static_cast<double>(p.resolution) * p.resolution;
  if (!this->ReportError(graupel::MemoryRefusal(
          ctx, "Cloud Cover", graupel::GridSubject(p.resolution, p.resolution, "image"),
          graupel::WithHostArrays(need, pixels, 4.0 + 3.0), "lower Resolution"))) {
    return 0;
  }
  gr_cloud_cover *clouds = nullptr;
  gr_status st = gr_cloud_cover_create(ctx, &p, &clouds);
  if (st != GR_OK) {
    return this->ReportFailure(st, "Cloud Cover could not set up the sky",
                               gr_cloud_cover_last_error(nullptr));
  }
  gr_grid g;
  gr_cloud_cover_grid(&p, &g);
  const vtkIdType npoints = static_cast<vtkIdType>(g.nx) * g.ny;
  vtkNew<vtkFloatArray> cloud;
  cloud->SetName("cloud");
  vtkNew<vtkUnsignedCharArray> rgb;
  rgb->SetName("sky_rgb");
  rgb->SetNumberOfComponents(3);
  if (!cloud->Allocate(npoints) || !rgb->Allocate(3 * npoints)) {
    gr_cloud_cover_destroy(clouds);
    vtkErrorMacro("Cloud Cover: out of host memory for " << g.nx << " x " << g.ny
                                                         << " pixels; lower Resolution.");
    return 0;
  }
  cloud->SetNumberOfTuples(npoints);
  rgb->SetNumberOfTuples(npoints);
  // Band by band (about 4 million pixels each): progress and abort between.
  const int band = std::max(1, (1 << 22) / g.nx);
  const std::string text =
      "Cloud Cover: " + std::to_string(g.nx) + " x " + std::to_string(g.ny) + " pixels";
  this->SetProgressText(text.c_str());
  this->UpdateProgress(0.0);
  for (int row = 0; row < g.ny && st == GR_OK; row += band) {
    const int rows = std::min(band, g.ny - row);
    st = gr_cloud_cover_compute_rows(clouds, t, row, rows);
    if (st == GR_OK) {
      st = gr_finish(ctx);
    }
    this->UpdateProgress(static_cast<double>(row + rows) / g.ny);
    if (st == GR_OK && this->AbortRequested("Cloud Cover", true)) {
      gr_cloud_cover_destroy(clouds);
      return 1;
    }
  }
  if (st == GR_OK) {
    st = gr_cloud_cover_get(clouds, cloud->GetPointer(0), rgb->GetPointer(0));
  }
  if (st != GR_OK) {
    std::string why = gr_cloud_cover_last_error(clouds);
    if (why.empty()) {
      why = gr_last_error(ctx);
    }
    gr_cloud_cover_destroy(clouds);
    return this->ReportFailure(st, "Cloud Cover could not compute the sky", why.c_str());
  }
  gr_cloud_cover_destroy(clouds);

  output->SetExtent(0, g.nx - 1, 0, g.ny - 1, 0, 0);
  output->SetSpacing(g.dx, g.dy, 1.0);
  output->SetOrigin(g.x0, g.y0, this->Altitude);
  output->GetPointData()->SetScalars(cloud);
  output->GetPointData()->AddArray(rgb);
  vtkNew<vtkDoubleArray> time;
  time->SetName("time");
  time->InsertNextValue(t);
  output->GetFieldData()->AddArray(time);
  output->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), t);
  this->AddDeviceFieldData(output);
  return 1;
}

void vtkCloudCoverSource::PrintSelf(ostream &os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Cover: " << this->Cover << "\n";
  os << indent << "Scale: " << this->Scale << "\n";
  os << indent << "Sharpness: " << this->Sharpness << "\n";
  os << indent << "WindSpeed: " << this->WindSpeed << "\n";
  os << indent << "WindDirection: " << this->WindDirection << "\n";
  os << indent << "Resolution: " << this->Resolution << "\n";
  os << indent << "Size: " << this->Size << "\n";
  os << indent << "Seed: " << this->Seed << "\n";
  os << indent << "Altitude: " << this->Altitude << "\n";
  os << indent << "Duration: " << this->Duration << "\n";
}
