/**
 * @class   vtkRainRunoffFilter
 * @brief   Rain on a terrain: rain gain, infiltration, runoff and pooling
 *          (seed 004's water simulation), stepped on OpenCL.
 *
 * Input 0 (`Input`) is the terrain: a 2-D vtkImageData with the point array
 * `elevation` (m; an input without it is refused: active scalars are not
 * guessed at). Optional point arrays on it: `water_depth` (m, the water present at
 * time 0) or `water_surface` (m: the depth is max(0, surface - elevation)),
 * `velocity` (m/s, 3 components, z ignored: the water's velocity at time 0;
 * the local inertial model starts from rest and leaves it out) and
 * `rain_rate` (m/s, replaces RainRate cell by cell). With both water_depth
 * and water_surface (a Rain Runoff output as the input) water_depth is
 * taken.
 * Input 1 (`PermeabilityMap`, optional) is an image with the same dimensions
 * whose point array `permeability` (m/s) replaces Permeability.
 *
 * The output has the terrain's geometry and the point arrays `water_depth`
 * (m, active scalars), `water_surface` (m), `velocity` (m/s, 3 components),
 * `discharge` (m^2/s), `infiltrated` (m, cumulative) and `elevation`, and
 * the field data `time`, `steps`, `initial_volume`, `rain_volume`,
 * `infiltrated_volume`, `outflow_volume`, `stored_volume`, `balance_error`
 * (m^3, double) and `max_depth` (m). The model, its deviation from the seed
 * and its conservation are described in kernels/include/graupel/rain_runoff.h.
 *
 * Time is handled by vtkGraupelSimulation: request a time with
 * UpdateTimeStep(t) (ParaView's animation does it). Checkpoints are the
 * core's gr_rain_runoff_state_save/load; an abort is honoured inside an
 * output interval through the core's progress callback.
 *
 * The setters clamp to the core's parameter table
 * (gr_rain_runoff_param_bounds, in the user's units): a value beyond a
 * range becomes its end; a value that is not a number, or at the open end
 * of a range such as CourantNumber's 0, is refused at the next update with a
 * sentence in the user's unit.
 */
#ifndef vtkRainRunoffFilter_h
#define vtkRainRunoffFilter_h

#include "GraupelFiltersModule.h"
#include "vtkGraupelSimulation.h"

struct gr_rain_runoff;

class GRAUPELFILTERS_EXPORT vtkRainRunoffFilter : public vtkGraupelSimulation {
public:
  static vtkRainRunoffFilter *New();
  vtkTypeMacro(vtkRainRunoffFilter, vtkGraupelSimulation);
  void PrintSelf(ostream &os, vtkIndent indent) override;

  enum Boundaries { OPEN = 0, CLOSED = 1 };
  enum FlowModels { SHALLOW_WATER = 0, LOCAL_INERTIAL = 1 };

  ///@{
  /** Rain intensity, mm/h (default 10). */
  virtual void SetRainRate(double value);
  vtkGetMacro(RainRate, double);
  ///@}

  ///@{
  /** Infiltration capacity of the ground where no map is given, mm/h (default 0). */
  virtual void SetPermeability(double value);
  vtkGetMacro(Permeability, double);
  ///@}

  ///@{
  /** Manning roughness of the ground, s/m^(1/3) (default 0.03). */
  virtual void SetManningN(double value);
  vtkGetMacro(ManningN, double);
  ///@}

  ///@{
  /** 0: water leaves through the grid's edge (default); 1: the edge is a wall. */
  virtual void SetBoundary(int value);
  vtkGetMacro(Boundary, int);
  ///@}

  ///@{
  /** 0: the shallow-water equations with advection (default); 1: the local inertial scheme. */
  virtual void SetFlowModel(int value);
  vtkGetMacro(FlowModel, int);
  ///@}

  ///@{
  /** Longest simulation step, s (default 1); shorter ones are taken when the flow needs them. */
  virtual void SetMaxTimeStep(double value);
  vtkGetMacro(MaxTimeStep, double);
  ///@}

  ///@{
  /** Courant number of the adaptive step (default 0.7). */
  virtual void SetCourantNumber(double value);
  vtkGetMacro(CourantNumber, double);
  ///@}

  /** Connects the optional permeability map (input port 1). */
  void SetPermeabilityMapConnection(vtkAlgorithmOutput *output);

protected:
  vtkRainRunoffFilter();
  ~vtkRainRunoffFilter() override;

  int FillInputPortInformation(int port, vtkInformation *info) override;

  int SetUpState(vtkInformationVector **inputVector) override;
  int ResetState() override;
  int AdvanceState(double t0, double t1) override;
  int FillOutput(vtkDataObject *output, vtkInformation *outInfo) override;
  void ReleaseState() override;
  int SaveState(std::vector<unsigned char> &bytes) override;
  int LoadState(const std::vector<unsigned char> &bytes) override;
  const char *GetSimulationLabel() override { return "Rain Runoff"; }

  double RainRate = 10.0;
  double Permeability = 0.0;
  double ManningN = 0.03;
  int Boundary = OPEN;
  int FlowModel = SHALLOW_WATER;
  double MaxTimeStep = 1.0;
  double CourantNumber = 0.7;

private:
  vtkRainRunoffFilter(const vtkRainRunoffFilter &) = delete;
  void operator=(const vtkRainRunoffFilter &) = delete;

  /** 0 with one sentence in the user's unit when a property is out of its range. */
  int CheckParameters();

  gr_rain_runoff *Simulation = nullptr;
};

#endif
