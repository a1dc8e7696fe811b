#include "vtkProceduralTerrainSource.h"

#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include "graupel/cl_runtime.h"
#include "graupel/procedural_terrain.h"

#include "GraupelMemory.h"
#include "GraupelParameterTable.h"

#include <algorithm>
#include <cstring>
#include <string>

vtkStandardNewMacro(vtkProceduralTerrainSource);

// The core's parameter table clamps every ranged property: the class writes
// no range of its own.
GRAUPEL_TABLE_SETTER(vtkProceduralTerrainSource, NoiseType, int, gr_procedural_terrain_param_bounds)
GRAUPEL_TABLE_SETTER(vtkProceduralTerrainSource, Octaves, int, gr_procedural_terrain_param_bounds)
GRAUPEL_TABLE_SETTER(vtkProceduralTerrainSource, Frequency, double,
                     gr_procedural_terrain_param_bounds)
GRAUPEL_TABLE_SETTER(vtkProceduralTerrainSource, Lacunarity, double,
                     gr_procedural_terrain_param_bounds)
GRAUPEL_TABLE_SETTER(vtkProceduralTerrainSource, Persistence, double,
                     gr_procedural_terrain_param_bounds)
GRAUPEL_TABLE_SETTER(vtkProceduralTerrainSource, Offset, double, gr_procedural_terrain_param_bounds)
GRAUPEL_TABLE_SETTER(vtkProceduralTerrainSource, Gain, double, gr_procedural_terrain_param_bounds)
GRAUPEL_TABLE_SETTER(vtkProceduralTerrainSource, SpectralExponent, double,
                     gr_procedural_terrain_param_bounds)
GRAUPEL_TABLE_SETTER(vtkProceduralTerrainSource, HeightScale, double,
                     gr_procedural_terrain_param_bounds)

vtkProceduralTerrainSource::vtkProceduralTerrainSource() {
  this->SetNumberOfInputPorts(0);
  gr_procedural_terrain_params p;
  gr_procedural_terrain_params_init(&p);
  this->Seed = p.seed;
  this->NoiseType = static_cast<int>(p.type);
  this->Octaves = p.octaves;
  this->Frequency = p.frequency;
  this->Lacunarity = p.lacunarity;
  this->Persistence = p.persistence;
  this->Offset = p.offset;
  this->Gain = p.gain;
  this->SpectralExponent = p.h;
  this->Invert = p.invert != 0;
  this->HeightScale = p.height_scale;
}

int vtkProceduralTerrainSource::RequestInformation(vtkInformation *, vtkInformationVector **,
                                                   vtkInformationVector *outputVector) {
  vtkInformation *outInfo = outputVector->GetInformationObject(0);
  if (this->Dimensions[0] < 1 || this->Dimensions[1] < 1 || !(this->Spacing > 0.0)) {
    vtkErrorMacro("Procedural Terrain needs Dimensions of at least 1 x 1 and a Spacing above 0 m;"
                  " got "
                  << this->Dimensions[0] << " x " << this->Dimensions[1] << " and " << this->Spacing
                  << " m.");
    return 0;
  }
  int extent[6] = {0, this->Dimensions[0] - 1, 0, this->Dimensions[1] - 1, 0, 0};
  double spacing[3] = {this->Spacing, this->Spacing, 1.0};
  outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  outInfo->Set(vtkDataObject::SPACING(), spacing, 3);
  outInfo->Set(vtkDataObject::ORIGIN(), this->Origin, 3);
  // Noise depends on world position only, so any piece can be computed alone.
  outInfo->Set(vtkAlgorithm::CAN_PRODUCE_SUB_EXTENT(), 1);
  vtkDataObject::SetPointDataActiveScalarInfo(outInfo, VTK_FLOAT, 1);
  return 1;
}

int vtkProceduralTerrainSource::RequestData(vtkInformation *, vtkInformationVector **,
                                            vtkInformationVector *outputVector) {
  vtkInformation *outInfo = outputVector->GetInformationObject(0);
  vtkImageData *output = vtkImageData::GetData(outInfo);
  int extent[6];
  outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), extent);
  output->Initialize();
  if (this->AbortRequested("Procedural Terrain", false)) {
    return 1;
  }

  gr_procedural_terrain_params p;
  gr_procedural_terrain_params_init(&p);
  p.seed = this->Seed;
  p.type = static_cast<gr_noise_type>(this->NoiseType);
  p.octaves = this->Octaves;
  p.frequency = this->Frequency;
  p.lacunarity = this->Lacunarity;
  p.persistence = this->Persistence;
  p.offset = this->Offset;
  p.gain = this->Gain;
  p.h = this->SpectralExponent;
  p.invert = this->Invert ? 1 : 0;
  p.height_scale = this->HeightScale;
  char msg[256];
  if (gr_procedural_terrain_params_validate(&p, msg, sizeof(msg)) != GR_OK) {
    vtkErrorMacro("Procedural Terrain: " << msg);
    return 0;
  }

  gr_grid grid = {};
  grid.nx = extent[1] - extent[0] + 1;
  grid.ny = extent[3] - extent[2] + 1;
  grid.dx = grid.dy = this->Spacing;
  grid.x0 = this->Origin[0];
  grid.y0 = this->Origin[1];
  grid.i0 = extent[0];
  grid.j0 = extent[2];
  if (grid.nx < 1 || grid.ny < 1) {
    return 1; // an empty piece (more MPI ranks than rows) is a valid answer
  }

  gr_context *ctx = this->GetContext();
  if (!ctx) {
    return 0;
  }
  // The elevation buffer and its host copy, checked against the device and
  // what this process can get before either is allocated.
  gr_memory_need need;
  gr_procedural_terrain_memory(&grid, &need);
  const vtkIdType npoints = static_cast<vtkIdType>(grid.nx) * grid.ny;
  if (!this->ReportError(graupel::MemoryRefusal(
          ctx, "Procedural Terrain", graupel::GridSubject(grid.nx, grid.ny),
          graupel::WithHostArrays(need, static_cast<double>(npoints), sizeof(float)),
          "choose smaller Dimensions (a larger Spacing keeps the extent)"))) {
    return 0;
  }
  gr_procedural_terrain *noise = nullptr;
  gr_status st = gr_procedural_terrain_create(ctx, &grid, &p, &noise);
  if (st != GR_OK) {
    // No generator exists after a failed create: the sentence is this thread's.
    return this->ReportFailure(st, "Procedural Terrain could not set up the noise",
                               gr_procedural_terrain_last_error(nullptr));
  }
  vtkNew<vtkFloatArray> elevation;
  elevation->SetName("elevation");
  if (!elevation->Allocate(npoints)) {
    gr_procedural_terrain_destroy(noise);
    vtkErrorMacro("Procedural Terrain: out of host memory for "
                  << grid.nx << " x " << grid.ny << " points; use smaller Dimensions.");
    return 0;
  }
  elevation->SetNumberOfTuples(npoints);
  // Band by band (about 4 million points each), so that a large terrain
  // reports progress and can be aborted between bands.
  const int band = std::max(1, (1 << 22) / grid.nx);
  const std::string text = "Procedural Terrain: " + std::to_string(grid.nx) + " x " +
                           std::to_string(grid.ny) + " points";
  this->SetProgressText(text.c_str());
  this->UpdateProgress(0.0);
  for (int row = 0; row < grid.ny && st == GR_OK; row += band) {
    const int rows = std::min(band, grid.ny - row);
    st = gr_procedural_terrain_compute_rows(noise, row, rows);
    if (st == GR_OK) {
      st = gr_finish(ctx);
    }
    this->UpdateProgress(static_cast<double>(row + rows) / grid.ny);
    if (st == GR_OK && this->AbortRequested("Procedural Terrain", true)) {
      gr_procedural_terrain_destroy(noise);
      return 1;
    }
  }
  if (st == GR_OK) {
    st = gr_procedural_terrain_get_field(noise, GR_FIELD_ELEVATION, elevation->GetPointer(0));
  }
  if (st != GR_OK) {
    // gr_finish is the context's, not the generator's: its sentence is this
    // thread's latest error, which the generator's own text then repeats.
    std::string why = gr_procedural_terrain_last_error(noise);
    if (why.empty()) {
      why = gr_last_error(ctx);
    }
    gr_procedural_terrain_destroy(noise);
    return this->ReportFailure(st, "Procedural Terrain could not compute the noise", why.c_str());
  }
  gr_procedural_terrain_destroy(noise);

  output->SetExtent(extent[0], extent[1], extent[2], extent[3], 0, 0);
  output->SetSpacing(this->Spacing, this->Spacing, 1.0);
  output->SetOrigin(this->Origin);
  output->GetPointData()->SetScalars(elevation);
  this->AddDeviceFieldData(output);
  return 1;
}

void vtkProceduralTerrainSource::PrintSelf(ostream &os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Dimensions: " << this->Dimensions[0] << " " << this->Dimensions[1] << "\n";
  os << indent << "Spacing: " << this->Spacing << "\n";
  os << indent << "Origin: " << this->Origin[0] << " " << this->Origin[1] << " " << this->Origin[2]
     << "\n";
  os << indent << "Seed: " << this->Seed << "\n";
  os << indent << "NoiseType: " << this->NoiseType << "\n";
  os << indent << "Octaves: " << this->Octaves << "\n";
  os << indent << "Frequency: " << this->Frequency << "\n";
  os << indent << "Lacunarity: " << this->Lacunarity << "\n";
  os << indent << "Persistence: " << this->Persistence << "\n";
  os << indent << "Offset: " << this->Offset << "\n";
  os << indent << "Gain: " << this->Gain << "\n";
  os << indent << "SpectralExponent: " << this->SpectralExponent << "\n";
  os << indent << "Invert: " << this->Invert << "\n";
  os << indent << "HeightScale: " << this->HeightScale << "\n";
}
