/**
 * @class   vtkRainRunoffFilter
 * @brief   Rain on a terrain: rain gain, infiltration, runoff and pooling
 *          (seed 004's water simulation), stepped on OpenCL.
 *
 * Input 0 (`Input`) is the terrain: a 2-D vtkImageData with the point array
 * `elevation` (m; the active scalars are used when there is no array of that
 * name). Optional point arrays on it: `water_depth` (m, the water present at
 * time 0) and `rain_rate` (m/s, replaces RainRate cell by cell).
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
 * UpdateTimeStep(t) (ParaView's animation does it).
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

  ///@{
  /** Rain intensity, mm/h (default 10; 0..3600). */
  vtkSetMacro(RainRate, double);
  vtkGetMacro(RainRate, double);
  ///@}

  ///@{
  /** Infiltration capacity of the ground where no map is given, mm/h (default 0). */
  vtkSetMacro(Permeability, double);
  vtkGetMacro(Permeability, double);
  ///@}

  ///@{
  /** Manning roughness of the ground, s/m^(1/3) (default 0.03; 0.005..1). */
  vtkSetMacro(ManningN, double);
  vtkGetMacro(ManningN, double);
  ///@}

  ///@{
  /** 0: water leaves through the grid's edge (default); 1: the edge is a wall. */
  vtkSetClampMacro(Boundary, int, 0, 1);
  vtkGetMacro(Boundary, int);
  ///@}

  ///@{
  /** Longest simulation step, s (default 1); shorter ones are taken when the flow needs them. */
  vtkSetMacro(MaxTimeStep, double);
  vtkGetMacro(MaxTimeStep, double);
  ///@}

  ///@{
  /** Courant number of the adaptive step, (0, 1] (default 0.7). */
  vtkSetMacro(CourantNumber, double);
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
  int AdvanceState(double seconds) override;
  int FillOutput(vtkImageData *output, const int extent[6]) override;
  void ReleaseState() override;

  double RainRate = 10.0;
  double Permeability = 0.0;
  double ManningN = 0.03;
  int Boundary = OPEN;
  double MaxTimeStep = 1.0;
  double CourantNumber = 0.7;

private:
  vtkRainRunoffFilter(const vtkRainRunoffFilter &) = delete;
  void operator=(const vtkRainRunoffFilter &) = delete;

  gr_rain_runoff *Simulation = nullptr;
  int GridDimensions[2] = {0, 0};
};

#endif
