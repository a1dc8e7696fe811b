#include "vtkSnowDeformationFilter.h"

#include "vtkDoubleArray.h"
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

#include "graupel/snow_deformation.h"

#include "GraupelArrays.h"
#include "GraupelObjects.h"
#include "GraupelParameterTable.h"
#include "GraupelPieces.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkSnowDeformationFilter);

namespace {
using graupel::AddValue;
using graupel::AsFloat;
using graupel::Posed;
const gr_param_bound *Bound(const char *property) {
  return graupel::TableRow(gr_snow_deformation_param_bounds, property);
}

// rho min and rho max (kg/m^3) per DensityPresets value from 1 on. The snow
// types are the thesis' Table 3.1 (seed 000, L887-L898, "Dichtevergleich
// unterschiedlicher Schneearten"). Sand is not in the thesis, which asks
// only for close ends (little compression) and a lower MaxSlope (L2993-L3002):
// 1500-1700 is dry sand's bulk density from loose to packed as soil-mechanics
// handbooks tabulate it (about 1.5-1.7 g/cm^3).
const double DensityPresetTable[][2] = {
    {30.0, 50.0},    // DRY_NEW_SNOW: trockener, lockerer Neuschnee
    {50.0, 100.0},   // BONDED_NEW_SNOW: gebundener Neuschnee
    {100.0, 200.0},  // STRONGLY_BONDED_NEW_SNOW: stark gebundener Neuschnee
    {200.0, 400.0},  // DRY_OLD_SNOW: trockener Altschnee
    {300.0, 500.0},  // WET_OLD_SNOW: feuchtnasser Altschnee
    {150.0, 300.0},  // DEPTH_HOAR: Schwimmschnee
    {500.0, 800.0},  // FIRN: mehrjaehriger Firn
    {800.0, 900.0},  // ICE: Eis
    {1500.0, 1700.0} // SAND
};

double TableDefault(const char *property) {
  return graupel::TableDefault(gr_snow_deformation_param_bounds, property);
}

void AddForce(vtkFieldData *fd, const double force[3], double peak, double area) {
  vtkNew<vtkDoubleArray> f;
  f->SetName("force");
  f->SetNumberOfComponents(3);
  f->InsertNextTuple(force);
  fd->AddArray(f);
  AddValue(fd, "peak_force", peak);
  AddValue(fd, "contact_area", area);
}

} // namespace

vtkSnowDeformationFilter::vtkSnowDeformationFilter()
    // Closed meshes: points at the same place are one vertex.
    : vtkGraupelObjectsSimulation(GR_SNOW_DEFORMATION_MAX_OBJECTS, true, 1) {
  this->SetNumberOfOutputPorts(2);
  // Steps of 1/60 s: 600 outputs of 10 s would be 36000 steps, and a wheel
  // at 2 m/s would move 20 m between outputs. 10 s of 0.25 s outputs show a
  // crossing of a few metres, 15 steps per output.
  this->SetTimeDefaults(10.0, 0.25);
  // The core runs as pieces of a split domain (an MPI run's strips).
  this->SetPieceRing(GR_SNOW_DEFORMATION_GHOST);
  this->MaxRelaxIterations = static_cast<int>(TableDefault("MaxRelaxIterations"));
  this->RelaxTolerance = TableDefault("RelaxTolerance");
  this->SlumpSpeed = TableDefault("SlumpSpeed");
}

vtkSnowDeformationFilter::~vtkSnowDeformationFilter() {
  this->ReleaseState();
}

GRAUPEL_CLAMP_SETTER(vtkSnowDeformationFilter, TimeStep, double, 1.0e-6, 60.0, "s")
GRAUPEL_TABLE_SETTER(vtkSnowDeformationFilter, InitialSnowDepth, double,
                     gr_snow_deformation_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowDeformationFilter, InitialDensity, double,
                     gr_snow_deformation_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowDeformationFilter, MinDensity, double, gr_snow_deformation_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowDeformationFilter, MaxDensity, double, gr_snow_deformation_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowDeformationFilter, CompressionModel, int,
                     gr_snow_deformation_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowDeformationFilter, MaxSlope, double, gr_snow_deformation_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowDeformationFilter, DirectionFalloff, double,
                     gr_snow_deformation_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowDeformationFilter, MaxRelaxIterations, int,
                     gr_snow_deformation_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowDeformationFilter, RelaxTolerance, double,
                     gr_snow_deformation_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowDeformationFilter, SlumpSpeed, double, gr_snow_deformation_param_bounds)

void vtkSnowDeformationFilter::SetDensityRange(double minimum, double maximum) {
  this->SetMinDensity(minimum);
  this->SetMaxDensity(maximum);
}

void vtkSnowDeformationFilter::GetDensityRange(double range[2]) const {
  range[0] = this->MinDensity;
  range[1] = this->MaxDensity;
}

bool vtkSnowDeformationFilter::GetDensityPresetRange(int preset, double range[2]) {
  if (preset <= CUSTOM || preset > SAND) {
    return false;
  }
  range[0] = DensityPresetTable[preset - 1][0];
  range[1] = DensityPresetTable[preset - 1][1];
  return true;
}

void vtkSnowDeformationFilter::GetDensityRangeInUse(double range[2]) const {
  if (!GetDensityPresetRange(this->DensityPreset, range)) {
    this->GetDensityRange(range);
  }
}

double vtkSnowDeformationFilter::GetInitialDensityInUse() const {
  double range[2];
  // A preset's snow starts loose: it compresses towards the type's rho max.
  return GetDensityPresetRange(this->DensityPreset, range) ? range[0] : this->InitialDensity;
}

int vtkSnowDeformationFilter::FillOutputPortInformation(int port, vtkInformation *info) {
  // Port 1 follows the Objects input's type (REQUEST_DATA_OBJECT below).
  info->Set(vtkDataObject::DATA_TYPE_NAME(), port == 0 ? "vtkImageData" : "vtkDataObject");
  return 1;
}

int vtkSnowDeformationFilter::CheckParameters() {
  // The table's rows MinDensity and MaxDensity are DensityRange's two values.
  const bool custom = this->DensityPreset == CUSTOM;
  double range[2];
  this->GetDensityRangeInUse(range);
  const struct {
    const char *property;
    const char *name; // as the user sets it
    double value;
  } values[] = {{"InitialSnowDepth", "InitialSnowDepth", this->InitialSnowDepth},
                {"InitialDensity", "InitialDensity", this->GetInitialDensityInUse()},
                {"MinDensity", "DensityRange's first value (rho min)", range[0]},
                {"MaxDensity", "DensityRange's second value (rho max)", range[1]},
                {"CompressionModel", "CompressionModel", double(this->CompressionModel)},
                {"MaxSlope", "MaxSlope", this->MaxSlope},
                {"DirectionFalloff", "DirectionFalloff", this->DirectionFalloff},
                {"MaxRelaxIterations", "MaxRelaxIterations", double(this->MaxRelaxIterations)},
                {"RelaxTolerance", "RelaxTolerance", this->RelaxTolerance},
                {"SlumpSpeed", "SlumpSpeed", this->SlumpSpeed}};
  for (const auto &p : values) {
    if (!this->ReportError(
            graupel::OutOfRange("Snow Deformation", p.name, Bound(p.property), p.value))) {
      return 0;
    }
  }
  if (!(this->TimeStep >= 1.0e-6 && this->TimeStep <= 60.0)) {
    vtkErrorMacro("Snow Deformation: TimeStep must be from 1e-6 s to 60 s; it is "
                  << this->TimeStep << " s. Set it within that range.");
    return 0;
  }
  if (custom && !(this->MinDensity <= this->MaxDensity)) {
    vtkErrorMacro("Snow Deformation: DensityRange runs backwards, from "
                  << this->MinDensity << " to " << this->MaxDensity
                  << " kg/m^3; give rho min first (swap the two values).");
    return 0;
  }
  if (custom &&
      !(this->InitialDensity >= this->MinDensity && this->InitialDensity <= this->MaxDensity)) {
    vtkErrorMacro("Snow Deformation: InitialDensity ("
                  << this->InitialDensity << " kg/m^3) lies outside DensityRange ("
                  << this->MinDensity << " to " << this->MaxDensity
                  << " kg/m^3); set it within the range or pick a DensityPreset.");
    return 0;
  }
  return this->CheckObjectMotion();
}

int vtkSnowDeformationFilter::CheckObjectsReachGrid(const double grid[4], double margin) {
  if (this->ObjectsTemporal || this->Objects.empty()) {
    return 1;
  }
  // The step ends AdvanceState takes (t0 + j dt within each output interval,
  // the last on the output time), so the test is exact; past 1e5 steps,
  // 1e5 even samples, each box widened by what the object can move between
  // two (the speed times the gap, plus its radius for any turn), so that an
  // object is never refused that a step could bring over the grid.
  std::vector<double> times;
  const int outputs = this->GetNumberOfOutputTimes();
  const double dt = this->TimeStep;
  const double end = outputs > 0 ? this->GetOutputTime(outputs - 1) : 0.0;
  const double limit = 1.0e5;
  const bool exact = end / dt < limit;
  times.push_back(0.0);
  if (exact) {
    for (int k = 1; k < outputs; ++k) {
      const double t0 = this->GetOutputTime(k - 1), t1 = this->GetOutputTime(k);
      const long long n = CountSteps(t0, t1, dt);
      for (long long j = 1; j <= n; ++j) {
        times.push_back(StepEnd(t0, t1, dt, j, n));
      }
    }
  } else {
    for (int j = 1; j <= static_cast<int>(limit); ++j) {
      times.push_back(end * j / limit);
    }
  }
  for (size_t k = 0; k < this->Objects.size(); ++k) {
    const graupel::Object &o = this->Objects[k];
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (size_t v = 0; v + 2 < o.vertices.size(); v += 3) {
      for (int c = 0; c < 3; ++c) {
        lo[c] = std::min(lo[c], static_cast<double>(o.vertices[v + c]));
        hi[c] = std::max(hi[c], static_cast<double>(o.vertices[v + c]));
      }
    }
    double pad = margin;
    if (!exact) {
      const double *u = o.velocity;
      const double radius = std::sqrt(std::max(lo[0] * lo[0], hi[0] * hi[0]) +
                                      std::max(lo[1] * lo[1], hi[1] * hi[1]) +
                                      std::max(lo[2] * lo[2], hi[2] * hi[2]));
      pad += std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]) * end / limit + radius;
    }
    double first[4] = {0.0, 0.0, 0.0, 0.0};
    bool over = false;
    for (size_t n = 0; n < times.size() && !over; ++n) {
      double m[16];
      this->Pose(k, times[n], m);
      double box[4] = {1e300, -1e300, 1e300, -1e300};
      for (int corner = 0; corner < 8; ++corner) {
        const double p[3] = {(corner & 1) ? hi[0] : lo[0], (corner & 2) ? hi[1] : lo[1],
                             (corner & 4) ? hi[2] : lo[2]};
        for (int c = 0; c < 2; ++c) {
          const double w = m[c] * p[0] + m[4 + c] * p[1] + m[8 + c] * p[2] + m[12 + c];
          box[2 * c] = std::min(box[2 * c], w);
          box[2 * c + 1] = std::max(box[2 * c + 1], w);
        }
      }
      if (n == 0) {
        std::copy(box, box + 4, first);
      }
      over = box[1] >= grid[0] - pad && box[0] <= grid[1] + pad && box[3] >= grid[2] - pad &&
             box[2] <= grid[3] + pad;
    }
    if (!over) {
      vtkErrorMacro("Snow Deformation's Objects"
                    << (this->Objects.size() > 1 ? " block " + std::to_string(k) : std::string())
                    << " lies outside the terrain's grid at every step up to " << end
                    << " s: at 0 s it spans x " << first[0] << " to " << first[1] << " m, y "
                    << first[2] << " to " << first[3] << " m, and the grid x " << grid[0] << " to "
                    << grid[1] << " m, y " << grid[2] << " to " << grid[3]
                    << " m; move the object onto the grid or give it a motion that reaches it.");
      return 0;
    }
  }
  return 1;
}

int vtkSnowDeformationFilter::SetObjects(double t, double h) {
  const size_t n = this->Objects.size();
  std::vector<gr_mesh> meshes(n);
  std::vector<double> velocities(3 * n, 0.0);
  for (size_t k = 0; k < n; ++k) {
    const graupel::Object &o = this->Objects[k];
    gr_mesh &m = meshes[k];
    m = graupel::MeshOf(o);
    this->Pose(k, t, m.transform);
    if (!this->ObjectsTemporal && !this->Path.empty()) {
      // The centre's velocity over the step: along a path it turns with the
      // path and stops at its end.
      double before[16];
      this->Pose(k, t - h, before);
      for (int c = 0; c < 3; ++c) {
        velocities[3 * k + c] = h > 0.0 ? (m.transform[12 + c] - before[12 + c]) / h : 0.0;
      }
    } else {
      for (int c = 0; c < 3; ++c) {
        velocities[3 * k + c] = o.velocity[c];
      }
    }
  }
  const gr_status st = gr_snow_deformation_set_objects(
      this->Simulation, meshes.data(), static_cast<int>(n), n ? velocities.data() : nullptr);
  if (st != GR_OK) {
    return this->ReportFailure(st, "Snow Deformation's Objects",
                               gr_snow_deformation_last_error(this->Simulation));
  }
  return 1;
}

int vtkSnowDeformationFilter::SetUpState(vtkInformationVector **inputVector) {
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
  {
    // Before anything is copied: the core's state on this rank's piece, the
    // output's six fields and an upload's staging plane.
    gr_grid grid;
    TerrainGrid(terrain, &grid);
    this->GetPieces().PieceGrid(&grid);
    gr_memory_need need;
    gr_snow_deformation_memory(&grid, &need);
    if (!this->CheckMemory(grid, need, 4.0 * (6 + 1))) {
      return 0;
    }
  }
  const size_t npoints = static_cast<size_t>(dims[0]) * static_cast<size_t>(dims[1]);
  std::vector<graupel::Upload> uploads;
  uploads.push_back({GR_FIELD_ELEVATION, AsFloat(elevationArray)});
  vtkPointData *pd = terrain->GetPointData();
  if (vtkDataArray *depth = pd->GetArray("snow_depth")) {
    uploads.push_back({GR_FIELD_SNOW_DEPTH, AsFloat(depth)});
  }
  if (vtkDataArray *density = pd->GetArray("snow_density")) {
    uploads.push_back({GR_FIELD_SNOW_DENSITY, AsFloat(density)});
  }
  for (const graupel::Upload &u : uploads) {
    if (!this->ReportError(graupel::CheckPerPoint("Snow Deformation", u, npoints))) {
      return 0;
    }
  }

  if (!this->ReadObjectInputs(inputVector)) {
    return 0;
  }

  gr_snow_deformation_params p;
  gr_snow_deformation_params_init(&p);
  p.initial_snow_depth = this->InitialSnowDepth;
  double range[2];
  this->GetDensityRangeInUse(range);
  p.initial_density = this->GetInitialDensityInUse();
  p.min_density = range[0];
  p.max_density = range[1];
  p.compression_model = this->CompressionModel;
  p.max_slope = this->MaxSlope;
  p.direction_falloff = this->DirectionFalloff;
  p.max_relax_iterations = this->MaxRelaxIterations;
  p.relax_tolerance = this->RelaxTolerance;
  p.slump_speed = this->SlumpSpeed;
  char msg[512];
  if (gr_snow_deformation_params_validate(&p, msg, sizeof(msg)) != GR_OK) {
    vtkErrorMacro("Snow Deformation: " << msg);
    return 0;
  }
  gr_grid grid;
  TerrainGrid(terrain, &grid);
  const double gridBounds[4] = {grid.x0, grid.x0 + (grid.nx - 1) * grid.dx, grid.y0,
                                grid.y0 + (grid.ny - 1) * grid.dy};
  // The core gives an object whose box reaches within a spacing of the grid
  // its rows and columns; farther out it touches nothing.
  if (!this->CheckObjectsReachGrid(gridBounds, std::max(grid.dx, grid.dy))) {
    return 0;
  }
  // A split run's strip: its rows, its ring and the whole domain around it.
  // Every piece sets every object (the core rasterizes each over its own
  // arrays) and the core sums what steers a step, the forces included, over
  // the pieces through the allreduce: every rank's forces and ledger are
  // the whole grid's.
  graupel::Pieces &pieces = this->GetPieces();
  pieces.PieceGrid(&grid);
  gr_status st = gr_snow_deformation_create(this->GetContext(), &grid, &p, &this->Simulation);
  if (st != GR_OK) {
    return this->ReportFailure(st, "Snow Deformation could not set up the simulation");
  }
  if (pieces.IsSplit()) {
    gr_snow_deformation *sim = this->Simulation;
    pieces.BindHalo(
        [sim](int side, size_t *bytes) { return gr_snow_deformation_halo_size(sim, side, bytes); },
        [sim](int side, void *host, size_t bytes) {
          return gr_snow_deformation_halo_get(sim, side, host, bytes);
        },
        [sim](int side, const void *host, size_t bytes) {
          return gr_snow_deformation_halo_set(sim, side, host, bytes);
        });
    gr_snow_deformation_set_allreduce(sim, graupel::Pieces::Allreduce, &pieces);
    gr_snow_deformation_set_halo_exchange(sim, graupel::Pieces::Exchange, &pieces);
  }
  for (const graupel::Upload &u : uploads) {
    const std::vector<float> local = pieces.LocalField(u.values->GetPointer(0), dims[0], 1);
    st = gr_snow_deformation_set_field(this->Simulation, u.field, local.data());
    if (st != GR_OK) {
      vtkErrorMacro(
          "Snow Deformation's Input: " << gr_snow_deformation_last_error(this->Simulation));
      return 0;
    }
  }
  gr_snow_deformation_set_progress(this->Simulation, &vtkGraupelSimulation::ThrottledProgress,
                                   this);
  // The objects at time 0: the forces (zero) have their count before a step.
  return this->SetObjects(0.0, 0.0);
}

int vtkSnowDeformationFilter::ResetState() {
  const gr_status st = gr_snow_deformation_reset(this->Simulation);
  gr_snow_deformation_set_progress(this->Simulation, &vtkGraupelSimulation::ThrottledProgress,
                                   this);
  return st == GR_OK ? 1
                     : this->ReportFailure(st, "Snow Deformation could not restart",
                                           gr_snow_deformation_last_error(this->Simulation));
}

int vtkSnowDeformationFilter::AdvanceState(double t0, double t1) {
  if (this->ObjectsTemporal && this->GetTemporalInputTime(1) != this->ObjectsReadAt) {
    // The objects' next time step holds from t0 on.
    if (!this->ReadObjects(this->GetTemporalInput(1))) {
      return ADVANCE_FAILED;
    }
    this->ObjectsReadAt = this->GetTemporalInputTime(1);
  }
  // A progress callback that asked to stop leaves the core refusing steps
  // until it is set again; an abort consumed since must not stop this call.
  gr_snow_deformation_set_progress(this->Simulation, &vtkGraupelSimulation::ThrottledProgress,
                                   this);
  // An output interval starts: the mean force reported at the next output
  // is over it alone.
  if (this->IsOutputTime(t0)) {
    gr_snow_deformation_clear_impulses(this->Simulation);
  }
  // Steps of TimeStep from t0, the last one ending on t1.
  const double dt = this->TimeStep;
  const long long n = CountSteps(t0, t1, dt);
  double t = t0;
  for (long long k = 1; k <= n; ++k) {
    const double next = StepEnd(t0, t1, dt, k, n);
    if (!this->SetObjects(next, next - t)) {
      return ADVANCE_FAILED;
    }
    const gr_status st = gr_snow_deformation_step(this->Simulation, next - t);
    if (st == GR_ERR_ABORTED) {
      return ADVANCE_ABORTED;
    }
    if (st != GR_OK) {
      return this->ReportFailure(st, "Snow Deformation could not advance",
                                 gr_snow_deformation_last_error(this->Simulation));
    }
    t = next;
  }
  return ADVANCE_DONE;
}

int vtkSnowDeformationFilter::SaveState(std::vector<unsigned char> &bytes) {
  size_t size = 0;
  if (gr_snow_deformation_state_size(this->Simulation, &size) != GR_OK) {
    return 0;
  }
  bytes.resize(size);
  return gr_snow_deformation_state_save(this->Simulation, bytes.data(), size) == GR_OK;
}

int vtkSnowDeformationFilter::LoadState(const std::vector<unsigned char> &bytes) {
  // An abort inside a step leaves the core refusing until set_progress.
  gr_snow_deformation_set_progress(this->Simulation, &vtkGraupelSimulation::ThrottledProgress,
                                   this);
  return gr_snow_deformation_state_load(this->Simulation, bytes.data(), bytes.size()) == GR_OK;
}

int vtkSnowDeformationFilter::FillObjectOutput(int, vtkDataObject *output, double t) {
  vtkDataObject *input = this->GetNumberOfInputConnections(1) ? this->GetTemporalInput(1) : nullptr;
  if (!input || !output) {
    return 1;
  }
  const size_t n = this->Objects.size();
  // The force is the mean over the output interval that ends here (the
  // impulse since the last output over its time: AdvanceState clears it at
  // each output), not the last step's, which aliases with the step.
  std::vector<double> force(3 * n + 3, 0.0), peak(n + 1, 0.0), area(n + 1, 0.0);
  if (n > 0) {
    gr_status st = gr_snow_deformation_object_mean_forces(
        this->Simulation, force.data(), peak.data(), nullptr, static_cast<int>(n));
    if (st == GR_OK) {
      st = gr_snow_deformation_object_forces(this->Simulation, nullptr, area.data(),
                                             static_cast<int>(n));
    }
    if (st != GR_OK) {
      return this->ReportFailure(st, "Snow Deformation could not read the objects' forces",
                                 gr_snow_deformation_last_error(this->Simulation));
    }
  }
  auto posed = [this, t, &force, &peak, &area](size_t k, vtkPolyData *leaf) {
    double matrix[16];
    this->Pose(k, t, matrix);
    vtkSmartPointer<vtkPolyData> one = Posed(leaf, this->Objects[k].centre, matrix);
    AddForce(one->GetFieldData(), &force[3 * k], peak[k], area[k]);
    return one;
  };
  vtkMultiBlockDataSet *blocks = nullptr;
  if (!graupel::FillObjectsOutput(input, output, n, posed, &blocks)) {
    return 0;
  }
  if (blocks) {
    // The whole: every object's force and contact area summed.
    double total[3] = {0.0, 0.0, 0.0}, totalArea = 0.0, totalPeak = 0.0;
    for (size_t k = 0; k < n; ++k) {
      for (int c = 0; c < 3; ++c) {
        total[c] += force[3 * k + c];
      }
      totalArea += area[k];
      totalPeak = std::max(totalPeak, peak[k]);
    }
    AddForce(blocks->GetFieldData(), total, totalPeak, totalArea);
  }
  return 1;
}

int vtkSnowDeformationFilter::FillOutput(vtkDataObject *outputObject, vtkInformation *outInfo) {
  const int fields[] = {GR_FIELD_SNOW_DEPTH, GR_FIELD_SNOW_SURFACE, GR_FIELD_SNOW_DENSITY,
                        GR_FIELD_OVERLAP,    GR_FIELD_CONTACT,      GR_FIELD_ELEVATION};
  if (!this->FillImage(
          outputObject, outInfo, fields, static_cast<int>(sizeof(fields) / sizeof(fields[0])),
          [this](int f, float *values) {
            return static_cast<int>(
                gr_snow_deformation_get_field(this->Simulation, static_cast<gr_field>(f), values));
          },
          [this]() { return gr_snow_deformation_last_error(this->Simulation); })) {
    return 0;
  }
  vtkImageData *output = vtkImageData::SafeDownCast(outputObject);

  gr_snow_deformation_ledger ledger;
  const gr_status st = gr_snow_deformation_ledger_get(this->Simulation, &ledger);
  if (st != GR_OK) {
    return this->ReportFailure(st, "Snow Deformation could not read its ledger",
                               gr_snow_deformation_last_error(this->Simulation));
  }
  vtkFieldData *fd = output->GetFieldData();
  // The state's absolute time: the ledger's sum of steps drifts by rounding.
  AddValue(fd, "time", this->GetStateTime());
  AddValue(fd, "steps", static_cast<double>(ledger.steps));
  AddValue(fd, "initial_volume", ledger.initial_volume);
  AddValue(fd, "initial_mass", ledger.initial_mass);
  AddValue(fd, "snow_volume", ledger.snow_volume);
  AddValue(fd, "snow_mass", ledger.snow_mass);
  AddValue(fd, "compressed_volume", ledger.compressed_volume);
  AddValue(fd, "displaced_volume", ledger.displaced_volume);
  AddValue(fd, "balance_error", ledger.balance_error);
  AddValue(fd, "volume_error", ledger.volume_error);
  AddValue(fd, "relax_iterations", ledger.relax_iterations);

  // The objects with their forces, at the same time.
  return this->FillObjectOutputs();
}

void vtkSnowDeformationFilter::ReleaseState() {
  gr_snow_deformation_destroy(this->Simulation);
  this->Simulation = nullptr;
}

void vtkSnowDeformationFilter::PrintSelf(ostream &os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  os << indent << "TimeStep: " << this->TimeStep << " s\n";
  os << indent << "InitialSnowDepth: " << this->InitialSnowDepth << " m\n";
  os << indent << "InitialDensity: " << this->InitialDensity << " kg/m^3\n";
  os << indent << "DensityRange: " << this->MinDensity << " " << this->MaxDensity << " kg/m^3\n";
  os << indent << "DensityPreset: " << this->DensityPreset << "\n";
  os << indent << "CompressionModel: " << this->CompressionModel << "\n";
  os << indent << "MaxSlope: " << this->MaxSlope << " m/m\n";
  os << indent << "DirectionFalloff: " << this->DirectionFalloff << "\n";
  os << indent << "MaxRelaxIterations: " << this->MaxRelaxIterations << "\n";
  os << indent << "RelaxTolerance: " << this->RelaxTolerance << " m\n";
  os << indent << "SlumpSpeed: " << this->SlumpSpeed << " m/s\n";
  this->PrintObjectMotion(os, indent);
}
