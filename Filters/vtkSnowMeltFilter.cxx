#include "vtkSnowMeltFilter.h"

#include "vtkDataArray.h"
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
#include "vtkTable.h"

#include "graupel/snow_melt.h"

#include "GraupelArrays.h"
#include "GraupelParameterTable.h"
#include "GraupelPieces.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkSnowMeltFilter);

namespace {
using graupel::AddValue;
using graupel::AsFloat;

double Default(const char *property) {
  return graupel::TableDefault(gr_snow_melt_param_bounds, property);
}

double ToCore(const char *property) {
  const gr_param_bound *row = graupel::TableRow(gr_snow_melt_param_bounds, property);
  return row ? row->to_core : 1.0;
}

// The column name of a table, or nullptr when the table has none.
vtkDataArray *Column(vtkTable *table, const char *name) {
  return table ? vtkDataArray::SafeDownCast(table->GetColumnByName(name)) : nullptr;
}
} // namespace

vtkSnowMeltFilter::vtkSnowMeltFilter() {
  // Days of melt, seen every 6 hours.
  this->SetTimeDefaults(864000.0, 21600.0);
  this->SetNumberOfInputPorts(2);
  // Strips of whole rows with one ring row (the slopes' central differences).
  this->SetPieceRing(GR_SNOW_MELT_GHOST);
  this->Latitude = Default("Latitude");
  this->StartDayOfYear = static_cast<int>(Default("StartDayOfYear"));
  this->StartHour = Default("StartHour");
  this->TimeStep = Default("TimeStep");
  this->MeltFactor = Default("MeltFactor");
  this->RadiationFactor = Default("RadiationFactor");
  this->ThresholdTemperature = Default("ThresholdTemperature");
  this->LapseRate = Default("LapseRate");
  this->ReferenceElevation = Default("ReferenceElevation");
  this->Transmissivity = Default("Transmissivity");
  this->RainSnowThreshold = Default("RainSnowThreshold");
  this->RainSnowBand = Default("RainSnowBand");
  this->NewSnowDensity = Default("NewSnowDensity");
  this->MaxDensity = Default("MaxDensity");
  this->SettlingTime = Default("SettlingTime");
  this->LiquidWaterCapacity = Default("LiquidWaterCapacity");
  this->RefreezeFactor = Default("RefreezeFactor");
  this->CastShadows = static_cast<int>(Default("CastShadows"));
  this->HorizonSectors = static_cast<int>(Default("HorizonSectors"));
}

vtkSnowMeltFilter::~vtkSnowMeltFilter() {
  this->ReleaseState();
}

GRAUPEL_CLAMP_SETTER(vtkSnowMeltFilter, AirTemperature, double, -100.0, 100.0, "degC")
GRAUPEL_CLAMP_SETTER(vtkSnowMeltFilter, Precipitation, double, 0.0, 1000.0, "mm/h")
GRAUPEL_CLAMP_SETTER(vtkSnowMeltFilter, InitialSnowDepth, double, 0.0, 1.0e4, "m")
GRAUPEL_CLAMP_SETTER(vtkSnowMeltFilter, InitialDensity, double, 20.0, 917.0, "kg/m^3")
GRAUPEL_TABLE_SETTER(vtkSnowMeltFilter, Latitude, double, gr_snow_melt_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowMeltFilter, StartDayOfYear, int, gr_snow_melt_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowMeltFilter, StartHour, double, gr_snow_melt_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowMeltFilter, TimeStep, double, gr_snow_melt_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowMeltFilter, MeltFactor, double, gr_snow_melt_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowMeltFilter, RadiationFactor, double, gr_snow_melt_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowMeltFilter, ThresholdTemperature, double, gr_snow_melt_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowMeltFilter, LapseRate, double, gr_snow_melt_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowMeltFilter, ReferenceElevation, double, gr_snow_melt_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowMeltFilter, Transmissivity, double, gr_snow_melt_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowMeltFilter, RainSnowThreshold, double, gr_snow_melt_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowMeltFilter, RainSnowBand, double, gr_snow_melt_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowMeltFilter, NewSnowDensity, double, gr_snow_melt_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowMeltFilter, MaxDensity, double, gr_snow_melt_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowMeltFilter, SettlingTime, double, gr_snow_melt_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowMeltFilter, LiquidWaterCapacity, double, gr_snow_melt_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowMeltFilter, RefreezeFactor, double, gr_snow_melt_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowMeltFilter, CastShadows, int, gr_snow_melt_param_bounds)
GRAUPEL_TABLE_SETTER(vtkSnowMeltFilter, HorizonSectors, int, gr_snow_melt_param_bounds)

int vtkSnowMeltFilter::FillInputPortInformation(int port, vtkInformation *info) {
  if (port == 1) {
    info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkTable");
    info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
    return 1;
  }
  return this->Superclass::FillInputPortInformation(port, info);
}

int vtkSnowMeltFilter::CheckParameters() {
  const struct {
    const char *property;
    double value;
  } values[] = {{"Latitude", this->Latitude},
                {"StartDayOfYear", double(this->StartDayOfYear)},
                {"StartHour", this->StartHour},
                {"TimeStep", this->TimeStep},
                {"MeltFactor", this->MeltFactor},
                {"RadiationFactor", this->RadiationFactor},
                {"ThresholdTemperature", this->ThresholdTemperature},
                {"LapseRate", this->LapseRate},
                {"ReferenceElevation", this->ReferenceElevation},
                {"Transmissivity", this->Transmissivity},
                {"RainSnowThreshold", this->RainSnowThreshold},
                {"RainSnowBand", this->RainSnowBand},
                {"NewSnowDensity", this->NewSnowDensity},
                {"MaxDensity", this->MaxDensity},
                {"SettlingTime", this->SettlingTime},
                {"LiquidWaterCapacity", this->LiquidWaterCapacity},
                {"RefreezeFactor", this->RefreezeFactor},
                {"CastShadows", double(this->CastShadows)},
                {"HorizonSectors", double(this->HorizonSectors)}};
  int count = 0;
  const gr_param_bound *table = gr_snow_melt_param_bounds(&count);
  for (const auto &p : values) {
    if (!this->ReportError(graupel::OutOfRange("Snow Melt", p.property,
                                               gr_param_find(table, count, p.property), p.value))) {
      return 0;
    }
  }
  const struct {
    const char *property;
    double value;
    const char *unit;
  } own[] = {{"AirTemperature", this->AirTemperature, "degC"},
             {"Precipitation", this->Precipitation, "mm/h"},
             {"InitialSnowDepth", this->InitialSnowDepth, "m"},
             {"InitialDensity", this->InitialDensity, "kg/m^3"}};
  for (const auto &p : own) {
    if (!std::isfinite(p.value)) {
      vtkErrorMacro("Snow Melt: " << p.property << " is " << p.value << " " << p.unit
                                  << "; set it to a number.");
      return 0;
    }
  }
  return 1;
}

int vtkSnowMeltFilter::ReadForcing(vtkInformationVector **inputVector) {
  this->ForcingTimes.clear();
  this->ForcingTemperature.clear();
  this->ForcingPrecipitation.clear();
  vtkTable *table = vtkTable::GetData(inputVector[1]);
  if (!table) {
    return 1;
  }
  vtkDataArray *time = Column(table, "time");
  vtkDataArray *temperature = Column(table, "air_temperature");
  vtkDataArray *precipitation = Column(table, "precipitation");
  if (!time || table->GetNumberOfRows() < 1) {
    vtkErrorMacro("Snow Melt's Forcing has no column 'time' (s) with at least one row; give "
                  "it time with air_temperature (degC) and/or precipitation (mm/h), or "
                  "disconnect it.");
    return 0;
  }
  if (!temperature && !precipitation) {
    vtkWarningMacro("Snow Melt's Forcing has neither air_temperature nor precipitation: "
                    "AirTemperature and Precipitation hold throughout.");
  }
  const vtkIdType rows = table->GetNumberOfRows();
  struct {
    vtkDataArray *array;
    std::vector<double> *values;
  } columns[] = {{time, &this->ForcingTimes},
                 {temperature, &this->ForcingTemperature},
                 {precipitation, &this->ForcingPrecipitation}};
  for (const auto &c : columns) {
    if (!c.array) {
      continue;
    }
    c.values->resize(static_cast<size_t>(rows));
    for (vtkIdType r = 0; r < rows; ++r) {
      const double v = c.array->GetComponent(r, 0);
      if (!std::isfinite(v)) {
        vtkErrorMacro("Snow Melt's Forcing column '" << c.array->GetName() << "' is " << v
                                                     << " in row " << r
                                                     << "; give every row a number.");
        return 0;
      }
      (*c.values)[static_cast<size_t>(r)] = v;
    }
  }
  for (size_t r = 1; r < this->ForcingTimes.size(); ++r) {
    if (!(this->ForcingTimes[r] > this->ForcingTimes[r - 1])) {
      vtkErrorMacro("Snow Melt's Forcing times must increase strictly; row "
                    << r << " has " << this->ForcingTimes[r] << " s after "
                    << this->ForcingTimes[r - 1]
                    << " s. Sort the table and remove repeated times.");
      return 0;
    }
  }
  return 1;
}

void vtkSnowMeltFilter::ForcingAt(double t, double &temperature, double &precipitation) const {
  temperature = this->AirTemperature;
  precipitation = this->Precipitation;
  if (this->ForcingTimes.empty()) {
    return;
  }
  // The last row at or before t; before the first row, the first.
  const auto after = std::upper_bound(this->ForcingTimes.begin(), this->ForcingTimes.end(), t);
  const size_t row = after == this->ForcingTimes.begin()
                         ? 0
                         : static_cast<size_t>(after - this->ForcingTimes.begin()) - 1;
  if (!this->ForcingTemperature.empty()) {
    temperature = this->ForcingTemperature[row];
  }
  if (!this->ForcingPrecipitation.empty()) {
    precipitation = this->ForcingPrecipitation[row];
  }
}

int vtkSnowMeltFilter::SetUpState(vtkInformationVector **inputVector) {
  vtkImageData *terrain = vtkImageData::GetData(inputVector[0]);
  if (!this->CheckTerrain(terrain)) {
    return 0;
  }
  int dims[3];
  terrain->GetDimensions(dims);
  vtkDataArray *elevationArray = this->GetElevation(terrain, "Input");
  if (!elevationArray || !this->CheckParameters() || !this->ReadForcing(inputVector)) {
    return 0;
  }
  vtkPointData *pd = terrain->GetPointData();
  vtkDataArray *depthArray = pd->GetArray("snow_depth");
  vtkDataArray *densityArray = pd->GetArray("snow_density");
  if (!depthArray && !(this->InitialSnowDepth > 0.0)) {
    vtkErrorMacro("Snow Melt has no snow: its Input has no point array snow_depth and "
                  "InitialSnowDepth is 0 m. Connect Snow Accumulation's or Snow Deformation's "
                  "output, or set InitialSnowDepth (m) above 0.");
    return 0;
  }

  gr_snow_melt_params p;
  gr_snow_melt_params_init(&p);
  p.latitude = this->Latitude;
  p.start_day = this->StartDayOfYear;
  p.start_hour = this->StartHour;
  p.time_step = this->TimeStep * ToCore("TimeStep");
  p.melt_factor = this->MeltFactor * ToCore("MeltFactor");
  p.radiation_factor = this->RadiationFactor * ToCore("RadiationFactor");
  p.threshold = this->ThresholdTemperature;
  p.lapse_rate = this->LapseRate * ToCore("LapseRate");
  p.reference_elevation = this->ReferenceElevation;
  p.transmissivity = this->Transmissivity;
  p.rain_snow_threshold = this->RainSnowThreshold;
  p.rain_snow_band = this->RainSnowBand;
  p.new_snow_density = this->NewSnowDensity * ToCore("NewSnowDensity");
  p.max_density = this->MaxDensity * ToCore("MaxDensity");
  p.settling_time = this->SettlingTime * ToCore("SettlingTime");
  p.liquid_capacity = this->LiquidWaterCapacity;
  p.refreeze_factor = this->RefreezeFactor * ToCore("RefreezeFactor");
  p.cast_shadows = this->CastShadows;
  p.horizon_sectors = this->HorizonSectors;
  char msg[512];
  if (gr_snow_melt_params_validate(&p, msg, sizeof(msg)) != GR_OK) {
    vtkErrorMacro("Snow Melt: " << msg);
    return 0;
  }

  gr_grid grid;
  TerrainGrid(terrain, &grid);
  graupel::Pieces &pieces = this->GetPieces();
  pieces.PieceGrid(&grid);
  gr_context *ctx = this->GetContext();
  if (!ctx) {
    return 0;
  }
  // The core's state on this rank's piece; the output's ten fields, the
  // uploads' staging planes and the whole grid's heights kept for the output.
  gr_memory_need need;
  gr_snow_melt_memory(&grid, &p, &need);
  // With FollowInputTime, a frame's two forcing planes are staged too.
  if (!this->CheckMemory(grid, need, 4.0 * (10 + 3 + 1 + (this->FollowInputTime ? 2 : 0)))) {
    return 0;
  }
  const vtkIdType n = static_cast<vtkIdType>(dims[0]) * dims[1];
  vtkSmartPointer<vtkFloatArray> elevation = AsFloat(elevationArray);
  std::vector<graupel::Upload> uploads;
  uploads.push_back({GR_FIELD_ELEVATION, elevation});
  auto constant = [n](double value) {
    vtkSmartPointer<vtkFloatArray> a = vtkSmartPointer<vtkFloatArray>::New();
    a->SetNumberOfTuples(n);
    a->FillValue(static_cast<float>(value));
    return a;
  };
  uploads.push_back(
      {GR_FIELD_SNOW_DEPTH, depthArray ? AsFloat(depthArray) : constant(this->InitialSnowDepth)});
  uploads.push_back({GR_FIELD_SNOW_DENSITY,
                     densityArray ? AsFloat(densityArray) : constant(this->InitialDensity)});
  for (const graupel::Upload &u : uploads) {
    if (!this->ReportError(graupel::CheckPerPoint("Snow Melt", u, static_cast<size_t>(n)))) {
      return 0;
    }
  }

  gr_status st = gr_snow_melt_create(ctx, &grid, &p, &this->Simulation);
  if (st != GR_OK) {
    return this->ReportFailure(st, "Snow Melt could not set up the simulation");
  }
  this->Dimensions[0] = dims[0];
  this->Dimensions[1] = dims[1];
  // Stepping is point-local: a split run needs no halo calls, only the
  // ledger's allreduce (and the whole terrain for the horizons, below).
  if (pieces.IsSplit()) {
    gr_snow_melt_set_allreduce(this->Simulation, graupel::Pieces::Allreduce, &pieces);
  }
  for (const graupel::Upload &u : uploads) {
    const std::vector<float> local = pieces.LocalField(u.values->GetPointer(0), dims[0], 1);
    st = gr_snow_melt_set_field(this->Simulation, u.field, local.data());
    if (st != GR_OK) {
      vtkErrorMacro("Snow Melt's Input: " << gr_snow_melt_last_error(this->Simulation));
      this->ReleaseState();
      return 0;
    }
  }
  if (this->CastShadows) {
    // The horizons cross the cuts: every rank gets the whole terrain once.
    st = gr_snow_melt_set_terrain(this->Simulation, elevation->GetPointer(0));
    if (st != GR_OK) {
      vtkErrorMacro("Snow Melt's Input: " << gr_snow_melt_last_error(this->Simulation));
      this->ReleaseState();
      return 0;
    }
  }
  this->Elevation.assign(elevation->GetPointer(0), elevation->GetPointer(0) + n);
  // A followed Input: the per-point forcing of the frame it holds now.
  this->UseTemperatureField = 0;
  this->UsePrecipitationField = 0;
  if (this->FollowInputTime && !this->SetForcingFromInput(terrain)) {
    this->ReleaseState();
    return 0;
  }
  this->FrameReadAt = this->GetTemporalInputTime(0);
  gr_snow_melt_set_progress(this->Simulation, &vtkGraupelSimulation::CoreProgress, this);
  return 1;
}

int vtkSnowMeltFilter::SetForcingFromInput(vtkImageData *frame) {
  const struct {
    const char *name;
    int field;
    int *use;
  } arrays[] = {{"air_temperature", GR_SNOW_MELT_TEMPERATURE, &this->UseTemperatureField},
                {"precipitation", GR_SNOW_MELT_PRECIPITATION, &this->UsePrecipitationField}};
  vtkPointData *pd = frame ? frame->GetPointData() : nullptr;
  int dims[3] = {0, 0, 0};
  if (frame) {
    frame->GetDimensions(dims);
  }
  const double t = this->GetTemporalInputTime(0);
  for (const auto &a : arrays) {
    // Each frame decides alone: without the array, the Forcing table or the
    // constant property holds over its interval.
    *a.use = 0;
    vtkDataArray *array = pd ? pd->GetArray(a.name) : nullptr;
    if (!array) {
      continue;
    }
    if (dims[0] != this->Dimensions[0] || dims[1] != this->Dimensions[1] ||
        array->GetNumberOfComponents() != 1) {
      vtkErrorMacro("Snow Melt's Input at t = "
                    << t << " s has " << dims[0] << " x " << dims[1] << " points with "
                    << array->GetNumberOfComponents() << " component(s) of '" << a.name
                    << "' but the simulation runs on " << this->Dimensions[0] << " x "
                    << this->Dimensions[1]
                    << " points; give every time step the same grid and one value a point.");
      return 0;
    }
    vtkSmartPointer<vtkFloatArray> values = AsFloat(array);
    const std::vector<float> local =
        this->GetPieces().LocalField(values->GetPointer(0), dims[0], 1);
    const gr_status st = gr_snow_melt_set_field(this->Simulation, a.field, local.data());
    if (st != GR_OK) {
      vtkErrorMacro(
          "Snow Melt's Input at t = " << t << " s: " << gr_snow_melt_last_error(this->Simulation));
      return 0;
    }
    *a.use = 1;
  }
  return 1;
}

int vtkSnowMeltFilter::ResetState() {
  // The followed Input's forcing is not in the core's state: the next
  // advance sets that of the frame it needs again.
  this->FrameReadAt = std::numeric_limits<double>::quiet_NaN();
  const gr_status st = gr_snow_melt_reset(this->Simulation);
  gr_snow_melt_set_progress(this->Simulation, &vtkGraupelSimulation::CoreProgress, this);
  return st == GR_OK ? 1
                     : this->ReportFailure(st, "Snow Melt could not restart",
                                           gr_snow_melt_last_error(this->Simulation));
}

int vtkSnowMeltFilter::AdvanceState(double t0, double t1) {
  // A progress callback that asked to stop leaves the core refusing steps
  // until it is set again; an abort consumed since must not stop this call.
  gr_snow_melt_set_progress(this->Simulation, &vtkGraupelSimulation::CoreProgress, this);
  // An output interval starts: melt_rate, water_release and the ledger's
  // released_since_mark at the next output are over it alone. The mark is
  // in the core's state, so a checkpoint (taken at an output, before this)
  // restores it as it was.
  if (this->IsOutputTime(t0)) {
    const gr_status st = gr_snow_melt_mark(this->Simulation);
    if (st != GR_OK) {
      return this->ReportFailure(st, "Snow Melt could not start an output interval",
                                 gr_snow_melt_last_error(this->Simulation));
    }
  }
  // A followed Input (FollowInputTime): the per-point forcing of the frame
  // that holds over [t0, t1] (the base cuts the advances at the frames).
  if (this->IsInputTemporal(0) && this->GetTemporalInputTime(0) != this->FrameReadAt) {
    if (!this->SetForcingFromInput(vtkImageData::SafeDownCast(this->GetTemporalInput(0)))) {
      return ADVANCE_FAILED;
    }
    this->FrameReadAt = this->GetTemporalInputTime(0);
  }
  // Pieces split at the Forcing's row times: the forcing is constant over
  // each advance. The cuts depend on t0, t1 and the table only.
  double t = t0;
  while (t < t1) {
    double next = t1;
    const auto after = std::upper_bound(this->ForcingTimes.begin(), this->ForcingTimes.end(), t);
    if (after != this->ForcingTimes.end() && *after < t1) {
      next = *after;
    }
    gr_snow_melt_forcing f;
    f.use_temperature_field = this->UseTemperatureField;
    f.use_precipitation_field = this->UsePrecipitationField;
    this->ForcingAt(t, f.air_temperature, f.precipitation);
    gr_status st = gr_snow_melt_set_forcing(this->Simulation, &f);
    if (st != GR_OK) {
      return this->ReportFailure(st, "Snow Melt's forcing",
                                 gr_snow_melt_last_error(this->Simulation));
    }
    st = gr_snow_melt_advance(this->Simulation, next - t, nullptr);
    if (st == GR_ERR_ABORTED) {
      return ADVANCE_ABORTED;
    }
    if (st != GR_OK) {
      return this->ReportFailure(st, "Snow Melt could not advance",
                                 gr_snow_melt_last_error(this->Simulation));
    }
    t = next;
  }
  return ADVANCE_DONE;
}

int vtkSnowMeltFilter::SaveState(std::vector<unsigned char> &bytes) {
  size_t size = 0;
  if (gr_snow_melt_state_size(this->Simulation, &size) != GR_OK) {
    return 0;
  }
  bytes.resize(size);
  return gr_snow_melt_state_save(this->Simulation, bytes.data(), size) == GR_OK;
}

int vtkSnowMeltFilter::LoadState(const std::vector<unsigned char> &bytes) {
  this->FrameReadAt = std::numeric_limits<double>::quiet_NaN();
  return gr_snow_melt_state_load(this->Simulation, bytes.data(), bytes.size()) == GR_OK;
}

int vtkSnowMeltFilter::FillOutput(vtkDataObject *outputObject, vtkInformation *outInfo) {
  const gr_snow_melt_output outputs[] = {GR_SNOW_MELT_SNOW_DEPTH, GR_SNOW_MELT_SNOW_DENSITY,
                                         GR_SNOW_MELT_SWE,        GR_SNOW_MELT_LIQUID_WATER,
                                         GR_SNOW_MELT_MELT_RATE,  GR_SNOW_MELT_WATER_RELEASE,
                                         GR_SNOW_MELT_RADIATION};
  std::vector<ImageArray> arrays;
  for (gr_snow_melt_output o : outputs) {
    arrays.push_back({gr_snow_melt_output_name(o), 1, [this, o](float *values) {
                        return static_cast<int>(gr_snow_melt_get(this->Simulation, o, values));
                      }});
  }
  // The heights, as the core was given them: the own rows of the whole grid's.
  arrays.push_back(
      {"elevation", 1, [this](float *values) {
         graupel::Pieces &pieces = this->GetPieces();
         const size_t nx = static_cast<size_t>(this->Dimensions[0]);
         const size_t first =
             pieces.IsSplit() ? static_cast<size_t>(pieces.GetOwnFirstRow()) * nx : 0;
         const size_t count =
             nx * static_cast<size_t>(pieces.IsSplit() ? pieces.GetOwnRows() : this->Dimensions[1]);
         if (first + count > this->Elevation.size()) {
           return static_cast<int>(GR_ERR_INVALID_ARGUMENT);
         }
         std::copy_n(this->Elevation.begin() + static_cast<std::ptrdiff_t>(first), count, values);
         return static_cast<int>(GR_OK);
       }});
  if (!this->FillImage(outputObject, outInfo, arrays,
                       [this] { return gr_snow_melt_last_error(this->Simulation); })) {
    return 0;
  }
  // Rain Runoff's rain: the water released, m/s.
  vtkImageData *output = vtkImageData::SafeDownCast(outputObject);
  vtkDataArray *release = output->GetPointData()->GetArray("water_release");
  vtkNew<vtkFloatArray> rain;
  rain->SetName("rain_rate");
  rain->SetNumberOfTuples(release->GetNumberOfTuples());
  for (vtkIdType k = 0; k < release->GetNumberOfTuples(); ++k) {
    rain->SetValue(k, static_cast<float>(release->GetComponent(k, 0) / 3.6e6));
  }
  output->GetPointData()->AddArray(rain);

  gr_snow_melt_ledger ledger;
  const gr_status st = gr_snow_melt_ledger_get(this->Simulation, &ledger);
  if (st != GR_OK) {
    return this->ReportFailure(st, "Snow Melt could not read its ledger",
                               gr_snow_melt_last_error(this->Simulation));
  }
  vtkFieldData *fd = output->GetFieldData();
  AddValue(fd, "time", this->GetStateTime());
  AddValue(fd, "steps", static_cast<double>(ledger.steps));
  AddValue(fd, "snowfall_in", ledger.snowfall_in);
  AddValue(fd, "snowfall_volume", ledger.snowfall_volume);
  AddValue(fd, "rain_volume", ledger.rain_volume);
  AddValue(fd, "melt_volume", ledger.melt_volume);
  AddValue(fd, "refrozen_volume", ledger.refrozen_volume);
  AddValue(fd, "released_volume", ledger.released_volume);
  AddValue(fd, "released_interval_volume", ledger.released_since_mark);
  AddValue(fd, "stored_swe_volume", ledger.stored_swe_volume);
  AddValue(fd, "stored_liquid_volume", ledger.stored_liquid_volume);
  AddValue(fd, "balance_error", ledger.balance_error);
  return 1;
}

void vtkSnowMeltFilter::ReleaseState() {
  gr_snow_melt_destroy(this->Simulation);
  this->Simulation = nullptr;
}

void vtkSnowMeltFilter::PrintSelf(ostream &os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  os << indent << "AirTemperature: " << this->AirTemperature << " degC\n";
  os << indent << "Precipitation: " << this->Precipitation << " mm/h\n";
  os << indent << "InitialSnowDepth: " << this->InitialSnowDepth << " m\n";
  os << indent << "InitialDensity: " << this->InitialDensity << " kg/m^3\n";
  os << indent << "Latitude: " << this->Latitude << " deg\n";
  os << indent << "StartDayOfYear: " << this->StartDayOfYear << "\n";
  os << indent << "StartHour: " << this->StartHour << " h\n";
  os << indent << "TimeStep: " << this->TimeStep << " s\n";
  os << indent << "MeltFactor: " << this->MeltFactor << " mm/(degC d)\n";
  os << indent << "RadiationFactor: " << this->RadiationFactor << " mm m^2/(W h degC)\n";
  os << indent << "ThresholdTemperature: " << this->ThresholdTemperature << " degC\n";
  os << indent << "LapseRate: " << this->LapseRate << " degC/km\n";
  os << indent << "ReferenceElevation: " << this->ReferenceElevation << " m\n";
  os << indent << "Transmissivity: " << this->Transmissivity << "\n";
  os << indent << "RainSnowThreshold: " << this->RainSnowThreshold << " degC\n";
  os << indent << "RainSnowBand: " << this->RainSnowBand << " degC\n";
  os << indent << "NewSnowDensity: " << this->NewSnowDensity << " kg/m^3\n";
  os << indent << "MaxDensity: " << this->MaxDensity << " kg/m^3\n";
  os << indent << "SettlingTime: " << this->SettlingTime << " d\n";
  os << indent << "LiquidWaterCapacity: " << this->LiquidWaterCapacity << "\n";
  os << indent << "RefreezeFactor: " << this->RefreezeFactor << " mm/(degC d)\n";
  os << indent << "CastShadows: " << this->CastShadows << "\n";
  os << indent << "HorizonSectors: " << this->HorizonSectors << "\n";
}
