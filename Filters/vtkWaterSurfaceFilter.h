/**
 * @class   vtkWaterSurfaceFilter
 * @brief   Waves on standing water (seed 003's height-field water surface,
 *          seed 004's raindrop ripples), stepped on OpenCL.
 *
 * Input 0 (`Input`) is a 2-D vtkImageData with the point array `elevation`
 * (m) and, optionally, `water_depth` (m): Rain Runoff's output, or a
 * terrain. The water is where water_depth exceeds WetDepth, or, with
 * UseLakeLevel on, where the elevation lies below LakeLevel (a lake replaces
 * any water_depth). An input with neither is refused with one sentence.
 * Connected to Rain Runoff (a time source), the water is Rain Runoff's at
 * its end (InputTime, see vtkGraupelSimulation); with FollowInputTime on it
 * follows the depth at each of Rain Runoff's time steps (sample and hold).
 *
 * The output has the input's geometry and the point arrays `wave_height`
 * (m above the still water, 0 on dry points; active scalars),
 * `water_surface` (m: elevation + depth + wave), `normal` (the water
 * surface's unit normal, 3 components; (0, 0, 1) on dry points and level
 * water), `wet` (1 or 0), `elevation` and `water_depth` (m, the still
 * water's), and the field data `time`, `steps`, `wet_points`,
 * `wave_volume`, `initial_volume` (m^3: equal to rounding, the mean level
 * is conserved), `energy` (m^4/s^2) and `max_wave` (m). The model is
 * described in kernels/include/graupel/water_surface.h.
 *
 * In an MPI run (pvbatch, pvserver) each rank simulates its strip along y
 * with the core's ring of 1 + the drops' reach in rows
 * (gr_water_surface_ghost), exchanging one row of wave height per step;
 * the ledger is reduced over the ranks exactly, so every rank reports the
 * whole grid's, and the field data `piece_cells` gives the points a rank
 * simulated (see vtkGraupelSimulation's "Distributed runs").
 *
 * The setters clamp to the core's parameter table
 * (gr_water_surface_param_bounds); a value that is not a number, or at the
 * open end of a range such as WaveSpeed's 0, is refused at the next update
 * with a sentence.
 */
#ifndef vtkWaterSurfaceFilter_h
#define vtkWaterSurfaceFilter_h

#include "GraupelFiltersModule.h"
#include "vtkGraupelSimulation.h"

struct gr_water_surface;

class GRAUPELFILTERS_EXPORT vtkWaterSurfaceFilter : public vtkGraupelSimulation {
public:
  static vtkWaterSurfaceFilter *New();
  vtkTypeMacro(vtkWaterSurfaceFilter, vtkGraupelSimulation);
  void PrintSelf(ostream &os, vtkIndent indent) override;

  ///@{
  /** Wave speed c, m/s (default 1: sqrt(g d) of 10 cm of water). */
  virtual void SetWaveSpeed(double value);
  vtkGetMacro(WaveSpeed, double);
  ///@}

  ///@{
  /** Damping gamma, 1/s (default 0.1): the wave energy decays as exp(-gamma t). */
  virtual void SetDamping(double value);
  vtkGetMacro(Damping, double);
  ///@}

  ///@{
  /** Points deeper than this carry waves, m (default 0.01). */
  virtual void SetWetDepth(double value);
  vtkGetMacro(WetDepth, double);
  ///@}

  ///@{
  /** 1: a lake where the elevation lies below LakeLevel (default 0: water_depth). */
  virtual void SetUseLakeLevel(int value);
  vtkGetMacro(UseLakeLevel, int);
  ///@}

  ///@{
  /** The lake's level, m (default 0). */
  virtual void SetLakeLevel(double value);
  vtkGetMacro(LakeLevel, double);
  ///@}

  ///@{
  /** Raindrops per m^2 per s (default 0.1; 0: none). */
  virtual void SetDropRate(double value);
  vtkGetMacro(DropRate, double);
  ///@}

  ///@{
  /** Depth of a drop's dimple, m (default 0.005). */
  virtual void SetDropAmplitude(double value);
  vtkGetMacro(DropAmplitude, double);
  ///@}

  ///@{
  /** Radius (the Gaussian's sigma) of a drop's dimple, m (default 0.5). */
  virtual void SetDropRadius(double value);
  vtkGetMacro(DropRadius, double);
  ///@}

  ///@{
  /** Seed of the drops (default 1). */
  virtual void SetSeed(int value);
  vtkGetMacro(Seed, int);
  ///@}

  ///@{
  /** Fraction of the CFL limit each step takes (default 0.5). */
  virtual void SetCourantNumber(double value);
  vtkGetMacro(CourantNumber, double);
  ///@}

protected:
  vtkWaterSurfaceFilter();
  ~vtkWaterSurfaceFilter() override;

  int RequestInformation(vtkInformation *request, vtkInformationVector **inputVector,
                         vtkInformationVector *outputVector) override;
  int SetUpState(vtkInformationVector **inputVector) override;
  int ResetState() override;
  int AdvanceState(double t0, double t1) override;
  int FillOutput(vtkDataObject *output, vtkInformation *outInfo) override;
  void ReleaseState() override;
  int SaveState(std::vector<unsigned char> &bytes) override;
  int LoadState(const std::vector<unsigned char> &bytes) override;
  const char *GetSimulationLabel() override { return "Water Surface"; }

  double WaveSpeed = 1.0;
  double Damping = 0.1;
  double WetDepth = 0.01;
  int UseLakeLevel = 0;
  double LakeLevel = 0.0;
  double DropRate = 0.1;
  double DropAmplitude = 0.005;
  double DropRadius = 0.5;
  int Seed = 1;
  double CourantNumber = 0.5;

private:
  vtkWaterSurfaceFilter(const vtkWaterSurfaceFilter &) = delete;
  void operator=(const vtkWaterSurfaceFilter &) = delete;

  int CheckParameters();
  /** Uploads the input's elevation and water_depth (the temporal input's now). */
  int ReadWater(vtkDataObject *input);

  gr_water_surface *Simulation = nullptr;
  int Dimensions[2] = {0, 0};
  double WaterReadAt = 0.0; // the input time the uploaded water is of; NaN: none
};

#endif
