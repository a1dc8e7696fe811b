#include "vtkWaterSurfaceFilter.h"

#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include "graupel/water_surface.h"

#include "GraupelArrays.h"
#include "GraupelParameterTable.h"
#include "GraupelPieces.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <limits>
#include <vector>

vtkStandardNewMacro(vtkWaterSurfaceFilter);

namespace {
using graupel::AddValue;
using graupel::AsFloat;

// The core's ring for DropRadius on rows dy apart; the widest ring when the
// spacing is not known yet (a wider ring than needed is accepted).
int Ring(double dropRadius, double dy) {
  gr_water_surface_params p;
  gr_water_surface_params_init(&p);
  int count = 0;
  const gr_param_bound *b =
      gr_param_find(gr_water_surface_param_bounds(&count), count, "DropRadius");
  if (b && dropRadius > 0.0 && dropRadius <= b->max) {
    p.drop_radius = dropRadius;
  }
  return dy > 0.0 ? gr_water_surface_ghost(&p, dy) : gr_water_surface_ghost(&p, 1e-30);
}
} // namespace

vtkWaterSurfaceFilter::vtkWaterSurfaceFilter() {
  // Rain Runoff's water is read at its end (InputTime); FollowInputTime
  // makes the ripples follow it in time.
  // Ripples live for seconds: a minute in half-second frames.
  this->SetTimeDefaults(60.0, 0.5);
  // The core runs as pieces of a split domain (an MPI run's strips); its
  // ring follows DropRadius and the spacing (RequestInformation sets it).
  this->SetPieceRing(Ring(this->DropRadius, 0.0));
}

int vtkWaterSurfaceFilter::RequestInformation(vtkInformation *request,
                                              vtkInformationVector **inputVector,
                                              vtkInformationVector *outputVector) {
  // The ring, 1 + the drops' reach in rows (gr_water_surface_ghost): a
  // property change comes through here before the next RequestData plans
  // the pieces.
  vtkInformation *in = inputVector[0]->GetInformationObject(0);
  double dy = 0.0;
  if (in && in->Has(vtkDataObject::SPACING())) {
    dy = in->Get(vtkDataObject::SPACING())[1];
  }
  this->SetPieceRing(Ring(this->DropRadius, dy));
  return this->Superclass::RequestInformation(request, inputVector, outputVector);
}

vtkWaterSurfaceFilter::~vtkWaterSurfaceFilter() {
  this->ReleaseState();
}

GRAUPEL_TABLE_SETTER(vtkWaterSurfaceFilter, WaveSpeed, double, gr_water_surface_param_bounds)
GRAUPEL_TABLE_SETTER(vtkWaterSurfaceFilter, Damping, double, gr_water_surface_param_bounds)
GRAUPEL_TABLE_SETTER(vtkWaterSurfaceFilter, WetDepth, double, gr_water_surface_param_bounds)
GRAUPEL_TABLE_SETTER(vtkWaterSurfaceFilter, UseLakeLevel, int, gr_water_surface_param_bounds)
GRAUPEL_TABLE_SETTER(vtkWaterSurfaceFilter, LakeLevel, double, gr_water_surface_param_bounds)
GRAUPEL_TABLE_SETTER(vtkWaterSurfaceFilter, DropRate, double, gr_water_surface_param_bounds)
GRAUPEL_TABLE_SETTER(vtkWaterSurfaceFilter, DropAmplitude, double, gr_water_surface_param_bounds)
GRAUPEL_TABLE_SETTER(vtkWaterSurfaceFilter, DropRadius, double, gr_water_surface_param_bounds)
GRAUPEL_TABLE_SETTER(vtkWaterSurfaceFilter, Seed, int, gr_water_surface_param_bounds)
GRAUPEL_TABLE_SETTER(vtkWaterSurfaceFilter, CourantNumber, double, gr_water_surface_param_bounds)

int vtkWaterSurfaceFilter::CheckParameters() {
  const struct {
    const char *property;
    double value;
  } values[] = {
      {"WaveSpeed", this->WaveSpeed},         {"Damping", this->Damping},
      {"WetDepth", this->WetDepth},           {"UseLakeLevel", double(this->UseLakeLevel)},
      {"LakeLevel", this->LakeLevel},         {"DropRate", this->DropRate},
      {"DropAmplitude", this->DropAmplitude}, {"DropRadius", this->DropRadius},
      {"Seed", double(this->Seed)},           {"CourantNumber", this->CourantNumber}};
  int count = 0;
  const gr_param_bound *table = gr_water_surface_param_bounds(&count);
  for (const auto &p : values) {
    if (!this->ReportError(graupel::OutOfRange("Water Surface", p.property,
                                               gr_param_find(table, count, p.property), p.value))) {
      return 0;
    }
  }
  return 1;
}

int vtkWaterSurfaceFilter::ReadWater(vtkDataObject *input) {
  vtkImageData *image = vtkImageData::SafeDownCast(input);
  if (!image) {
    vtkErrorMacro("Water Surface needs an image on its Input.");
    return 0;
  }
  int dims[3];
  image->GetDimensions(dims);
  if (dims[0] != this->Dimensions[0] || dims[1] != this->Dimensions[1] || dims[2] != 1) {
    vtkErrorMacro("Water Surface's Input changed its grid in time ("
                  << this->Dimensions[0] << " x " << this->Dimensions[1] << " to " << dims[0]
                  << " x " << dims[1] << " x " << dims[2]
                  << "); give it one grid at every time step.");
    return 0;
  }
  vtkDataArray *elevation = this->GetElevation(image, "Input");
  if (!elevation) {
    return 0;
  }
  vtkDataArray *depth = image->GetPointData()->GetArray("water_depth");
  if (!depth && !this->UseLakeLevel) {
    vtkErrorMacro("Water Surface has no water: its Input has no point array water_depth and "
                  "UseLakeLevel is off. Connect Rain Runoff's output (or an image with "
                  "water_depth), or turn UseLakeLevel on with a LakeLevel (m) above the ground.");
    return 0;
  }
  const vtkIdType n = static_cast<vtkIdType>(dims[0]) * dims[1];
  struct Upload {
    gr_field field;
    vtkDataArray *array;
  } uploads[] = {{GR_FIELD_ELEVATION, elevation}, {GR_FIELD_WATER_DEPTH, depth}};
  for (const Upload &u : uploads) {
    if (!u.array) {
      continue;
    }
    vtkSmartPointer<vtkFloatArray> values = AsFloat(u.array);
    if (values->GetNumberOfComponents() != 1 || values->GetNumberOfTuples() != n) {
      vtkErrorMacro("Water Surface's Input array '" << gr_field_name(u.field)
                                                    << "' must have one value per point.");
      return 0;
    }
    // A split run's local array: its strip and ring.
    const std::vector<float> local =
        this->GetPieces().LocalField(values->GetPointer(0), dims[0], 1);
    const gr_status st = gr_water_surface_set_field(this->Simulation, u.field, local.data());
    if (st != GR_OK) {
      return this->ReportFailure(st, "Water Surface could not use its Input",
                                 gr_water_surface_last_error(this->Simulation));
    }
  }
  return 1;
}

int vtkWaterSurfaceFilter::SetUpState(vtkInformationVector **inputVector) {
  vtkImageData *terrain = vtkImageData::GetData(inputVector[0]);
  if (!terrain) {
    vtkErrorMacro("Water Surface needs an image on its Input: a terrain with elevation, or Rain "
                  "Runoff's output.");
    return 0;
  }
  int dims[3];
  terrain->GetDimensions(dims);
  double spacing[3];
  terrain->GetSpacing(spacing);
  if (dims[0] < 2 || dims[1] < 2 || dims[2] != 1) {
    vtkErrorMacro("Water Surface needs a 2-D image of at least 2 x 2 points on its Input; it got "
                  << dims[0] << " x " << dims[1] << " x " << dims[2]
                  << ". Slice a volume or resample the terrain first.");
    return 0;
  }
  if (!(spacing[0] > 0.0) || !(spacing[1] > 0.0)) {
    vtkErrorMacro("Water Surface needs a spacing above 0 m in x and y; the Input has "
                  << spacing[0] << " x " << spacing[1] << " m. Set the spacing on the source.");
    return 0;
  }
  if (!this->CheckParameters()) {
    return 0;
  }
  gr_water_surface_params p;
  gr_water_surface_params_init(&p);
  p.wave_speed = this->WaveSpeed;
  p.damping = this->Damping;
  p.wet_depth = this->WetDepth;
  p.use_lake_level = this->UseLakeLevel;
  p.lake_level = this->LakeLevel;
  p.drop_rate = this->DropRate;
  p.drop_amplitude = this->DropAmplitude;
  p.drop_radius = this->DropRadius;
  p.seed = this->Seed;
  p.cfl = this->CourantNumber;
  gr_grid grid;
  TerrainGrid(terrain, &grid);
  this->Dimensions[0] = dims[0];
  this->Dimensions[1] = dims[1];
  // A split run's strip: its rows, its ring and the whole domain around it.
  // The core exchanges a row of wave height with the neighbouring ranks
  // every step and reduces the ledger over the ranks, so every rank's waves
  // and ledger are the whole grid's.
  graupel::Pieces &pieces = this->GetPieces();
  pieces.PieceGrid(&grid);
  gr_context *ctx = this->GetContext();
  if (!ctx) {
    return 0;
  }
  // The core's state on this rank's piece, the output's fields (wave height,
  // surface, normal, wet, elevation, depth: 8 floats) and the water's two
  // staging planes.
  gr_memory_need need;
  gr_water_surface_memory(&grid, &need);
  if (!this->CheckMemory(grid, need, 4.0 * (8 + 2))) {
    return 0;
  }
  gr_status st = gr_water_surface_create(ctx, &grid, &p, &this->Simulation);
  if (st != GR_OK) {
    return this->ReportFailure(st, "Water Surface could not set up the simulation");
  }
  if (pieces.IsSplit()) {
    gr_water_surface *sim = this->Simulation;
    pieces.BindHalo(
        [sim](int side, size_t *bytes) { return gr_water_surface_halo_size(sim, side, bytes); },
        [sim](int side, void *host, size_t bytes) {
          return gr_water_surface_halo_get(sim, side, host, bytes);
        },
        [sim](int side, const void *host, size_t bytes) {
          return gr_water_surface_halo_set(sim, side, host, bytes);
        });
    gr_water_surface_set_allreduce(sim, graupel::Pieces::Allreduce, &pieces);
    gr_water_surface_set_halo_exchange(sim, graupel::Pieces::Exchange, &pieces);
  }
  if (!this->ReadWater(terrain)) {
    this->ReleaseState();
    return 0;
  }
  // Finds the water now. A terrain without a wet point is refused at once;
  // Rain Runoff's water in time may be dry at first (the storm has not
  // gathered yet).
  gr_water_surface_ledger ledger;
  st = gr_water_surface_ledger_get(this->Simulation, &ledger);
  if (st != GR_OK) {
    this->ReportFailure(st, "Water Surface", gr_water_surface_last_error(this->Simulation));
    this->ReleaseState();
    return 0;
  }
  if (ledger.wet_points == 0 && !this->IsInputTemporal(0)) {
    vtkDataArray *elevation = this->TerrainHeights(terrain);
    vtkDataArray *depth = terrain->GetPointData()->GetArray("water_depth");
    if (this->UseLakeLevel) {
      vtkErrorMacro("Water Surface has no water: no elevation of the Input lies below LakeLevel ("
                    << this->LakeLevel << " m; the lowest ground is " << elevation->GetRange(0)[0]
                    << " m). Raise LakeLevel above the lowest ground.");
    } else {
      vtkErrorMacro("Water Surface has no water: no water_depth of the Input exceeds WetDepth ("
                    << this->WetDepth << " m; the deepest water is " << depth->GetRange(0)[1]
                    << " m). Lower WetDepth, or give it deeper water.");
    }
    this->ReleaseState();
    return 0;
  }
  this->WaterReadAt = this->GetTemporalInputTime(0);
  gr_water_surface_set_progress(this->Simulation, &vtkGraupelSimulation::CoreProgress, this);
  return 1;
}

int vtkWaterSurfaceFilter::ResetState() {
  // The input is read again before the next step (it may be of another time).
  this->WaterReadAt = std::numeric_limits<double>::quiet_NaN();
  const gr_status st = gr_water_surface_reset(this->Simulation);
  if (st != GR_OK) {
    return this->ReportFailure(st, "Water Surface could not restart",
                               gr_water_surface_last_error(this->Simulation));
  }
  // Water followed in time: the time step that holds from 0 on (the one this
  // pass delivers) is read now, so that the output at time 0, which no
  // advance precedes, shows it as the set-up's does, not the last one read.
  if (this->IsInputTemporal(0)) {
    if (!this->ReadWater(this->GetTemporalInput(0))) {
      return 0;
    }
    this->WaterReadAt = this->GetTemporalInputTime(0);
  }
  return 1;
}

int vtkWaterSurfaceFilter::AdvanceState(double t0, double t1) {
  if (!(this->GetTemporalInputTime(0) == this->WaterReadAt)) {
    // The input's water at its time step that holds from t0 on.
    if (!this->ReadWater(this->GetTemporalInput(0))) {
      return ADVANCE_FAILED;
    }
    this->WaterReadAt = this->GetTemporalInputTime(0);
  }
  const gr_status st = gr_water_surface_advance(this->Simulation, t1 - t0, nullptr);
  if (st == GR_ERR_ABORTED) {
    return ADVANCE_ABORTED;
  }
  return st == GR_OK ? ADVANCE_DONE
                     : this->ReportFailure(st, "Water Surface could not advance",
                                           gr_water_surface_last_error(this->Simulation));
}

int vtkWaterSurfaceFilter::SaveState(std::vector<unsigned char> &bytes) {
  size_t size = 0;
  if (gr_water_surface_state_size(this->Simulation, &size) != GR_OK) {
    return 0;
  }
  bytes.resize(size);
  return gr_water_surface_state_save(this->Simulation, bytes.data(), size) == GR_OK;
}

int vtkWaterSurfaceFilter::LoadState(const std::vector<unsigned char> &bytes) {
  this->WaterReadAt = std::numeric_limits<double>::quiet_NaN();
  return gr_water_surface_state_load(this->Simulation, bytes.data(), bytes.size()) == GR_OK;
}

int vtkWaterSurfaceFilter::FillOutput(vtkDataObject *outputObject, vtkInformation *outInfo) {
  const gr_water_surface_output outputs[] = {GR_WATER_WAVE_HEIGHT, GR_WATER_SURFACE,
                                             GR_WATER_NORMAL,      GR_WATER_WET,
                                             GR_WATER_ELEVATION,   GR_WATER_DEPTH};
  std::vector<ImageArray> arrays;
  for (gr_water_surface_output o : outputs) {
    arrays.push_back({gr_water_surface_output_name(o), gr_water_surface_output_components(o),
                      [this, o](float *values) {
                        return static_cast<int>(gr_water_surface_get(this->Simulation, o, values));
                      }});
  }
  if (!this->FillImage(outputObject, outInfo, arrays,
                       [this] { return gr_water_surface_last_error(this->Simulation); })) {
    return 0;
  }
  vtkImageData *output = vtkImageData::SafeDownCast(outputObject);
  output->GetPointData()->SetActiveNormals("normal");
  gr_water_surface_ledger ledger;
  const gr_status st = gr_water_surface_ledger_get(this->Simulation, &ledger);
  if (st != GR_OK) {
    return this->ReportFailure(st, "Water Surface could not read its ledger",
                               gr_water_surface_last_error(this->Simulation));
  }
  vtkFieldData *fd = output->GetFieldData();
  AddValue(fd, "time", ledger.time);
  AddValue(fd, "steps", static_cast<double>(ledger.steps));
  AddValue(fd, "wet_points", static_cast<double>(ledger.wet_points));
  AddValue(fd, "wave_volume", ledger.wave_volume);
  AddValue(fd, "initial_volume", ledger.initial_volume);
  AddValue(fd, "energy", ledger.energy);
  AddValue(fd, "max_wave", ledger.max_wave);
  return 1;
}

void vtkWaterSurfaceFilter::ReleaseState() {
  gr_water_surface_destroy(this->Simulation);
  this->Simulation = nullptr;
}

void vtkWaterSurfaceFilter::PrintSelf(ostream &os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  os << indent << "WaveSpeed: " << this->WaveSpeed << " m/s\n";
  os << indent << "Damping: " << this->Damping << " 1/s\n";
  os << indent << "WetDepth: " << this->WetDepth << " m\n";
  os << indent << "UseLakeLevel: " << this->UseLakeLevel << "\n";
  os << indent << "LakeLevel: " << this->LakeLevel << " m\n";
  os << indent << "DropRate: " << this->DropRate << " 1/(m^2 s)\n";
  os << indent << "DropAmplitude: " << this->DropAmplitude << " m\n";
  os << indent << "DropRadius: " << this->DropRadius << " m\n";
  os << indent << "Seed: " << this->Seed << "\n";
  os << indent << "CourantNumber: " << this->CourantNumber << "\n";
}
