#include "vtkRainRunoffFilter.h"

#include "vtkAlgorithmOutput.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkSmartPointer.h"
#include "vtkTable.h"

#include "graupel/rain_runoff.h"

#include "GraupelArrays.h"
#include "GraupelParameterTable.h"
#include "GraupelPieces.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkRainRunoffFilter);

namespace {
using graupel::AsFloat;

// The core's parameter table row for a property, or nullptr.
const gr_param_bound *Bound(const char *property) {
  return graupel::TableRow(gr_rain_runoff_param_bounds, property);
}

} // namespace

vtkRainRunoffFilter::vtkRainRunoffFilter() {
  this->SetNumberOfInputPorts(4);
  this->SetNumberOfOutputPorts(2);
  // The core runs as pieces of a split domain (an MPI run's strips), its
  // ring as wide as the flow model's stencil.
  this->SetPieceRing(GR_RAIN_RUNOFF_GHOST_SW);
  // Inflows may vary in time (a river's discharge per input time step).
  this->SetInputPortPolicy(3, TEMPORAL_INPUT);
}

// The core's parameter table clamps every property: the class writes no
// range of its own.
GRAUPEL_TABLE_SETTER(vtkRainRunoffFilter, RainRate, double, gr_rain_runoff_param_bounds)
GRAUPEL_TABLE_SETTER(vtkRainRunoffFilter, Permeability, double, gr_rain_runoff_param_bounds)
GRAUPEL_TABLE_SETTER(vtkRainRunoffFilter, ManningN, double, gr_rain_runoff_param_bounds)
GRAUPEL_TABLE_SETTER(vtkRainRunoffFilter, BoundaryWest, int, gr_rain_runoff_param_bounds)
GRAUPEL_TABLE_SETTER(vtkRainRunoffFilter, BoundaryEast, int, gr_rain_runoff_param_bounds)
GRAUPEL_TABLE_SETTER(vtkRainRunoffFilter, BoundarySouth, int, gr_rain_runoff_param_bounds)
GRAUPEL_TABLE_SETTER(vtkRainRunoffFilter, BoundaryNorth, int, gr_rain_runoff_param_bounds)
GRAUPEL_TABLE_SETTER(vtkRainRunoffFilter, LevelWest, double, gr_rain_runoff_param_bounds)
GRAUPEL_TABLE_SETTER(vtkRainRunoffFilter, LevelEast, double, gr_rain_runoff_param_bounds)
GRAUPEL_TABLE_SETTER(vtkRainRunoffFilter, LevelSouth, double, gr_rain_runoff_param_bounds)
GRAUPEL_TABLE_SETTER(vtkRainRunoffFilter, LevelNorth, double, gr_rain_runoff_param_bounds)
GRAUPEL_TABLE_SETTER(vtkRainRunoffFilter, NoDataBoundary, int, gr_rain_runoff_param_bounds)

void vtkRainRunoffFilter::SetRainFrames(int value) {
  // Not a parameter of the core: which frame the base hands the core when.
  value = value < FRAME_FROM_ITS_TIME          ? FRAME_FROM_ITS_TIME
          : value > FRAME_OVER_INTERVAL_BEFORE ? FRAME_OVER_INTERVAL_BEFORE
                                               : value;
  if (value != this->RainFrames) {
    this->RainFrames = value;
    this->SetInputFrameHold(0, value == FRAME_OVER_INTERVAL_BEFORE ? HOLD_INTERVAL_BEFORE
                                                                   : HOLD_FROM_TIME);
    this->Modified();
  }
}

void vtkRainRunoffFilter::SetBoundary(int value) {
  this->SetBoundaryWest(value);
  this->SetBoundaryEast(value);
  this->SetBoundarySouth(value);
  this->SetBoundaryNorth(value);
}

int vtkRainRunoffFilter::GetBoundary() {
  const int w = this->BoundaryWest;
  return w == this->BoundaryEast && w == this->BoundarySouth && w == this->BoundaryNorth ? w : -1;
}
GRAUPEL_TABLE_SETTER(vtkRainRunoffFilter, FlowModel, int, gr_rain_runoff_param_bounds)
GRAUPEL_TABLE_SETTER(vtkRainRunoffFilter, MaxTimeStep, double, gr_rain_runoff_param_bounds)
GRAUPEL_TABLE_SETTER(vtkRainRunoffFilter, CourantNumber, double, gr_rain_runoff_param_bounds)
GRAUPEL_TABLE_SETTER(vtkRainRunoffFilter, WettingDepth, double, gr_rain_runoff_param_bounds)
GRAUPEL_TABLE_SETTER(vtkRainRunoffFilter, DebrisFactor, double, gr_rain_runoff_param_bounds)

int vtkRainRunoffFilter::CheckParameters() {
  const struct {
    const char *property;
    double value;
  } values[] = {{"RainRate", this->RainRate},
                {"Permeability", this->Permeability},
                {"ManningN", this->ManningN},
                {"BoundaryWest", double(this->BoundaryWest)},
                {"BoundaryEast", double(this->BoundaryEast)},
                {"BoundarySouth", double(this->BoundarySouth)},
                {"BoundaryNorth", double(this->BoundaryNorth)},
                {"LevelWest", this->LevelWest},
                {"LevelEast", this->LevelEast},
                {"LevelSouth", this->LevelSouth},
                {"LevelNorth", this->LevelNorth},
                {"MaxTimeStep", this->MaxTimeStep},
                {"CourantNumber", this->CourantNumber},
                {"FlowModel", double(this->FlowModel)},
                {"WettingDepth", this->WettingDepth},
                {"DebrisFactor", this->DebrisFactor},
                {"NoDataBoundary", double(this->NoDataBoundary)}};
  for (const auto &p : values) {
    if (!this->ReportError(
            graupel::OutOfRange("Rain Runoff", p.property, Bound(p.property), p.value))) {
      return 0;
    }
  }
  return 1;
}

vtkRainRunoffFilter::~vtkRainRunoffFilter() {
  this->ReleaseState();
}

void vtkRainRunoffFilter::SetPermeabilityMapConnection(vtkAlgorithmOutput *output) {
  this->SetInputConnection(1, output);
}

void vtkRainRunoffFilter::SetGaugesConnection(vtkAlgorithmOutput *output) {
  this->SetInputConnection(2, output);
}

void vtkRainRunoffFilter::SetInflowsConnection(vtkAlgorithmOutput *output) {
  this->SetInputConnection(3, output);
}

void vtkRainRunoffFilter::AddInflow(int side, double time, double discharge) {
  this->InflowTimes[side].push_back(time);
  this->InflowDischarges[side].push_back(discharge);
  this->Modified();
}

void vtkRainRunoffFilter::RemoveAllInflow(int side) {
  if (!this->InflowTimes[side].empty()) {
    this->InflowTimes[side].clear();
    this->InflowDischarges[side].clear();
    this->Modified();
  }
}

void vtkRainRunoffFilter::AddHyetograph(double time, double rate) {
  this->HyetographTimes.push_back(time);
  this->HyetographRates.push_back(rate);
  this->Modified();
}

void vtkRainRunoffFilter::RemoveAllHyetograph() {
  if (!this->HyetographTimes.empty()) {
    this->HyetographTimes.clear();
    this->HyetographRates.clear();
    this->Modified();
  }
}

int vtkRainRunoffFilter::GetNumberOfHyetographRows() {
  return static_cast<int>(this->HyetographTimes.size());
}

int vtkRainRunoffFilter::GetNumberOfInflowRows(int side) {
  return side >= 0 && side < 4 ? static_cast<int>(this->InflowTimes[side].size()) : 0;
}

#define GRAUPEL_RAIN_RUNOFF_INFLOW(Side, index)                                                    \
  void vtkRainRunoffFilter::AddInflow##Side(double time, double discharge) {                       \
    this->AddInflow(index, time, discharge);                                                       \
  }                                                                                                \
  void vtkRainRunoffFilter::RemoveAllInflow##Side() {                                              \
    this->RemoveAllInflow(index);                                                                  \
  }
GRAUPEL_RAIN_RUNOFF_INFLOW(West, 0)
GRAUPEL_RAIN_RUNOFF_INFLOW(East, 1)
GRAUPEL_RAIN_RUNOFF_INFLOW(South, 2)
GRAUPEL_RAIN_RUNOFF_INFLOW(North, 3)
#undef GRAUPEL_RAIN_RUNOFF_INFLOW

int vtkRainRunoffFilter::FillOutputPortInformation(int port, vtkInformation *info) {
  info->Set(vtkDataObject::DATA_TYPE_NAME(), port == 0 ? "vtkImageData" : "vtkTable");
  return 1;
}

int vtkRainRunoffFilter::RequestInformation(vtkInformation *request,
                                            vtkInformationVector **inputVector,
                                            vtkInformationVector *outputVector) {
  // The ring follows the flow model (a property change comes through here
  // before the next RequestData plans the pieces).
  this->SetPieceRing(this->FlowModel == LOCAL_INERTIAL ? GR_RAIN_RUNOFF_GHOST
                                                       : GR_RAIN_RUNOFF_GHOST_SW);
  // The base gives the hydrograph the simulation's times.
  return this->Superclass::RequestInformation(request, inputVector, outputVector);
}

int vtkRainRunoffFilter::FillInputPortInformation(int port, vtkInformation *info) {
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), port >= 2 ? "vtkPointSet" : "vtkImageData");
  if (port >= 1) {
    info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
  }
  return 1;
}

// What SetUpState hands the core: the input fields, each with where it
// came from (for the sentences), and the Manning map.
struct vtkRainRunoffFilter::Upload {
  gr_field field;
  vtkSmartPointer<vtkFloatArray> values;
  const char *where;
};
struct vtkRainRunoffFilter::Inputs {
  std::vector<Upload> uploads;
  vtkDataArray *manning = nullptr;
  const char *manningWhere = "Input";
};

int vtkRainRunoffFilter::CollectInputs(vtkImageData *terrain, vtkImageData *map,
                                       vtkDataArray *elevationArray, Inputs &in) {
  int dims[3];
  terrain->GetDimensions(dims);
  vtkPointData *pd = terrain->GetPointData();
  in.uploads.push_back({GR_FIELD_ELEVATION, AsFloat(elevationArray), "Input"});
  // The water: its depth, or its surface (a Rain Runoff output has both:
  // the depth is the one then).
  if (vtkDataArray *depth = pd->GetArray("water_depth")) {
    in.uploads.push_back({GR_FIELD_WATER_DEPTH, AsFloat(depth), "Input"});
  } else if (vtkDataArray *surface = pd->GetArray("water_surface")) {
    in.uploads.push_back({GR_FIELD_WATER_SURFACE, AsFloat(surface), "Input"});
  }
  // After the water, whose velocity it is; the local inertial model starts
  // from rest.
  vtkDataArray *velocity = pd->GetArray("velocity");
  if (velocity && this->FlowModel == SHALLOW_WATER) {
    in.uploads.push_back({GR_FIELD_VELOCITY, AsFloat(velocity), "Input"});
  }
  this->RainFollowed = pd->GetArray("rain_rate") != nullptr;
  if (vtkDataArray *rain = pd->GetArray("rain_rate")) {
    in.uploads.push_back({GR_FIELD_RAIN_RATE, AsFloat(rain), "Input"});
  }
  // The Manning map: the terrain's manning_n, or the PermeabilityMap's.
  in.manning = pd->GetArray("manning_n");
  in.manningWhere = "Input";
  if (map) {
    int mdims[3];
    map->GetDimensions(mdims);
    vtkDataArray *k = map->GetPointData()->GetArray("permeability");
    vtkDataArray *mn = map->GetPointData()->GetArray("manning_n");
    if (!k && !mn) {
      vtkErrorMacro("Rain Runoff's PermeabilityMap has no point array 'permeability' (m/s) or "
                    "'manning_n' (s/m^(1/3)); name the map's array so, or disconnect the map to "
                    "use Permeability and ManningN.");
      return 0;
    }
    if (mn) {
      in.manning = mn;
      in.manningWhere = "PermeabilityMap";
    }
    if (mdims[0] != dims[0] || mdims[1] != dims[1] || mdims[2] != dims[2]) {
      vtkErrorMacro("Rain Runoff's PermeabilityMap has "
                    << mdims[0] << " x " << mdims[1] << " x " << mdims[2]
                    << " points but the terrain has " << dims[0] << " x " << dims[1] << " x "
                    << dims[2] << "; resample the map onto the terrain's grid.");
      return 0;
    }
    if (k) {
      in.uploads.push_back({GR_FIELD_PERMEABILITY, AsFloat(k), "PermeabilityMap"});
    }
  }
  const size_t npoints = static_cast<size_t>(dims[0]) * static_cast<size_t>(dims[1]);
  char msg[512];
  for (const Upload &u : in.uploads) {
    const int comps = gr_field_components(u.field);
    if (u.values->GetNumberOfComponents() != comps ||
        static_cast<size_t>(u.values->GetNumberOfTuples()) != npoints) {
      vtkErrorMacro("Rain Runoff's "
                    << u.where << " array '" << gr_field_name(u.field) << "' must have "
                    << (comps == 1 ? "one value" : "3 components") << " per point.");
      return 0;
    }
    if (gr_rain_runoff_field_validate(u.field, u.values->GetPointer(0), npoints * comps, msg,
                                      sizeof(msg)) != GR_OK) {
      vtkErrorMacro("Rain Runoff's " << u.where << ": " << msg);
      return 0;
    }
  }

  return 1;
}

int vtkRainRunoffFilter::CoreParams(gr_rain_runoff_params *p) {
  gr_rain_runoff_params_init(p);
  // The user's units (mm/h) to the core's (m/s): each row's to_core.
  p->rain_rate = this->RainRate * Bound("RainRate")->to_core;
  p->permeability = this->Permeability * Bound("Permeability")->to_core;
  p->manning_n = this->ManningN;
  p->cfl = this->CourantNumber;
  p->max_dt = this->MaxTimeStep;
  const int kinds[4] = {this->BoundaryWest, this->BoundaryEast, this->BoundarySouth,
                        this->BoundaryNorth};
  const double levels[4] = {this->LevelWest, this->LevelEast, this->LevelSouth, this->LevelNorth};
  for (int e = 0; e < 4; ++e) {
    p->boundary[e] = static_cast<gr_boundary>(kinds[e]);
    p->boundary_level[e] = levels[e];
  }
  p->flow_model =
      this->FlowModel == LOCAL_INERTIAL ? GR_FLOW_LOCAL_INERTIAL : GR_FLOW_SHALLOW_WATER;
  p->wetting_depth = this->WettingDepth;
  p->debris_factor = this->DebrisFactor;
  p->no_data = this->NoDataBoundary == OPEN ? GR_BOUNDARY_OPEN : GR_BOUNDARY_CLOSED;
  char msg[512];
  if (gr_rain_runoff_params_validate(p, msg, sizeof(msg)) != GR_OK) {
    vtkErrorMacro("Rain Runoff: " << msg);
    return 0;
  }

  return 1;
}

int vtkRainRunoffFilter::SnapGauges(vtkImageData *terrain, vtkPointSet *gauges) {
  int dims[3];
  terrain->GetDimensions(dims);
  double spacing[3];
  terrain->GetSpacing(spacing);
  // Each gauge at its nearest terrain point.
  this->GaugeCells.clear();
  if (gauges) {
    int ext[6];
    terrain->GetExtent(ext);
    const double *origin = terrain->GetOrigin();
    for (vtkIdType k = 0; k < gauges->GetNumberOfPoints(); ++k) {
      double x[3];
      gauges->GetPoint(k, x);
      const double fi = (x[0] - origin[0]) / spacing[0] - ext[0];
      const double fj = (x[1] - origin[1]) / spacing[1] - ext[2];
      const bool finite = std::isfinite(fi) && std::isfinite(fj);
      const long long ci = finite ? std::llround(fi) : -1, cj = finite ? std::llround(fj) : -1;
      if (ci < 0 || cj < 0 || ci >= dims[0] || cj >= dims[1]) {
        vtkErrorMacro(
            "Rain Runoff's Gauges point "
            << k << " at (" << x[0] << ", " << x[1] << ") lies off the terrain (x "
            << origin[0] + ext[0] * spacing[0] << " to " << origin[0] + ext[1] * spacing[0]
            << " m, y " << origin[1] + ext[2] * spacing[1] << " to "
            << origin[1] + ext[3] * spacing[1] << " m); move it onto the terrain or remove it.");
        return 0;
      }
      this->GaugeCells.push_back(static_cast<int>(ci));
      this->GaugeCells.push_back(static_cast<int>(cj));
    }
  }

  return 1;
}

int vtkRainRunoffFilter::CreateCore(vtkImageData *terrain, const gr_rain_runoff_params &p,
                                    const Inputs &in) {
  int dims[3];
  terrain->GetDimensions(dims);
  const size_t npoints = static_cast<size_t>(dims[0]) * static_cast<size_t>(dims[1]);
  // A split run's strip: its rows, its ring and the whole domain around it.
  // Every input field goes up as the local array (own rows and ring); point
  // inflows stay in the whole domain's indices (the core keeps those in its
  // local array); the core reduces the stable step and the ledger over the
  // pieces, so every rank's ledger is the whole grid's.
  graupel::Pieces &pieces = this->GetPieces();
  gr_grid grid;
  TerrainGrid(terrain, &grid);
  pieces.PieceGrid(&grid);
  gr_status st = gr_rain_runoff_create(this->GetContext(), &grid, &p, &this->Simulation);
  if (st != GR_OK) {
    return this->ReportFailure(st, "Rain Runoff could not set up the simulation");
  }
  if (pieces.IsSplit()) {
    gr_rain_runoff *sim = this->Simulation;
    pieces.BindHalo(
        [sim](int side, size_t *bytes) { return gr_rain_runoff_halo_size(sim, side, bytes); },
        [sim](int side, void *host, size_t bytes) {
          return gr_rain_runoff_halo_get(sim, side, host, bytes);
        },
        [sim](int side, const void *host, size_t bytes) {
          return gr_rain_runoff_halo_set(sim, side, host, bytes);
        });
    gr_rain_runoff_set_allreduce(sim, graupel::Pieces::Allreduce, &pieces);
    gr_rain_runoff_set_halo_exchange(sim, graupel::Pieces::Exchange, &pieces);
  }
  for (const Upload &u : in.uploads) {
    const std::vector<float> local =
        pieces.LocalField(u.values->GetPointer(0), dims[0], gr_field_components(u.field));
    st = gr_rain_runoff_set_field(this->Simulation, u.field, local.data());
    if (st != GR_OK) {
      return this->ReportFailure(st, "Rain Runoff could not upload its inputs",
                                 gr_rain_runoff_last_error(this->Simulation));
    }
  }
  // The Manning map, in double (n^2 then rounds as ManningN's does).
  vtkDataArray *manning = in.manning;
  const char *manningWhere = in.manningWhere;
  if (manning) {
    if (manning->GetNumberOfComponents() != 1 ||
        static_cast<size_t>(manning->GetNumberOfTuples()) != npoints) {
      vtkErrorMacro("Rain Runoff's " << manningWhere
                                     << " array 'manning_n' must have one value per point.");
      return 0;
    }
    // The local array's rows (own rows and ring; the whole grid unsplit).
    const size_t first = static_cast<size_t>(pieces.GetLocalFirstRow()) * dims[0];
    std::vector<double> n(static_cast<size_t>(pieces.GetLocalRows()) * dims[0]);
    for (size_t c = 0; c < n.size(); ++c) {
      n[c] = manning->GetComponent(static_cast<vtkIdType>(first + c), 0);
    }
    if (gr_rain_runoff_set_manning_map(this->Simulation, n.data()) != GR_OK) {
      vtkErrorMacro("Rain Runoff's " << manningWhere << ": "
                                     << gr_rain_runoff_last_error(this->Simulation));
      return 0;
    }
  }
  return 1;
}

int vtkRainRunoffFilter::SetTimeSeries() {
  // The hyetograph, in m/s.
  if (!this->HyetographTimes.empty()) {
    std::vector<double> rates(this->HyetographRates);
    const double toCore = Bound("RainRate")->to_core; // mm/h, as RainRate
    for (double &r : rates) {
      r *= toCore;
    }
    if (gr_rain_runoff_set_hyetograph(this->Simulation, this->HyetographTimes.data(), rates.data(),
                                      static_cast<int>(this->HyetographTimes.size())) != GR_OK) {
      vtkErrorMacro("Rain Runoff's Hyetograph: " << gr_rain_runoff_last_error(this->Simulation));
      return 0;
    }
  }
  // The inflows: each edge's hydrograph, and the points with a discharge.
  const char *sides[4] = {"InflowWest", "InflowEast", "InflowSouth", "InflowNorth"};
  for (int e = 0; e < 4; ++e) {
    if (gr_rain_runoff_set_edge_inflow(this->Simulation, e, this->InflowTimes[e].data(),
                                       this->InflowDischarges[e].data(),
                                       static_cast<int>(this->InflowTimes[e].size())) != GR_OK) {
      vtkErrorMacro("Rain Runoff's " << sides[e] << ": "
                                     << gr_rain_runoff_last_error(this->Simulation));
      return 0;
    }
  }
  return 1;
}

int vtkRainRunoffFilter::SetUpState(vtkInformationVector **inputVector) {
  vtkImageData *terrain = vtkImageData::GetData(inputVector[0]);
  vtkImageData *map = inputVector[1]->GetNumberOfInformationObjects()
                          ? vtkImageData::GetData(inputVector[1])
                          : nullptr;
  if (!this->CheckTerrain(terrain)) {
    return 0;
  }
  vtkDataArray *elevationArray = this->GetElevation(terrain, "Input");
  if (!elevationArray || !this->CheckParameters()) {
    return 0;
  }
  if (!this->CheckStateMemory(terrain, map, inputVector)) {
    return 0;
  }

  Inputs in;
  gr_rain_runoff_params p;
  vtkPointSet *gauges = inputVector[2]->GetNumberOfInformationObjects()
                            ? vtkPointSet::GetData(inputVector[2])
                            : nullptr;
  if (!this->CollectInputs(terrain, map, elevationArray, in) || !this->CoreParams(&p) ||
      !this->SnapGauges(terrain, gauges) || !this->CreateCore(terrain, p, in) ||
      !this->SetTimeSeries()) {
    return 0;
  }
  vtkPointSet *inflows = inputVector[3]->GetNumberOfInformationObjects()
                             ? vtkPointSet::SafeDownCast(this->GetTemporalInput(3))
                             : nullptr;
  if (!this->SetPointInflows(inflows, terrain)) {
    return 0;
  }
  this->InflowsReadAt = this->GetTemporalInputTime(3);
  this->RainReadAt = this->GetTemporalInputTime(0);
  // Progress with the simulated time, and an abort inside a long interval.
  gr_rain_runoff_set_progress(this->Simulation, &vtkGraupelSimulation::CoreProgress, this);
  this->Ledgers.clear();
  this->GaugeRows.clear();
  return this->RecordLedger(0);
}

int vtkRainRunoffFilter::CheckStateMemory(vtkImageData *terrain, vtkImageData *map,
                                          vtkInformationVector **inputVector) {
  vtkPointData *pd = terrain->GetPointData();
  vtkPointData *md = map ? map->GetPointData() : nullptr;
  int inputs = GR_RAIN_RUNOFF_INPUT_NO_DATA; // NaN elevations are found later
  inputs |= pd->GetArray("rain_rate") ? GR_RAIN_RUNOFF_INPUT_RAIN : 0;
  inputs |= md && md->GetArray("permeability") ? GR_RAIN_RUNOFF_INPUT_PERMEABILITY : 0;
  const bool manning = pd->GetArray("manning_n") || (md && md->GetArray("manning_n"));
  inputs |= manning ? GR_RAIN_RUNOFF_INPUT_MANNING : 0;
  bool inflows = inputVector[3]->GetNumberOfInformationObjects() > 0;
  for (const std::vector<double> &times : this->InflowTimes) {
    inflows = inflows || !times.empty();
  }
  inputs |= inflows ? GR_RAIN_RUNOFF_INPUT_INFLOWS : 0;
  gr_rain_runoff_params p;
  gr_rain_runoff_params_init(&p);
  p.flow_model = this->FlowModel == LOCAL_INERTIAL ? GR_FLOW_LOCAL_INERTIAL : GR_FLOW_SHALLOW_WATER;
  gr_grid grid;
  TerrainGrid(terrain, &grid);
  this->GetPieces().PieceGrid(&grid);
  gr_memory_need need;
  gr_rain_runoff_memory(this->GetContext(), &grid, &p, inputs, &need);
  // The output's fields (water depth and surface, velocity, discharge,
  // infiltrated, elevation: 8 floats) and flood maps, with the maps' staging
  // plane; the uploads' staging (3 floats) and the Manning map in double.
  const double output = 4.0 * (8 + GR_RAIN_RUNOFF_MAP_COUNT + 1);
  const double staging = 4.0 * 3 + (manning ? 8.0 : 0.0);
  return this->CheckMemory(grid, need, output + staging);
}

int vtkRainRunoffFilter::SetPointInflows(vtkPointSet *points, vtkImageData *terrain) {
  if (!points || !terrain) {
    return 1;
  }
  vtkDataArray *q = points->GetPointData()->GetArray("discharge");
  const vtkIdType n = points->GetNumberOfPoints();
  if (n > 0 && (!q || q->GetNumberOfComponents() != 1)) {
    vtkErrorMacro("Rain Runoff's Inflows need the point array 'discharge' (m^3/s, one value per "
                  "point); add it, or disconnect the Inflows input.");
    return 0;
  }
  int ext[6], dims[3];
  terrain->GetExtent(ext);
  terrain->GetDimensions(dims);
  const double *origin = terrain->GetOrigin(), *spacing = terrain->GetSpacing();
  std::vector<int> ij;
  std::vector<double> discharge;
  for (vtkIdType k = 0; k < n; ++k) {
    double x[3];
    points->GetPoint(k, x);
    const double fi = (x[0] - origin[0]) / spacing[0] - ext[0];
    const double fj = (x[1] - origin[1]) / spacing[1] - ext[2];
    const bool finite = std::isfinite(fi) && std::isfinite(fj);
    const long long ci = finite ? std::llround(fi) : -1, cj = finite ? std::llround(fj) : -1;
    if (ci < 0 || cj < 0 || ci >= dims[0] || cj >= dims[1]) {
      vtkErrorMacro("Rain Runoff's Inflows point "
                    << k << " at (" << x[0] << ", " << x[1] << ") lies off the terrain (x "
                    << origin[0] + ext[0] * spacing[0] << " to " << origin[0] + ext[1] * spacing[0]
                    << " m, y " << origin[1] + ext[2] * spacing[1] << " to "
                    << origin[1] + ext[3] * spacing[1]
                    << " m); move it onto the terrain or remove it.");
      return 0;
    }
    ij.push_back(static_cast<int>(ci));
    ij.push_back(static_cast<int>(cj));
    discharge.push_back(q->GetComponent(k, 0));
  }
  if (gr_rain_runoff_set_point_inflows(this->Simulation, ij.data(), discharge.data(),
                                       static_cast<int>(n)) != GR_OK) {
    vtkErrorMacro("Rain Runoff's Inflows: " << gr_rain_runoff_last_error(this->Simulation));
    return 0;
  }
  return 1;
}

int vtkRainRunoffFilter::SetRainFromInput(vtkImageData *terrain) {
  vtkDataArray *rain = terrain ? terrain->GetPointData()->GetArray("rain_rate") : nullptr;
  if (!rain) {
    if (this->RainFollowed) {
      vtkErrorMacro("Rain Runoff's Input has no point array 'rain_rate' at t = "
                    << this->GetTemporalInputTime(0)
                    << " s, though it had one before; give every time step its rain (m/s).");
      return 0;
    }
    return 1; // no rain map: RainRate (or the Hyetograph) rains
  }
  int dims[3];
  terrain->GetDimensions(dims);
  const size_t npoints = static_cast<size_t>(dims[0]) * static_cast<size_t>(dims[1]);
  vtkSmartPointer<vtkFloatArray> values = graupel::AsFloat(rain);
  char msg[512];
  if (values->GetNumberOfComponents() != 1 ||
      static_cast<size_t>(values->GetNumberOfTuples()) != npoints) {
    vtkErrorMacro("Rain Runoff's Input array 'rain_rate' must have one value per point.");
    return 0;
  }
  if (gr_rain_runoff_field_validate(GR_FIELD_RAIN_RATE, values->GetPointer(0), npoints, msg,
                                    sizeof(msg)) != GR_OK) {
    vtkErrorMacro("Rain Runoff's Input at t = " << this->GetTemporalInputTime(0) << " s: " << msg);
    return 0;
  }
  const std::vector<float> local = this->GetPieces().LocalField(values->GetPointer(0), dims[0], 1);
  const gr_status st = gr_rain_runoff_set_field(this->Simulation, GR_FIELD_RAIN_RATE, local.data());
  if (st != GR_OK) {
    return this->ReportFailure(st, "Rain Runoff could not take the Input's rain",
                               gr_rain_runoff_last_error(this->Simulation));
  }
  this->RainFollowed = true;
  return 1;
}

int vtkRainRunoffFilter::ResetState() {
  this->InflowsReadAt = std::numeric_limits<double>::quiet_NaN();
  this->RainReadAt = std::numeric_limits<double>::quiet_NaN();
  const gr_status st = gr_rain_runoff_reset(this->Simulation);
  return st == GR_OK ? this->RecordLedger(0)
                     : this->ReportFailure(st, "Rain Runoff could not restart",
                                           gr_rain_runoff_last_error(this->Simulation));
}

int vtkRainRunoffFilter::AdvanceState(double t0, double t1) {
  // Temporal Inflows: the discharges of the input's time step that holds
  // over [t0, t1] (the base keeps the input at the step the state needs).
  if (this->IsInputTemporal(3) && this->GetTemporalInputTime(3) != this->InflowsReadAt) {
    if (!this->SetPointInflows(vtkPointSet::SafeDownCast(this->GetTemporalInput(3)),
                               vtkImageData::SafeDownCast(this->GetTemporalInput(0)))) {
      return ADVANCE_FAILED;
    }
    this->InflowsReadAt = this->GetTemporalInputTime(3);
  }
  // A temporal Input followed in time (FollowInputTime): its rain_rate of
  // the time step that holds over [t0, t1] by RainFrames, e.g. a series of
  // radar frames (from their time on) or Snow Melt's mean release (over the
  // interval before).
  if (this->IsInputTemporal(0) && this->GetTemporalInputTime(0) != this->RainReadAt) {
    if (!this->SetRainFromInput(vtkImageData::SafeDownCast(this->GetTemporalInput(0)))) {
      return ADVANCE_FAILED;
    }
    this->RainReadAt = this->GetTemporalInputTime(0);
  }
  const gr_status st = gr_rain_runoff_advance(this->Simulation, t1 - t0, nullptr);
  if (st == GR_ERR_ABORTED) {
    return ADVANCE_ABORTED;
  }
  if (st != GR_OK) {
    return this->ReportFailure(st, "Rain Runoff could not advance",
                               gr_rain_runoff_last_error(this->Simulation));
  }
  // At an output time (the base's own test of the knot), the hydrograph's row.
  const int next = this->GetStateIndex() + 1;
  if (t1 == this->GetOutputTime(next) && !this->RecordLedger(next)) {
    return ADVANCE_FAILED;
  }
  return ADVANCE_DONE;
}

namespace {
// A checkpoint's layout: the core's bytes, then the hydrograph's rows up to
// the state's output time (a restart from a file has no other record of
// them): rows, gauges, the ledgers' doubles, the gauges' floats, and last
// the core's byte count.
template <typename T>
void Put(std::vector<unsigned char> &bytes, const T *values, size_t n) {
  const unsigned char *p = reinterpret_cast<const unsigned char *>(values);
  bytes.insert(bytes.end(), p, p + n * sizeof(T));
}
template <typename T>
bool Take(const std::vector<unsigned char> &bytes, size_t &at, T *values, size_t n) {
  if (n > (bytes.size() - at) / sizeof(T)) {
    return false;
  }
  std::memcpy(values, bytes.data() + at, n * sizeof(T));
  at += n * sizeof(T);
  return true;
}
} // namespace

int vtkRainRunoffFilter::SaveState(std::vector<unsigned char> &bytes) {
  size_t size = 0;
  if (gr_rain_runoff_state_size(this->Simulation, &size) != GR_OK) {
    return 0;
  }
  bytes.resize(size);
  if (gr_rain_runoff_state_save(this->Simulation, bytes.data(), size) != GR_OK) {
    return 0;
  }
  const vtkTypeInt64 rows = this->GetStateIndex() + 1;
  const vtkTypeInt64 gauges = static_cast<vtkTypeInt64>(this->GaugeCells.size() / 2);
  if (rows < 1 || this->Ledgers.size() < static_cast<size_t>(rows) ||
      this->GaugeRows.size() < static_cast<size_t>(rows)) {
    return 0;
  }
  Put(bytes, &rows, 1);
  Put(bytes, &gauges, 1);
  for (vtkTypeInt64 r = 0; r < rows; ++r) {
    Put(bytes, this->Ledgers[static_cast<size_t>(r)].data(), 7);
    const std::vector<float> &g = this->GaugeRows[static_cast<size_t>(r)];
    if (g.size() != 3 * static_cast<size_t>(gauges)) {
      return 0;
    }
    Put(bytes, g.data(), g.size());
  }
  const vtkTypeInt64 core = static_cast<vtkTypeInt64>(size);
  Put(bytes, &core, 1);
  return 1;
}

int vtkRainRunoffFilter::LoadState(const std::vector<unsigned char> &bytes) {
  vtkTypeInt64 core = 0, rows = 0, gauges = 0;
  size_t at = bytes.size() >= sizeof(core) ? bytes.size() - sizeof(core) : 0;
  if (!Take(bytes, at, &core, 1) || core < 0 || static_cast<size_t>(core) > bytes.size()) {
    return 0;
  }
  at = static_cast<size_t>(core);
  if (!Take(bytes, at, &rows, 1) || !Take(bytes, at, &gauges, 1) || rows < 1 ||
      gauges != static_cast<vtkTypeInt64>(this->GaugeCells.size() / 2) ||
      static_cast<size_t>(rows) > bytes.size()) {
    return 0;
  }
  std::vector<std::array<double, 7>> ledgers(static_cast<size_t>(rows));
  std::vector<std::vector<float>> gaugeRows(static_cast<size_t>(rows));
  for (size_t r = 0; r < ledgers.size(); ++r) {
    gaugeRows[r].resize(3 * static_cast<size_t>(gauges));
    if (!Take(bytes, at, ledgers[r].data(), 7) ||
        !Take(bytes, at, gaugeRows[r].data(), gaugeRows[r].size())) {
      return 0;
    }
  }
  if (at != bytes.size() - sizeof(core) ||
      gr_rain_runoff_state_load(this->Simulation, bytes.data(), static_cast<size_t>(core)) !=
          GR_OK) {
    return 0;
  }
  // The rows up to the checkpoint's time; later ones are recorded again.
  if (this->Ledgers.size() < ledgers.size()) {
    this->Ledgers.resize(ledgers.size());
    this->GaugeRows.resize(ledgers.size());
  }
  std::copy(ledgers.begin(), ledgers.end(), this->Ledgers.begin());
  std::copy(gaugeRows.begin(), gaugeRows.end(), this->GaugeRows.begin());
  // The point inflows and a followed Input's rain are not in the core's
  // state: the next advance sets those of the inputs' time steps again.
  this->InflowsReadAt = std::numeric_limits<double>::quiet_NaN();
  this->RainReadAt = std::numeric_limits<double>::quiet_NaN();
  return 1;
}

void vtkRainRunoffFilter::ReleaseState() {
  gr_rain_runoff_destroy(this->Simulation);
  this->Simulation = nullptr;
}

void vtkRainRunoffFilter::PrintSelf(ostream &os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  os << indent << "RainRate: " << this->RainRate << " mm/h\n";
  os << indent << "Permeability: " << this->Permeability << " mm/h\n";
  os << indent << "ManningN: " << this->ManningN << "\n";
  const char *kinds[] = {"open", "closed", "transmissive", "level"};
  const int edges[4] = {this->BoundaryWest, this->BoundaryEast, this->BoundarySouth,
                        this->BoundaryNorth};
  const double levels[4] = {this->LevelWest, this->LevelEast, this->LevelSouth, this->LevelNorth};
  const char *sides[] = {"West", "East", "South", "North"};
  for (int e = 0; e < 4; ++e) {
    os << indent << "Boundary" << sides[e] << ": "
       << (edges[e] >= 0 && edges[e] < 4 ? kinds[edges[e]] : "(invalid)");
    if (edges[e] == LEVEL) {
      os << " at " << levels[e] << " m";
    }
    os << "\n";
  }
  os << indent
     << "FlowModel: " << (this->FlowModel == LOCAL_INERTIAL ? "local inertial" : "shallow water")
     << "\n";
  os << indent << "MaxTimeStep: " << this->MaxTimeStep << " s\n";
  os << indent << "CourantNumber: " << this->CourantNumber << "\n";
  os << indent << "WettingDepth: " << this->WettingDepth << " m\n";
  os << indent << "DebrisFactor: " << this->DebrisFactor << "\n";
  os << indent << "NoDataBoundary: " << (this->NoDataBoundary == OPEN ? "outfall" : "wall") << "\n";
  os << indent << "RainFrames: "
     << (this->RainFrames == FRAME_OVER_INTERVAL_BEFORE ? "over the interval before"
                                                        : "from its time on")
     << "\n";
}
