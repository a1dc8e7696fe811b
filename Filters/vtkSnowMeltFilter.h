/**
 * @class   vtkSnowMeltFilter
 * @brief   Snowmelt by an enhanced temperature-index model (Hock 1999) with
 *          clear-sky radiation, cast shadows, rain, liquid water, refreezing
 *          and settling, stepped on OpenCL.
 *
 * Input 0 (`Input`) is a 2-D vtkImageData with the terrain heights (Height
 * Array, `elevation` by default, m) and, as Snow Accumulation and Snow
 * Deformation write them, the point arrays `snow_depth` (m) and
 * `snow_density` (kg/m^3). Without `snow_depth` the snow is InitialSnowDepth
 * (m) everywhere; without `snow_density`, InitialDensity (kg/m^3). An Input
 * without `snow_depth` while InitialSnowDepth is 0 is refused with one
 * sentence.
 *
 * Input 1 (`Forcing`, optional) is a vtkTable with the column `time` (s of
 * the simulation, strictly increasing) and any of `air_temperature` (degC
 * at ReferenceElevation) and `precipitation` (mm/h). Each row holds from its
 * time until the next row's (sample and hold; before the first row the
 * first holds, after the last the last): the core is advanced in pieces
 * split at the rows' times, so the forcing is constant over each advance. A
 * column that is missing, or no table, gives the constant properties
 * AirTemperature and Precipitation.
 *
 * Per-point forcing from a temporal Input (FollowInputTime 1): each time
 * step (frame) of the Input that has the point array `air_temperature`
 * (degC at the point; the lapse rate is not applied to it) and/or
 * `precipitation` (mm/h) sets that forcing point by point, held from the
 * frame's time until the next frame's (sample and hold, as the frames of a
 * weather model or a radar; before the first frame the first holds, after
 * the last the last). The core is advanced in pieces split at the frames'
 * times, as at the Forcing's rows. A frame without one of the arrays leaves
 * that quantity to the Forcing table or the constant property over its
 * interval, as without the Input's arrays; so each frame decides alone and
 * the result never depends on the order in which times are asked. A value
 * that is not finite or out of range (+-100 degC, 0 to 1000 mm/h) is
 * refused with one sentence naming the frame's time and the point, and an
 * empty output. The heights and the initial snow are read once, at
 * set-up: give every frame the same. With FollowInputTime 0 the Input's
 * air_temperature and precipitation are not read.
 *
 * The output has the Input's grid and the point arrays `snow_depth` (m;
 * active scalars), `snow_density` (kg/m^3), `swe` and `liquid_water` (m
 * w.e.), `melt_rate` and `water_release` (mm/h, the means over the output
 * interval that ends at this output), `radiation` (W/m^2, the last step's
 * mean), `elevation` (m) and `rain_rate` (m/s: water_release / 3.6e6, the
 * array Rain Runoff reads as its rain from a temporal Input, with
 * FollowInputTime on); and the field data `time`, `steps` and the ledger
 * (m^3): `snowfall_in`, `snowfall_volume`, `rain_volume`, `melt_volume`,
 * `refrozen_volume`, `released_volume`, `released_interval_volume` (released
 * over the output interval that ends here), `stored_swe_volume`,
 * `stored_liquid_volume` and `balance_error` (exactly 0: the core's state is
 * fixed point). The model is described in kernels/include/graupel/snow_melt.h.
 *
 * The season as a chain (Snow Accumulation -> Snow Melt -> Rain Runoff),
 * not one simulation stepping the three cores in lockstep: the filters
 * already exist, each keeps its own time step (an hour for the snow,
 * seconds for the water), and the chain is what users save in a state
 * file, split over ranks and check-point like any other. The price is a
 * coupling through output times, made exact by the rate being a mean:
 * rain_rate at an output is the release over the interval before it, and
 * Rain Runoff with RainFrames 1 rains each frame over that same interval,
 * so the water Rain Runoff books equals what Snow Melt released, whatever
 * the output interval (py.melt_runoff).
 *
 * In an MPI run (pvbatch, pvserver) each rank simulates its strip along y
 * with a ring of 1 row (the slopes); the horizons come from the whole
 * terrain, given to every rank; the ledger is reduced over the ranks
 * exactly (see vtkGraupelSimulation's "Distributed runs").
 *
 * The setters of the core's parameters clamp to its table
 * (gr_snow_melt_param_bounds); a value that is not a number, or at the open
 * end of a range (Transmissivity 0, SettlingTime 0), is refused at the next
 * update with a sentence.
 */
#ifndef vtkSnowMeltFilter_h
#define vtkSnowMeltFilter_h

#include "GraupelFiltersModule.h"
#include "vtkGraupelSimulation.h"

#include <vector>

struct gr_snow_melt;
class vtkImageData;

class GRAUPELFILTERS_EXPORT vtkSnowMeltFilter : public vtkGraupelSimulation {
public:
  static vtkSnowMeltFilter *New();
  vtkTypeMacro(vtkSnowMeltFilter, vtkGraupelSimulation);
  void PrintSelf(ostream &os, vtkIndent indent) override;

  ///@{
  /** Air temperature at ReferenceElevation, degC (default 2), when no Forcing column gives it. */
  virtual void SetAirTemperature(double value);
  vtkGetMacro(AirTemperature, double);
  ///@}

  ///@{
  /** Precipitation, mm/h (default 0), when no Forcing column gives it. */
  virtual void SetPrecipitation(double value);
  vtkGetMacro(Precipitation, double);
  ///@}

  ///@{
  /** Snow depth where the Input has no snow_depth, m (default 0: the Input must have it). */
  virtual void SetInitialSnowDepth(double value);
  vtkGetMacro(InitialSnowDepth, double);
  ///@}

  ///@{
  /** Snow density where the Input has no snow_density, kg/m^3 (default 300). */
  virtual void SetInitialDensity(double value);
  vtkGetMacro(InitialDensity, double);
  ///@}

  ///@{
  /** The core's parameters; units and ranges are its table's (docs/SnowMelt.md). */
  virtual void SetLatitude(double value);
  vtkGetMacro(Latitude, double);
  virtual void SetStartDayOfYear(int value);
  vtkGetMacro(StartDayOfYear, int);
  virtual void SetStartHour(double value);
  vtkGetMacro(StartHour, double);
  virtual void SetTimeStep(double value);
  vtkGetMacro(TimeStep, double);
  virtual void SetMeltFactor(double value);
  vtkGetMacro(MeltFactor, double);
  virtual void SetRadiationFactor(double value);
  vtkGetMacro(RadiationFactor, double);
  virtual void SetThresholdTemperature(double value);
  vtkGetMacro(ThresholdTemperature, double);
  virtual void SetLapseRate(double value);
  vtkGetMacro(LapseRate, double);
  virtual void SetReferenceElevation(double value);
  vtkGetMacro(ReferenceElevation, double);
  virtual void SetTransmissivity(double value);
  vtkGetMacro(Transmissivity, double);
  virtual void SetRainSnowThreshold(double value);
  vtkGetMacro(RainSnowThreshold, double);
  virtual void SetRainSnowBand(double value);
  vtkGetMacro(RainSnowBand, double);
  virtual void SetNewSnowDensity(double value);
  vtkGetMacro(NewSnowDensity, double);
  virtual void SetMaxDensity(double value);
  vtkGetMacro(MaxDensity, double);
  /** Days. */
  virtual void SetSettlingTime(double value);
  vtkGetMacro(SettlingTime, double);
  virtual void SetLiquidWaterCapacity(double value);
  vtkGetMacro(LiquidWaterCapacity, double);
  virtual void SetRefreezeFactor(double value);
  vtkGetMacro(RefreezeFactor, double);
  virtual void SetCastShadows(int value);
  vtkGetMacro(CastShadows, int);
  virtual void SetHorizonSectors(int value);
  vtkGetMacro(HorizonSectors, int);
  ///@}

protected:
  vtkSnowMeltFilter();
  ~vtkSnowMeltFilter() override;

  int FillInputPortInformation(int port, vtkInformation *info) override;
  int SetUpState(vtkInformationVector **inputVector) override;
  int ResetState() override;
  int AdvanceState(double t0, double t1) override;
  int FillOutput(vtkDataObject *output, vtkInformation *outInfo) override;
  void ReleaseState() override;
  int SaveState(std::vector<unsigned char> &bytes) override;
  int LoadState(const std::vector<unsigned char> &bytes) override;
  const char *GetSimulationLabel() override { return "Snow Melt"; }

  double AirTemperature = 2.0;
  double Precipitation = 0.0;
  double InitialSnowDepth = 0.0;
  double InitialDensity = 300.0;
  double Latitude;
  int StartDayOfYear;
  double StartHour;
  double TimeStep;
  double MeltFactor;
  double RadiationFactor;
  double ThresholdTemperature;
  double LapseRate;
  double ReferenceElevation;
  double Transmissivity;
  double RainSnowThreshold;
  double RainSnowBand;
  double NewSnowDensity;
  double MaxDensity;
  double SettlingTime;
  double LiquidWaterCapacity;
  double RefreezeFactor;
  int CastShadows;
  int HorizonSectors;

private:
  vtkSnowMeltFilter(const vtkSnowMeltFilter &) = delete;
  void operator=(const vtkSnowMeltFilter &) = delete;

  int CheckParameters();
  /** The Forcing table's rows into ForcingTimes etc.; 0 after one sentence. */
  int ReadForcing(vtkInformationVector **inputVector);
  /** The forcing that holds from time t on (s). */
  void ForcingAt(double t, double &temperature, double &precipitation) const;
  /**
   * With FollowInputTime, the per-point air_temperature and precipitation
   * of the Input's frame now (frame), each to the core where the frame has
   * it, and the use flags; 0 after one sentence.
   */
  int SetForcingFromInput(vtkImageData *frame);

  gr_snow_melt *Simulation = nullptr;
  int Dimensions[2] = {0, 0};
  std::vector<float> Elevation;           // the whole grid's heights, for the output
  std::vector<double> ForcingTimes;       // empty: no table
  std::vector<double> ForcingTemperature; // empty: the column is missing
  std::vector<double> ForcingPrecipitation;
  // The followed Input's frame whose per-point forcing the core holds (NaN:
  // none yet, read it at the next advance) and which of its fields apply.
  double FrameReadAt = 0.0;
  int UseTemperatureField = 0;
  int UsePrecipitationField = 0;
};

#endif
