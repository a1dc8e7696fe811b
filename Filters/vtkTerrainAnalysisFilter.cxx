#include "vtkTerrainAnalysisFilter.h"
#include "GraupelTerrain.h"

#include "vtkDataArray.h"
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
#include "graupel/terrain_analysis.h"

#include "GraupelArrays.h"
#include "GraupelMemory.h"
#include "GraupelParameterTable.h"

#include <algorithm>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkTerrainAnalysisFilter);

// The core's parameter table clamps every ranged property: the class writes
// no range of its own.
GRAUPEL_TABLE_SETTER(vtkTerrainAnalysisFilter, SunAzimuth, double, gr_terrain_analysis_param_bounds)
GRAUPEL_TABLE_SETTER(vtkTerrainAnalysisFilter, SunElevation, double,
                     gr_terrain_analysis_param_bounds)
GRAUPEL_TABLE_SETTER(vtkTerrainAnalysisFilter, PenumbraWidth, double,
                     gr_terrain_analysis_param_bounds)
GRAUPEL_TABLE_SETTER(vtkTerrainAnalysisFilter, CoverMode, int, gr_terrain_analysis_param_bounds)
GRAUPEL_TABLE_SETTER(vtkTerrainAnalysisFilter, SnowExponent, double,
                     gr_terrain_analysis_param_bounds)
GRAUPEL_TABLE_SETTER(vtkTerrainAnalysisFilter, SnowCoverLimit, double,
                     gr_terrain_analysis_param_bounds)
GRAUPEL_TABLE_SETTER(vtkTerrainAnalysisFilter, RockSlope, double, gr_terrain_analysis_param_bounds)
GRAUPEL_TABLE_SETTER(vtkTerrainAnalysisFilter, WaterLevel, double, gr_terrain_analysis_param_bounds)

vtkTerrainAnalysisFilter::vtkTerrainAnalysisFilter() {
  gr_terrain_analysis_params p;
  gr_terrain_analysis_params_init(&p);
  this->SunAzimuth = p.sun_azimuth;
  this->SunElevation = p.sun_elevation;
  this->PenumbraWidth = p.penumbra_width;
  this->ModelShadows = p.model_shadows != 0;
  this->CoverMode = p.cover_mode;
  this->SnowExponent = p.snow_exponent;
  this->SnowCoverLimit = p.snow_cover_limit;
  this->RockSlope = p.rock_slope;
  this->WaterLevel = p.water_level;
}

int vtkTerrainAnalysisFilter::RequestUpdateExtent(vtkInformation *,
                                                  vtkInformationVector **inputVector,
                                                  vtkInformationVector *) {
  // The whole terrain: derivatives need neighbours and shadow rays cross it.
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

namespace {
// A float output of the core as a named VTK array; nullptr when reading failed.
vtkSmartPointer<vtkFloatArray> ReadOutput(gr_terrain_analysis *t, gr_terrain_output o,
                                          vtkIdType npoints, gr_status *st) {
  auto a = vtkSmartPointer<vtkFloatArray>::New();
  a->SetName(gr_terrain_output_name(o));
  a->SetNumberOfComponents(o == GR_TERRAIN_NORMAL ? 3 : 1);
  a->SetNumberOfTuples(npoints);
  *st = gr_terrain_analysis_get_output(t, o, a->GetPointer(0));
  return *st == GR_OK ? a : nullptr;
}
} // namespace

vtkDataArray *vtkTerrainAnalysisFilter::Heights(vtkImageData *input, std::string &name) {
  const char *label = this->GetLabel();
  if (!input) {
    vtkErrorMacro(<< label << " needs a terrain image on its Input.");
    return nullptr;
  }
  int dims[3];
  input->GetDimensions(dims);
  if (input->GetNumberOfPoints() < 1 || dims[2] != 1) {
    vtkErrorMacro(<< label << " needs a 2-D terrain (nx x ny x 1 points) on its Input; it got "
                  << dims[0] << " x " << dims[1] << " x " << dims[2] << " points.");
    return nullptr;
  }
  double spacing[3];
  input->GetSpacing(spacing);
  if (!(spacing[0] > 0.0) || !(spacing[1] > 0.0)) {
    vtkErrorMacro(<< label << " needs a terrain spacing above 0 m in x and y; the Input has "
                  << spacing[0] << " and " << spacing[1] << " m.");
    return nullptr;
  }
  // The Height Array, point or cell data (the Input is then the view of
  // cell centres: GraupelTerrain.h); by default elevation.
  std::string why;
  vtkDataArray *heights = this->TerrainHeights(input, &why);
  if (!heights) {
    vtkErrorMacro(<< graupel::NoHeightsSentence(label, "Input", why));
    return nullptr;
  }
  name = heights->GetName() ? heights->GetName() : "elevation";
  return heights;
}

bool vtkTerrainAnalysisFilter::CoreParams(gr_terrain_analysis_params *p) {
  gr_terrain_analysis_params_init(p);
  p->sun_azimuth = this->SunAzimuth;
  p->sun_elevation = this->SunElevation;
  p->penumbra_width = this->PenumbraWidth;
  p->model_shadows = this->ModelShadows ? 1 : 0;
  p->cover_mode = this->CoverMode;
  p->snow_exponent = this->SnowExponent;
  p->snow_cover_limit = this->SnowCoverLimit;
  p->rock_slope = this->RockSlope;
  p->water_level = this->WaterLevel;
  char msg[256];
  if (gr_terrain_analysis_params_validate(p, msg, sizeof(msg)) != GR_OK) {
    vtkErrorMacro(<< this->GetLabel() << ": " << msg);
    return false;
  }
  return true;
}

int vtkTerrainAnalysisFilter::Compute(gr_context *ctx, const gr_grid &grid,
                                      const gr_terrain_analysis_params &p, vtkDataArray *heights,
                                      const std::string &name,
                                      std::vector<vtkSmartPointer<vtkDataArray>> &arrays) {
  const char *label = this->GetLabel();
  gr_terrain_analysis *t = nullptr;
  gr_status st = gr_terrain_analysis_create(ctx, &grid, &p, &t);
  if (st != GR_OK) {
    return this->ReportFailure(st, (std::string(label) + " could not set up").c_str(),
                               gr_terrain_analysis_last_error(nullptr));
  }
  st = gr_terrain_analysis_set_heights(t, graupel::AsFloat(heights)->GetPointer(0));
  if (st != GR_OK) {
    std::string why = gr_terrain_analysis_last_error(t);
    gr_terrain_analysis_destroy(t);
    vtkErrorMacro(<< label << "'s Input array '" << name << "': " << why);
    return 0;
  }
  // The shadow band by band (about a million points each), so that a large
  // terrain reports progress and can be aborted between bands.
  const bool shadow = this->GetShadowOnly() || this->ModelShadows;
  const int band = std::max(1, (1 << 20) / grid.nx);
  this->UpdateProgress(0.0);
  for (int row = 0; shadow && row < grid.ny && st == GR_OK; row += band) {
    const int rows = std::min(band, grid.ny - row);
    st = gr_terrain_analysis_compute_shadow_rows(t, row, rows);
    if (st == GR_OK) {
      st = gr_finish(ctx);
    }
    this->UpdateProgress(0.9 * (row + rows) / grid.ny);
    if (st == GR_OK && this->AbortRequested(label, true)) {
      gr_terrain_analysis_destroy(t);
      return -1;
    }
  }
  if (st == GR_OK && !this->GetShadowOnly()) {
    st = gr_terrain_analysis_compute(t);
  }
  const vtkIdType npoints = static_cast<vtkIdType>(grid.nx) * grid.ny;
  if (st == GR_OK && shadow) {
    arrays.emplace_back(ReadOutput(t, GR_TERRAIN_SHADOW, npoints, &st));
  }
  if (!this->GetShadowOnly()) {
    const gr_terrain_output outputs[] = {GR_TERRAIN_NORMAL, GR_TERRAIN_SLOPE, GR_TERRAIN_ASPECT,
                                         GR_TERRAIN_SNOW_COVER, GR_TERRAIN_HILLSHADE};
    for (gr_terrain_output o : outputs) {
      if (st == GR_OK) {
        arrays.emplace_back(ReadOutput(t, o, npoints, &st));
      }
    }
    if (st == GR_OK) {
      vtkNew<vtkUnsignedCharArray> classes;
      classes->SetName(gr_terrain_output_name(GR_TERRAIN_COVER_CLASS));
      classes->SetNumberOfTuples(npoints);
      st = gr_terrain_analysis_get_cover_class(t, classes->GetPointer(0));
      arrays.emplace_back(classes.Get());
    }
  }
  if (st != GR_OK) {
    std::string why = gr_terrain_analysis_last_error(t);
    if (why.empty()) {
      why = gr_last_error(ctx);
    }
    gr_terrain_analysis_destroy(t);
    return this->ReportFailure(st, (std::string(label) + " could not compute").c_str(),
                               why.c_str());
  }
  gr_terrain_analysis_destroy(t);
  this->UpdateProgress(1.0);
  return 1;
}

int vtkTerrainAnalysisFilter::RequestData(vtkInformation *, vtkInformationVector **inputVector,
                                          vtkInformationVector *outputVector) {
  const char *label = this->GetLabel();
  vtkImageData *input = vtkImageData::GetData(inputVector[0]);
  vtkImageData *output = vtkImageData::GetData(outputVector);
  output->Initialize();
  if (this->AbortRequested(label, false)) {
    return 1;
  }
  std::string name;
  vtkDataArray *heights = this->Heights(input, name);
  gr_terrain_analysis_params p;
  if (!heights || !this->CoreParams(&p)) {
    return 0;
  }
  int dims[3];
  double spacing[3], origin[3];
  input->GetDimensions(dims);
  input->GetSpacing(spacing);
  input->GetOrigin(origin);
  gr_grid grid = {};
  grid.nx = dims[0];
  grid.ny = dims[1];
  grid.dx = spacing[0];
  grid.dy = spacing[1];
  grid.x0 = origin[0];
  grid.y0 = origin[1];
  gr_context *ctx = this->GetContext();
  if (!ctx) {
    return 0;
  }
  // The core's buffers, the output arrays (the shadow's float, or every
  // output: 33 bytes a point) and a float copy of heights stored otherwise.
  gr_memory_need need;
  gr_terrain_analysis_memory(&grid, &need);
  const double points = static_cast<double>(grid.nx) * grid.ny;
  const double outputBytes = this->GetShadowOnly() ? 4.0 : 4.0 * (1 + 3 + 4) + 1.0;
  const double copyBytes = vtkFloatArray::SafeDownCast(heights) ? 0.0 : 4.0;
  if (!this->ReportError(graupel::MemoryRefusal(
          ctx, label, graupel::GridSubject(grid.nx, grid.ny),
          graupel::WithHostArrays(need, points, outputBytes + copyBytes),
          "resample the terrain to fewer points (e.g. with Resample To Image)"))) {
    return 0;
  }
  this->SetProgressText((std::string(label) + ": " + std::to_string(grid.nx) + " x " +
                         std::to_string(grid.ny) + " points")
                            .c_str());
  std::vector<vtkSmartPointer<vtkDataArray>> arrays;
  const int done = this->Compute(ctx, grid, p, heights, name, arrays);
  if (done <= 0) {
    return done < 0 ? 1 : 0; // aborted (an empty output) or failed (said why)
  }
  output->ShallowCopy(input);
  vtkPointData *pd = output->GetPointData();
  for (const auto &a : arrays) {
    pd->AddArray(a);
  }
  // Shown on Apply: Terrain Shadow's output coloured by the shadow; Terrain
  // Analysis's keeps the input's active scalars (elevation, on Graupel's
  // terrains) and is lit by the terrain's true normals, a shaded relief even
  // before a warp. Were hillshade the active scalars, a Terrain Shadow
  // applied to this output would take it as its heights (ParaView picks the
  // active scalars for the Height Array).
  if (this->GetShadowOnly()) {
    pd->SetActiveScalars("shadow");
  } else {
    pd->SetActiveNormals("normal");
  }
  this->AddDeviceFieldData(output);
  return 1;
}

void vtkTerrainAnalysisFilter::PrintSelf(ostream &os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  os << indent << "SunAzimuth: " << this->SunAzimuth << "\n";
  os << indent << "SunElevation: " << this->SunElevation << "\n";
  os << indent << "PenumbraWidth: " << this->PenumbraWidth << "\n";
  os << indent << "ModelShadows: " << this->ModelShadows << "\n";
  os << indent << "CoverMode: " << this->CoverMode << "\n";
  os << indent << "SnowExponent: " << this->SnowExponent << "\n";
  os << indent << "SnowCoverLimit: " << this->SnowCoverLimit << "\n";
  os << indent << "RockSlope: " << this->RockSlope << "\n";
  os << indent << "WaterLevel: " << this->WaterLevel << "\n";
}
