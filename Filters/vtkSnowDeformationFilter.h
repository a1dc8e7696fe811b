/**
 * @class   vtkSnowDeformationFilter
 * @brief   Objects pressing into and ploughing through snow (seed 000's
 *          thesis), stepped on OpenCL.
 *
 * Input 0 is the terrain (a 2-D image with `elevation`, m, and optionally
 * `snow_depth` and `snow_density` at time 0, so Snow Accumulation's output
 * chains in; else InitialSnowDepth and InitialDensity); input 1 the Objects
 * (closed triangle meshes or a multiblock of them, moving with
 * ObjectVelocity, along a Path, or by their own time steps); input 2 an
 * optional Path. Output 0 is the terrain's grid with the snow (`snow_depth`,
 * `snow_density`, `snow_surface`, ...) and the mass ledger; output 1 the
 * objects at their pose with the force on each. The page
 * docs/SnowDeformation.md gives every array, property and unit; the model
 * and its departures from the seed are the core's header,
 * kernels/include/graupel/snow_deformation.h.
 *
 * Time, checkpoints, temporal objects, aborts and MPI pieces are
 * vtkGraupelSimulation's and vtkGraupelObjectsSimulation's. The setters clamp
 * to the core's parameter table; values it refuses give one sentence at the
 * next update.
 */
#ifndef vtkSnowDeformationFilter_h
#define vtkSnowDeformationFilter_h

#include "GraupelFiltersModule.h"
#include "vtkGraupelObjectsSimulation.h"

#include <vector>

struct gr_snow_deformation;
class vtkDataObject;

class GRAUPELFILTERS_EXPORT vtkSnowDeformationFilter : public vtkGraupelObjectsSimulation {
public:
  static vtkSnowDeformationFilter *New();
  vtkTypeMacro(vtkSnowDeformationFilter, vtkGraupelObjectsSimulation);
  void PrintSelf(ostream &os, vtkIndent indent) override;

  enum CompressionModels { DENSITY_DRIVEN = 0, CONSTANT_FRACTION = 1 };

  /** Snow types of the thesis' Table 3.1, and sand (see GetDensityPresetRange). */
  enum DensityPresets {
    CUSTOM = 0, // DensityRange and InitialDensity as set
    DRY_NEW_SNOW = 1,
    BONDED_NEW_SNOW = 2,
    STRONGLY_BONDED_NEW_SNOW = 3,
    DRY_OLD_SNOW = 4,
    WET_OLD_SNOW = 5,
    DEPTH_HOAR = 6,
    FIRN = 7,
    ICE = 8,
    SAND = 9
  };

  ///@{
  /** Length of one simulation step, s (default 1/60; from 1e-6 to 60). */
  virtual void SetTimeStep(double value);
  vtkGetMacro(TimeStep, double);
  ///@}

  ///@{
  /** Snow depth where the Input has no `snow_depth`, m (default 0.5). */
  virtual void SetInitialSnowDepth(double value);
  vtkGetMacro(InitialSnowDepth, double);
  ///@}

  ///@{
  /** Snow density where the Input has no `snow_density`, kg/m^3 (default 150). */
  virtual void SetInitialDensity(double value);
  vtkGetMacro(InitialDensity, double);
  ///@}

  ///@{
  /** Density of the loosest snow (rho_min), kg/m^3 (default 100). */
  virtual void SetMinDensity(double value);
  vtkGetMacro(MinDensity, double);
  ///@}

  ///@{
  /** Density of fully compressed snow (rho_max), kg/m^3 (default 400). */
  virtual void SetMaxDensity(double value);
  vtkGetMacro(MaxDensity, double);
  ///@}

  ///@{
  /**
   * Both densities at once, kg/m^3 (ParaView's DensityRange, default 100
   * 400): the custom range, in force while DensityPreset is CUSTOM.
   */
  void SetDensityRange(double minimum, double maximum);
  void SetDensityRange(const double range[2]) { this->SetDensityRange(range[0], range[1]); }
  void GetDensityRange(double range[2]) const;
  ///@}

  ///@{
  /**
   * A snow type (DensityPresets; default CUSTOM). Any but CUSTOM sets the
   * density range to the type's and the initial density to its loose end,
   * in place of DensityRange and InitialDensity, which are kept for CUSTOM.
   */
  vtkSetClampMacro(DensityPreset, int, CUSTOM, SAND);
  vtkGetMacro(DensityPreset, int);
  ///@}

  /** A preset's density range, kg/m^3; false (range untouched) for CUSTOM or no preset. */
  static bool GetDensityPresetRange(int preset, double range[2]);

  /** The density range in force: the preset's, or DensityRange for CUSTOM, kg/m^3. */
  void GetDensityRangeInUse(double range[2]) const;
  /** The initial density in force: the preset's loose end, or InitialDensity, kg/m^3. */
  double GetInitialDensityInUse() const;

  ///@{
  /** 0: density-driven compression (default); 1: a constant 15 % compressed. */
  virtual void SetCompressionModel(int value);
  vtkGetMacro(CompressionModel, int);
  ///@}

  ///@{
  /** Steepest slope the snow keeps (talus), m/m (default 0.6). */
  virtual void SetMaxSlope(double value);
  vtkGetMacro(MaxSlope, double);
  ///@}

  ///@{
  /** K of the direction weights: higher sends more snow ahead (default 8). */
  virtual void SetDirectionFalloff(double value);
  vtkGetMacro(DirectionFalloff, double);
  ///@}

  ///@{
  /** Most talus relaxation iterations per step. */
  virtual void SetMaxRelaxIterations(int value);
  vtkGetMacro(MaxRelaxIterations, int);
  ///@}

  ///@{
  /** Talus relaxation stops when no point can move more snow than this, m. */
  virtual void SetRelaxTolerance(double value);
  vtkGetMacro(RelaxTolerance, double);
  ///@}

  ///@{
  /**
   * How fast snow slides down a slope steeper than MaxSlope, m/s (default
   * 2, about sqrt(g H) for a pile H = 0.4 m high; 0: instantly, every step
   * relaxes to the end). A step of dt runs at most ceil(SlumpSpeed dt /
   * spacing) talus iterations, the rest goes on in the next steps, so a
   * collapse takes the same time on every grid.
   */
  virtual void SetSlumpSpeed(double value);
  vtkGetMacro(SlumpSpeed, double);
  ///@}

protected:
  vtkSnowDeformationFilter();
  ~vtkSnowDeformationFilter() override;

  int FillOutputPortInformation(int port, vtkInformation *info) override;

  int SetUpState(vtkInformationVector **inputVector) override;
  int ResetState() override;
  int AdvanceState(double t0, double t1) override;
  int FillOutput(vtkDataObject *output, vtkInformation *outInfo) override;
  void ReleaseState() override;
  int SaveState(std::vector<unsigned char> &bytes) override;
  int LoadState(const std::vector<unsigned char> &bytes) override;
  const char *GetSimulationLabel() override { return "Snow Deformation"; }

  double TimeStep = 1.0 / 60.0;
  double InitialSnowDepth = 0.5;
  double InitialDensity = 150.0;
  double MinDensity = 100.0;
  double MaxDensity = 400.0;
  int DensityPreset = CUSTOM;
  int CompressionModel = DENSITY_DRIVEN;
  double MaxSlope = 0.6;
  double DirectionFalloff = 8.0;
  int MaxRelaxIterations = 0; // the table's default, set in the constructor
  double RelaxTolerance = 0.0;
  double SlumpSpeed = 0.0; // the table's default, set in the constructor

private:
  vtkSnowDeformationFilter(const vtkSnowDeformationFilter &) = delete;
  void operator=(const vtkSnowDeformationFilter &) = delete;

  int CheckParameters();
  /** Refuses an object that is over the terrain's grid at no step up to EndTime. */
  int CheckObjectsReachGrid(const double gridBounds[4], double margin);
  /** Hands the objects at their poses at time t to the core (velocities over [t - h, t]). */
  int SetObjects(double t, double h);
  /** The objects at their poses at time t with their forces and contact areas (output 1). */
  int FillObjectOutput(int port, vtkDataObject *output, double t) override;

  gr_snow_deformation *Simulation = nullptr;
};

#endif
