#include "vtkSnowAccumulationFilter.h"

#include "vtkDemandDrivenPipeline.h"
#include "vtkDoubleArray.h"
#include "vtkExecutive.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMultiBlockDataSet.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include "graupel/snow_accumulation.h"

#include "GraupelArrays.h"
#include "GraupelObjects.h"
#include "GraupelParameterTable.h"
#include "GraupelPieces.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkSnowAccumulationFilter);

namespace {
using graupel::AddValue;
using graupel::AsFloat;
using graupel::Posed;
const gr_param_bound *Bound(const char *property) {
  return graupel::TableRow(gr_snow_accumulation_param_bounds, property);
}

double TableDefault(const char *property) {
  return graupel::TableDefault(gr_snow_accumulation_param_bounds, property);
}

double TableToCore(const char *property) {
  const gr_param_bound *b = Bound(property);
  return b ? b->to_core : 1.0;
}

} // namespace

vtkSnowAccumulationFilter::vtkSnowAccumulationFilter()
    // One vertex per point (the snow is handed back per point); open meshes.
    : vtkGraupelObjectsSimulation(GR_SNOW_ACCUMULATION_MAX_OBJECTS, false, 0) {
  this->SetNumberOfOutputPorts(3);
  // A snowfall of a few hours: 6 h of 15 min outputs, three 5 min steps
  // each (72 exposure views). Growth is a rate times dt, so longer steps
  // give the same snow; they only see the exposure change less often.
  this->SetTimeDefaults(21600.0, 900.0);
  this->Flutter = TableDefault("Flutter");
  this->SnowfallRate = TableDefault("SnowfallRate");
  this->NoiseAmplitude = TableDefault("NoiseAmplitude");
  this->NoiseScale = TableDefault("NoiseScale");
  this->Seed = static_cast<int>(TableDefault("Seed"));
  this->ExposureResolution = static_cast<int>(TableDefault("ExposureResolution"));
  this->BlurRadius = static_cast<int>(TableDefault("BlurRadius"));
  this->Dilation = static_cast<int>(TableDefault("Dilation"));
  this->MaxDepth = TableDefault("MaxDepth");
  this->StabilityFactor = TableDefault("StabilityFactor");
  this->SnowDensity = TableDefault("SnowDensity");
  this->AccumulationTextureSize = static_cast<int>(TableDefault("AccumulationTextureSize"));
  // The core runs as pieces of a split domain (an MPI run's strips); its
  // ring follows BlurRadius (RequestInformation sets it again).
  gr_snow_accumulation_params ring;
  gr_snow_accumulation_params_init(&ring);
  ring.blur_radius = this->BlurRadius;
  this->SetPieceRing(gr_snow_accumulation_ghost(&ring));
}

vtkSnowAccumulationFilter::~vtkSnowAccumulationFilter() {
  this->ReleaseState();
}

GRAUPEL_CLAMP_SETTER(vtkSnowAccumulationFilter, TimeStep, double, 1.0e-6, 86400.0, "s")
GRAUPEL_TABLE_SETTER(vtkSnowAccumulationFilter, Flutter, double, gr_snow_accumulation_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowAccumulationFilter, SnowfallRate, double,
                     gr_snow_accumulation_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowAccumulationFilter, NoiseAmplitude, double,
                     gr_snow_accumulation_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowAccumulationFilter, NoiseScale, double,
                     gr_snow_accumulation_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowAccumulationFilter, Seed, int, gr_snow_accumulation_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowAccumulationFilter, ExposureResolution, int,
                     gr_snow_accumulation_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowAccumulationFilter, BlurRadius, int, gr_snow_accumulation_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowAccumulationFilter, Dilation, int, gr_snow_accumulation_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowAccumulationFilter, MaxDepth, double, gr_snow_accumulation_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowAccumulationFilter, StabilityFactor, double,
                     gr_snow_accumulation_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowAccumulationFilter, SnowDensity, double,
                     gr_snow_accumulation_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowAccumulationFilter, AccumulationTextureSize, int,
                     gr_snow_accumulation_param_bounds)

int vtkSnowAccumulationFilter::FillOutputPortInformation(int port, vtkInformation *info) {
  // Port 1 follows the Objects input's type (REQUEST_DATA_OBJECT below).
  info->Set(vtkDataObject::DATA_TYPE_NAME(), port == 0   ? "vtkImageData"
                                             : port == 1 ? "vtkDataObject"
                                                         : "vtkMultiBlockDataSet");
  return 1;
}

vtkTypeBool vtkSnowAccumulationFilter::ProcessRequest(vtkInformation *request,
                                                      vtkInformationVector **inInfo,
                                                      vtkInformationVector *outInfo) {
  if ((request->Has(vtkStreamingDemandDrivenPipeline::REQUEST_UPDATE_EXTENT()) ||
       request->Has(vtkDemandDrivenPipeline::REQUEST_DATA())) &&
      request->Has(vtkExecutive::FROM_OUTPUT_PORT())) {
    const int port = request->Get(vtkExecutive::FROM_OUTPUT_PORT());
    vtkInformation *from = port >= 0 ? outInfo->GetInformationObject(port) : nullptr;
    const int outputs = this->GetNumberOfOutputTimes();
    // A consumer that asks for no time reads this output once (Snow
    // Deformation's Input, a writer): it wants the snow that fell, so it
    // gets the last output, not the bare ground of time 0.
    if (from && outputs > 0 && !from->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP())) {
      from->Set(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP(),
                this->GetOutputTime(outputs - 1));
    }
    // The base passes a request from the objects' or the textures' port on
    // to port 0 at the time this sets.
  }
  return this->Superclass::ProcessRequest(request, inInfo, outInfo);
}

int vtkSnowAccumulationFilter::RequestInformation(vtkInformation *request,
                                                  vtkInformationVector **inputVector,
                                                  vtkInformationVector *outputVector) {
  // The ring follows BlurRadius, BlurRadius + 2 rows (gr_snow_accumulation_ghost):
  // a property change comes through here before the next RequestData plans the pieces.
  gr_snow_accumulation_params ring;
  gr_snow_accumulation_params_init(&ring);
  const gr_param_bound *blur = Bound("BlurRadius");
  ring.blur_radius = std::max(0, std::min(this->BlurRadius, blur ? int(blur->max) : 0));
  this->SetPieceRing(gr_snow_accumulation_ghost(&ring));
  // The base gives the objects' and the textures' outputs the simulation's times.
  return this->Superclass::RequestInformation(request, inputVector, outputVector);
}

int vtkSnowAccumulationFilter::CheckParameters() {
  const struct {
    const char *property;
    double value;
  } values[] = {{"Flutter", this->Flutter},
                {"SnowfallRate", this->SnowfallRate},
                {"NoiseAmplitude", this->NoiseAmplitude},
                {"NoiseScale", this->NoiseScale},
                {"Seed", double(this->Seed)},
                {"ExposureResolution", double(this->ExposureResolution)},
                {"BlurRadius", double(this->BlurRadius)},
                {"Dilation", double(this->Dilation)},
                {"MaxDepth", this->MaxDepth},
                {"StabilityFactor", this->StabilityFactor},
                {"SnowDensity", this->SnowDensity},
                {"AccumulationTextureSize", double(this->AccumulationTextureSize)}};
  for (const auto &p : values) {
    if (!this->ReportError(
            graupel::OutOfRange("Snow Accumulation", p.property, Bound(p.property), p.value))) {
      return 0;
    }
  }
  if (!(this->TimeStep >= 1.0e-6 && this->TimeStep <= 86400.0)) {
    vtkErrorMacro("Snow Accumulation: TimeStep must be from 1e-6 s to 86400 s; it is "
                  << this->TimeStep << " s. Set it within that range.");
    return 0;
  }
  return this->CheckObjectMotion();
}

bool vtkSnowAccumulationFilter::ObjectsMove() const {
  if (this->ObjectsTemporal || this->Objects.empty()) {
    return false;
  }
  // A path places the objects on it, so their poses change even at rest.
  if (!this->Path.empty() || this->ObjectAngularVelocity != 0.0) {
    return true;
  }
  for (const graupel::Object &o : this->Objects) {
    if (o.velocity[0] != 0.0 || o.velocity[1] != 0.0 || o.velocity[2] != 0.0) {
      return true;
    }
  }
  return false;
}

int vtkSnowAccumulationFilter::SetObjects(double t) {
  const size_t n = this->Objects.size();
  std::vector<gr_mesh> meshes(n);
  for (size_t k = 0; k < n; ++k) {
    meshes[k] = graupel::MeshOf(this->Objects[k]);
    this->Pose(k, t, meshes[k].transform);
  }
  gr_status st =
      gr_snow_accumulation_set_objects(this->Simulation, meshes.data(), static_cast<int>(n));
  // The same texture again keeps its snow: the core compares.
  for (size_t k = 0; st == GR_OK && k < n; ++k) {
    const graupel::Object &o = this->Objects[k];
    const bool textured = !o.uv.empty() && this->AccumulationTextureSize > 0;
    st = gr_snow_accumulation_set_object_texture(this->Simulation, static_cast<int>(k),
                                                 textured ? o.uv.data() : nullptr,
                                                 textured ? this->AccumulationTextureSize : 0);
  }
  if (st != GR_OK) {
    return this->ReportFailure(st, "Snow Accumulation's Objects",
                               gr_snow_accumulation_last_error(this->Simulation));
  }
  return 1;
}

int vtkSnowAccumulationFilter::SetUpState(vtkInformationVector **inputVector) {
  vtkImageData *terrain = vtkImageData::GetData(inputVector[0]);
  if (!this->CheckTerrain(terrain)) {
    return 0;
  }
  int dims[3];
  terrain->GetDimensions(dims);
  vtkDataArray *elevationArray = this->GetElevation(terrain, "Input");
  if (!elevationArray || !this->CheckParameters()) {
    return 0;
  }
  const size_t npoints = static_cast<size_t>(dims[0]) * static_cast<size_t>(dims[1]);
  std::vector<graupel::Upload> uploads;
  uploads.push_back({GR_FIELD_ELEVATION, AsFloat(elevationArray)});
  if (vtkDataArray *depth = terrain->GetPointData()->GetArray("snow_depth")) {
    uploads.push_back({GR_FIELD_SNOW_DEPTH, AsFloat(depth)});
  }
  char msg[512];
  for (const graupel::Upload &u : uploads) {
    if (!this->ReportError(graupel::CheckPerPoint("Snow Accumulation", u, npoints))) {
      return 0;
    }
    // Checked on the host, before the device is touched.
    if (gr_snow_accumulation_field_validate(u.field, u.values->GetPointer(0), npoints,
                                            static_cast<size_t>(dims[0]), msg,
                                            sizeof(msg)) != GR_OK) {
      vtkErrorMacro("Snow Accumulation's Input: " << msg);
      return 0;
    }
  }
  if (!this->ReadObjectInputs(inputVector)) {
    return 0;
  }

  gr_snow_accumulation_params p;
  gr_snow_accumulation_params_init(&p);
  for (int c = 0; c < 3; ++c) {
    p.direction[c] = this->SnowDirection[c];
  }
  p.flutter = this->Flutter * TableToCore("Flutter");
  p.snowfall_rate = this->SnowfallRate * TableToCore("SnowfallRate");
  p.noise_amplitude = this->NoiseAmplitude * TableToCore("NoiseAmplitude");
  p.noise_scale = this->NoiseScale * TableToCore("NoiseScale");
  p.seed = this->Seed;
  p.exposure_resolution = this->ExposureResolution;
  p.blur_radius = this->BlurRadius;
  p.dilation = this->Dilation;
  p.max_depth = this->MaxDepth * TableToCore("MaxDepth");
  p.stability_factor = this->StabilityFactor * TableToCore("StabilityFactor");
  p.snow_density = this->SnowDensity * TableToCore("SnowDensity");
  p.texture_size = this->AccumulationTextureSize;
  if (gr_snow_accumulation_params_validate(&p, msg, sizeof(msg)) != GR_OK) {
    vtkErrorMacro("Snow Accumulation: " << msg);
    return 0;
  }
  gr_context *ctx = this->GetContext();
  if (!ctx) {
    return 0;
  }
  // The device's limit first, so the sentence names ExposureResolution
  // rather than a failed allocation.
  int limit = 0;
  gr_status st = gr_snow_accumulation_max_resolution(ctx, &limit);
  if (st != GR_OK) {
    return this->ReportFailure(st, "Snow Accumulation could not query the device");
  }
  if (this->ExposureResolution > limit) {
    vtkErrorMacro("Snow Accumulation: ExposureResolution "
                  << this->ExposureResolution << " is beyond the device '" << this->GetDeviceName()
                  << "': its exposure view can be at most " << limit
                  << " texels across; lower ExposureResolution or pick another Device.");
    return 0;
  }
  gr_grid grid;
  TerrainGrid(terrain, &grid);
  // A split run's strip: its rows, its ring and the whole domain around it.
  // Every rank keeps every object (their snow is the same bits on each);
  // the core combines the ranks' exposure views, the surface under the
  // objects and the ledger's rows through the allreduce, so every rank's
  // snow and ledger are the whole grid's.
  graupel::Pieces &pieces = this->GetPieces();
  pieces.PieceGrid(&grid);
  // Before the device: the core's state on this rank's piece with the
  // exposure view (checked against the device above, for its own
  // sentence), the output's five fields and an upload's staging plane.
  gr_memory_need need;
  gr_snow_accumulation_memory(&grid, &p, &need);
  if (!this->CheckMemory(grid, need, 4.0 * (5 + 1))) {
    return 0;
  }
  st = gr_snow_accumulation_create(ctx, &grid, &p, &this->Simulation);
  if (st != GR_OK) {
    return this->ReportFailure(st, "Snow Accumulation could not set up the simulation");
  }
  if (pieces.IsSplit()) {
    gr_snow_accumulation *sim = this->Simulation;
    pieces.BindHalo(
        [sim](int side, size_t *bytes) { return gr_snow_accumulation_halo_size(sim, side, bytes); },
        [sim](int side, void *host, size_t bytes) {
          return gr_snow_accumulation_halo_get(sim, side, host, bytes);
        },
        [sim](int side, const void *host, size_t bytes) {
          return gr_snow_accumulation_halo_set(sim, side, host, bytes);
        });
    gr_snow_accumulation_set_allreduce(sim, graupel::Pieces::Allreduce, &pieces);
    gr_snow_accumulation_set_halo_exchange(sim, graupel::Pieces::Exchange, &pieces);
  }
  for (const graupel::Upload &u : uploads) {
    const std::vector<float> local = pieces.LocalField(u.values->GetPointer(0), dims[0], 1);
    st = gr_snow_accumulation_set_field(this->Simulation, u.field, local.data());
    if (st != GR_OK) {
      vtkErrorMacro(
          "Snow Accumulation's Input: " << gr_snow_accumulation_last_error(this->Simulation));
      return 0;
    }
  }
  gr_snow_accumulation_set_progress(this->Simulation, &vtkGraupelSimulation::ThrottledProgress,
                                    this);
  return this->SetObjects(0.0);
}

int vtkSnowAccumulationFilter::ResetState() {
  gr_status st = gr_snow_accumulation_reset(this->Simulation);
  gr_snow_accumulation_set_progress(this->Simulation, &vtkGraupelSimulation::ThrottledProgress,
                                    this);
  if (st != GR_OK) {
    return this->ReportFailure(st, "Snow Accumulation could not restart",
                               gr_snow_accumulation_last_error(this->Simulation));
  }
  // Moving objects back to their place at time 0 (reset keeps the poses).
  return this->ObjectsMove() ? this->SetObjects(0.0) : 1;
}

int vtkSnowAccumulationFilter::AdvanceState(double t0, double t1) {
  if (this->ObjectsTemporal && this->GetTemporalInputTime(1) != this->ObjectsReadAt) {
    // The objects' next time step holds from t0 on.
    if (!this->ReadObjects(this->GetTemporalInput(1)) || !this->SetObjects(t0)) {
      return ADVANCE_FAILED;
    }
    this->ObjectsReadAt = this->GetTemporalInputTime(1);
  }
  // A progress callback that asked to stop leaves the core refusing steps
  // until it is set again; an abort consumed since must not stop this call.
  gr_snow_accumulation_set_progress(this->Simulation, &vtkGraupelSimulation::ThrottledProgress,
                                    this);
  // Steps of TimeStep from t0, the last one ending on t1.
  const double dt = this->TimeStep;
  const long long n = CountSteps(t0, t1, dt);
  const bool moving = this->ObjectsMove();
  double t = t0;
  for (long long k = 1; k <= n; ++k) {
    const double next = StepEnd(t0, t1, dt, k, n);
    if (moving && !this->SetObjects(next)) {
      return ADVANCE_FAILED;
    }
    const gr_status st = gr_snow_accumulation_step(this->Simulation, next - t);
    if (st == GR_ERR_ABORTED) {
      return ADVANCE_ABORTED;
    }
    if (st != GR_OK) {
      return this->ReportFailure(st, "Snow Accumulation could not advance",
                                 gr_snow_accumulation_last_error(this->Simulation));
    }
    t = next;
  }
  return ADVANCE_DONE;
}

int vtkSnowAccumulationFilter::SaveState(std::vector<unsigned char> &bytes) {
  size_t size = 0;
  if (gr_snow_accumulation_state_size(this->Simulation, &size) != GR_OK) {
    return 0;
  }
  bytes.resize(size);
  return gr_snow_accumulation_state_save(this->Simulation, bytes.data(), size) == GR_OK;
}

int vtkSnowAccumulationFilter::LoadState(const std::vector<unsigned char> &bytes) {
  // An abort inside a step leaves the core refusing until set_progress.
  gr_snow_accumulation_set_progress(this->Simulation, &vtkGraupelSimulation::ThrottledProgress,
                                    this);
  return gr_snow_accumulation_state_load(this->Simulation, bytes.data(), bytes.size()) == GR_OK;
}

int vtkSnowAccumulationFilter::FillObjects(vtkDataObject *output, double t) {
  vtkDataObject *input = this->GetNumberOfInputConnections(1) ? this->GetTemporalInput(1) : nullptr;
  if (!input || !output) {
    return 1;
  }
  // One object at its pose with its snow per point.
  auto snowy = [this, t](size_t k, vtkPolyData *leaf) -> vtkSmartPointer<vtkPolyData> {
    double matrix[16];
    this->Pose(k, t, matrix);
    vtkSmartPointer<vtkPolyData> posed = Posed(leaf, this->Objects[k].centre, matrix);
    const int points = static_cast<int>(leaf->GetNumberOfPoints());
    vtkNew<vtkFloatArray> depth;
    depth->SetName("snow_depth");
    depth->SetNumberOfTuples(points);
    vtkNew<vtkFloatArray> offset;
    offset->SetName("snow_offset");
    offset->SetNumberOfComponents(3);
    offset->SetNumberOfTuples(points);
    const int o = static_cast<int>(k);
    gr_status st = gr_snow_accumulation_get_object_field(this->Simulation, o, GR_FIELD_SNOW_DEPTH,
                                                         depth->GetPointer(0), points);
    if (st == GR_OK) {
      st = gr_snow_accumulation_get_object_offsets(this->Simulation, o, offset->GetPointer(0),
                                                   points);
    }
    if (st != GR_OK) {
      this->ReportFailure(st, "Snow Accumulation could not read the objects' snow",
                          gr_snow_accumulation_last_error(this->Simulation));
      return nullptr;
    }
    posed->GetPointData()->AddArray(depth);
    posed->GetPointData()->AddArray(offset);
    posed->GetPointData()->SetActiveScalars("snow_depth");
    posed->GetPointData()->SetActiveVectors("snow_offset");
    return posed;
  };
  return graupel::FillObjectsOutput(input, output, this->Objects.size(), snowy) ? 1 : 0;
}

int vtkSnowAccumulationFilter::FillOutput(vtkDataObject *outputObject, vtkInformation *outInfo) {
  const int fields[] = {GR_FIELD_SNOW_DEPTH, GR_FIELD_SNOW_SURFACE, GR_FIELD_SNOW_DENSITY,
                        GR_FIELD_EXPOSURE, GR_FIELD_ELEVATION};
  if (!this->FillImage(
          outputObject, outInfo, fields, static_cast<int>(sizeof(fields) / sizeof(fields[0])),
          [this](int f, float *values) {
            return static_cast<int>(
                gr_snow_accumulation_get_field(this->Simulation, static_cast<gr_field>(f), values));
          },
          [this]() { return gr_snow_accumulation_last_error(this->Simulation); })) {
    return 0;
  }
  vtkImageData *output = vtkImageData::SafeDownCast(outputObject);

  gr_snow_accumulation_ledger ledger;
  const gr_status st = gr_snow_accumulation_ledger_get(this->Simulation, &ledger);
  if (st != GR_OK) {
    return this->ReportFailure(st, "Snow Accumulation could not read its ledger",
                               gr_snow_accumulation_last_error(this->Simulation));
  }
  vtkFieldData *fd = output->GetFieldData();
  // The state's absolute time: the ledger's sum of steps drifts by rounding.
  AddValue(fd, "time", this->GetStateTime());
  AddValue(fd, "steps", static_cast<double>(ledger.steps));
  AddValue(fd, "initial_volume", ledger.initial_volume);
  AddValue(fd, "snowfall_volume", ledger.snowfall_volume);
  AddValue(fd, "stored_volume", ledger.stored_volume);
  AddValue(fd, "stored_volume_terrain", ledger.stored_volume_terrain);
  AddValue(fd, "stored_volume_objects", ledger.stored_volume_objects);
  AddValue(fd, "shed_volume", ledger.shed_volume);
  AddValue(fd, "dropped_volume", ledger.dropped_volume);
  AddValue(fd, "balance_error", ledger.balance_error);

  // The objects and their textures, at the same time.
  return this->FillObjectOutputs();
}

int vtkSnowAccumulationFilter::FillObjectOutput(int port, vtkDataObject *output, double t) {
  if (port == 1) {
    return this->FillObjects(output, t);
  }
  auto *textures = vtkMultiBlockDataSet::SafeDownCast(output);
  return !textures || this->FillTextures(textures) ? 1 : 0;
}

int vtkSnowAccumulationFilter::FillTextures(vtkMultiBlockDataSet *output) {
  const unsigned int n = static_cast<unsigned int>(this->Objects.size());
  output->SetNumberOfBlocks(n);
  for (unsigned int k = 0; k < n; ++k) {
    vtkNew<vtkImageData> image;
    const graupel::Object &o = this->Objects[k];
    const int size = this->AccumulationTextureSize;
    if (!o.uv.empty() && size > 0) {
      // Texel centres in UV units: texel (i, j) at ((i + 0.5) / size, (j + 0.5) / size).
      image->SetDimensions(size, size, 1);
      image->SetSpacing(1.0 / size, 1.0 / size, 1.0);
      image->SetOrigin(0.5 / size, 0.5 / size, 0.0);
      vtkNew<vtkFloatArray> depth;
      depth->SetName("snow_depth");
      depth->SetNumberOfTuples(static_cast<vtkIdType>(size) * size);
      const gr_status st = gr_snow_accumulation_get_object_texture(
          this->Simulation, static_cast<int>(k), depth->GetPointer(0), size);
      if (st != GR_OK) {
        return this->ReportFailure(st, "Snow Accumulation could not read an accumulation texture",
                                   gr_snow_accumulation_last_error(this->Simulation));
      }
      image->GetPointData()->AddArray(depth);
      image->GetPointData()->SetActiveScalars("snow_depth");
    }
    output->SetBlock(k, image);
  }
  return 1;
}

void vtkSnowAccumulationFilter::ReleaseState() {
  gr_snow_accumulation_destroy(this->Simulation);
  this->Simulation = nullptr;
}

void vtkSnowAccumulationFilter::PrintSelf(ostream &os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  os << indent << "TimeStep: " << this->TimeStep << " s\n";
  os << indent << "SnowDirection: " << this->SnowDirection[0] << " " << this->SnowDirection[1]
     << " " << this->SnowDirection[2] << "\n";
  os << indent << "Flutter: " << this->Flutter << " deg\n";
  os << indent << "SnowfallRate: " << this->SnowfallRate << " cm/h\n";
  os << indent << "NoiseAmplitude: " << this->NoiseAmplitude << "\n";
  os << indent << "NoiseScale: " << this->NoiseScale << " m\n";
  os << indent << "Seed: " << this->Seed << "\n";
  os << indent << "ExposureResolution: " << this->ExposureResolution << "\n";
  os << indent << "BlurRadius: " << this->BlurRadius << "\n";
  os << indent << "Dilation: " << this->Dilation << "\n";
  os << indent << "MaxDepth: " << this->MaxDepth << " m\n";
  os << indent << "StabilityFactor: " << this->StabilityFactor << " 1/s\n";
  os << indent << "SnowDensity: " << this->SnowDensity << " kg/m^3\n";
  os << indent << "AccumulationTextureSize: " << this->AccumulationTextureSize << "\n";
  this->PrintObjectMotion(os, indent);
}
