/**
 * @class   vtkSnowDeformationFilter
 * @brief   Objects pressing into and ploughing through snow (seed 000's
 *          thesis), stepped on OpenCL.
 *
 * Input 0 (`Input`) is the terrain: a 2-D vtkImageData with the point array
 * `elevation` (m). Optional point arrays on it give the snow at time 0:
 * `snow_depth` (m) and `snow_density` (kg/m^3), so Snow Accumulation's output
 * chains in; without them InitialSnowDepth and InitialDensity apply.
 *
 * Input 1 (`Objects`, optional) is a closed triangle mesh (vtkPolyData; its
 * polygons and strips are split into triangles here) or a multiblock of them,
 * one object per leaf. Each object is handed to the core in its own frame:
 * its vertices about the centre of its bounds, with a pose that puts it in
 * the world (float vertices stay exact far from the origin).
 * - Objects that do not advertise time steps move by the properties
 *   (vtkGraupelMotion): the centre moves at ObjectVelocity (m/s) and the
 *   object turns at ObjectAngularVelocity (deg/s) about RotationAxis
 *   through its centre; with a Path (input 2, a polyline) the centre follows
 *   the path at the speed |ObjectVelocity|, the object's +x turned along the
 *   path's tangent. A leaf's field data `velocity` (3 values, m/s) replaces
 *   ObjectVelocity for that object.
 * - Objects that advertise time steps are read at each (sample and hold,
 *   see vtkGraupelSimulation): their geometry is the pose, and their
 *   velocity (for the direction of the displaced snow and the resistance) is
 *   the leaf's field data `velocity`, else ObjectVelocity.
 *
 * Time: every interval between the simulation's knots (output times, the
 * objects' time steps) is stepped in TimeStep-sized steps, the last one
 * shortened to end on the knot; each step takes the objects at their pose at
 * the step's end. The knots depend on properties and inputs only, so a
 * result does not depend on the order in which times are requested.
 *
 * Output 0 has the terrain's geometry and the point arrays `snow_depth` (m,
 * active scalars), `snow_surface` (m), `snow_density` (kg/m^3), `overlap`
 * (m, last step), `contact` (1 under an object in the last step) and
 * `elevation`; field data `time` (s), `steps`, `snow_volume` (m^3),
 * `snow_mass` (kg), `compressed_volume` and `displaced_volume` (m^3,
 * cumulative), `balance_error` (kg: mass now minus mass at the start),
 * `volume_error` (m^3) and `relax_iterations`. Output 1 is the objects at
 * their pose at the output time (vtkPolyData, or a multiblock of the same
 * structure as the input), each with field data `force` (3 components, N:
 * the snow's resistance, the mean over the output interval that ends at
 * the output: the impulse of its steps over its time, which does not alias
 * with the step as one step's force does), `peak_force` (N, the largest
 * step force's magnitude in that interval) and `contact_area` (m^2); a
 * multiblock's own field data holds the sums (the largest peak).
 *
 * The snow type: DensityRange (rho min, rho max) and InitialDensity, or a
 * DensityPreset (the thesis' Table 3.1 snow types, and sand), which then
 * sets both: the range it names and an initial density at its loose end.
 *
 * An object that never comes over the grid (its bounds more than a grid
 * spacing beyond the terrain's at every step up to EndTime) is refused: it
 * is a misplaced object, not an idle one. Objects with time steps are taken
 * as they come.
 *
 * Time defaults (SetTimeDefaults): EndTime 10 s, OutputInterval 0.25 s,
 * the scale of a wheel crossing a few metres of snow in steps of 1/60 s.
 *
 * MPI (pvbatch, pvserver): each rank simulates its strip of the grid with
 * the core's ring of GR_SNOW_DEFORMATION_GHOST rows (see vtkGraupelSimulation,
 * "Distributed runs"); every rank takes every object, the core sums what
 * steers a step over the ranks, and every rank's ledger and forces are the
 * whole grid's, bit for bit. Field data `piece_cells` gives the grid points
 * the rank simulated, ring included.
 * The model is described in kernels/include/graupel/snow_deformation.h; the
 * setters clamp to its parameter table (gr_snow_deformation_param_bounds).
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
