/**
 * @class   vtkSnowAccumulationFilter
 * @brief   Snowfall from a direction onto terrain and objects (seed 002:
 *          occlusion-based accumulation), stepped on OpenCL.
 *
 * Input 0 is the terrain (a 2-D image with `elevation`, m, and optionally
 * the `snow_depth` at time 0); input 1 optional Objects (triangle meshes or
 * a multiblock of them, open surfaces such as a roof included, standing
 * still, moving with ObjectVelocity or along a Path, or following their own
 * time steps); input 2 an optional Path. Output 0 is the terrain's grid with
 * the snow (`snow_depth`, `snow_surface`, `exposure`, ...) and the ledger;
 * output 1 the objects at their pose with the snow kept on their faces.
 * Snow Deformation chains onto output 0. The page docs/SnowAccumulation.md
 * gives every array, property and unit; the model and its departures from
 * the seed are the core's header, kernels/include/graupel/snow_accumulation.h.
 *
 * Time, checkpoints, temporal objects, aborts and MPI pieces are
 * vtkGraupelSimulation's and vtkGraupelObjectsSimulation's. The setters clamp
 * to the core's parameter table; values it refuses give one sentence at the
 * next update.
 */
#ifndef vtkSnowAccumulationFilter_h
#define vtkSnowAccumulationFilter_h

#include "GraupelFiltersModule.h"
#include "vtkGraupelObjectsSimulation.h"

#include <vector>

struct gr_snow_accumulation;
class vtkDataObject;
class vtkMultiBlockDataSet;

class GRAUPELFILTERS_EXPORT vtkSnowAccumulationFilter : public vtkGraupelObjectsSimulation {
public:
  static vtkSnowAccumulationFilter *New();
  vtkTypeMacro(vtkSnowAccumulationFilter, vtkGraupelObjectsSimulation);
  void PrintSelf(ostream &os, vtkIndent indent) override;

  ///@{
  /** Length of one simulation step, s (default 300; from 1e-6 to 86400). */
  virtual void SetTimeStep(double value);
  vtkGetMacro(TimeStep, double);
  ///@}

  ///@{
  /**
   * The direction the snow falls, any length (default 0 0 -1); wind tilts
   * it, at most 75 degrees from straight down.
   */
  vtkSetVector3Macro(SnowDirection, double);
  vtkGetVector3Macro(SnowDirection, double);
  ///@}

  ///@{
  /** The largest random turn of the direction per step, deg (default 0). */
  virtual void SetFlutter(double value);
  vtkGetMacro(Flutter, double);
  ///@}

  ///@{
  /** Fresh snow per hour on an exposed surface facing the snow, cm/h (default 2). */
  virtual void SetSnowfallRate(double value);
  vtkGetMacro(SnowfallRate, double);
  ///@}

  ///@{
  /** A of the growth's noise modulation (1 + A N), 0 to 1 (default 0.2). */
  virtual void SetNoiseAmplitude(double value);
  vtkGetMacro(NoiseAmplitude, double);
  ///@}

  ///@{
  /** The noise lattice, m (default 1). */
  virtual void SetNoiseScale(double value);
  vtkGetMacro(NoiseScale, double);
  ///@}

  ///@{
  /** Seed of the noise and of the flutter (default 0). */
  virtual void SetSeed(int value);
  vtkGetMacro(Seed, int);
  ///@}

  ///@{
  /** Texels across the exposure view (default 1024). */
  virtual void SetExposureResolution(int value);
  vtkGetMacro(ExposureResolution, int);
  ///@}

  ///@{
  /** Radius of the growth's blur, grid points (default 1; 0: none). */
  virtual void SetBlurRadius(int value);
  vtkGetMacro(BlurRadius, int);
  ///@}

  ///@{
  /** 1: the growth is dilated over 3 x 3 points (the thesis' dilation); default 0. */
  virtual void SetDilation(int value);
  vtkGetMacro(Dilation, int);
  vtkBooleanMacro(Dilation, int);
  ///@}

  ///@{
  /** Capacity of a horizontal surface, m (default 1): MaxDepth cos(slope) on a slope. */
  virtual void SetMaxDepth(double value);
  vtkGetMacro(MaxDepth, double);
  ///@}

  ///@{
  /** Fraction of the excess over the capacity shed per second, 0 to 1 (default 1). */
  virtual void SetStabilityFactor(double value);
  vtkGetMacro(StabilityFactor, double);
  ///@}

  ///@{
  /** Density of the fresh snow, kg/m^3 (default 100), written as `snow_density`. */
  virtual void SetSnowDensity(double value);
  vtkGetMacro(SnowDensity, double);
  ///@}

  ///@{
  /** Texels across each textured object's accumulation texture (default 256; 0: none). */
  virtual void SetAccumulationTextureSize(int value);
  vtkGetMacro(AccumulationTextureSize, int);
  ///@}

  /** A request without a time gets the last output (see the .cxx); the base does the rest. */
  vtkTypeBool ProcessRequest(vtkInformation *request, vtkInformationVector **inInfo,
                             vtkInformationVector *outInfo) override;

protected:
  vtkSnowAccumulationFilter();
  ~vtkSnowAccumulationFilter() override;

  int FillOutputPortInformation(int port, vtkInformation *info) override;

  int RequestInformation(vtkInformation *, vtkInformationVector **,
                         vtkInformationVector *) override;

  int SetUpState(vtkInformationVector **inputVector) override;
  int ResetState() override;
  int AdvanceState(double t0, double t1) override;
  int FillOutput(vtkDataObject *output, vtkInformation *outInfo) override;
  void ReleaseState() override;
  int SaveState(std::vector<unsigned char> &bytes) override;
  int LoadState(const std::vector<unsigned char> &bytes) override;
  const char *GetSimulationLabel() override { return "Snow Accumulation"; }

  double TimeStep = 300.0;
  double SnowDirection[3] = {0.0, 0.0, -1.0};
  double Flutter = 0.0; // the table's defaults, set in the constructor
  double SnowfallRate = 0.0;
  double NoiseAmplitude = 0.0;
  double NoiseScale = 0.0;
  int Seed = 0;
  int ExposureResolution = 0;
  int BlurRadius = 0;
  int Dilation = 0;
  double MaxDepth = 0.0;
  double StabilityFactor = 0.0;
  double SnowDensity = 0.0;
  int AccumulationTextureSize = 0;

private:
  vtkSnowAccumulationFilter(const vtkSnowAccumulationFilter &) = delete;
  void operator=(const vtkSnowAccumulationFilter &) = delete;

  int CheckParameters();
  /** Whether any object moves by the properties (poses change between steps). */
  bool ObjectsMove() const;
  /** Hands the objects at their poses at time t to the core. */
  int SetObjects(double t);
  /** Output 1: FillObjects; output 2: FillTextures. */
  int FillObjectOutput(int port, vtkDataObject *output, double t) override;
  /** The objects at their poses at time t with their snow per point. */
  int FillObjects(vtkDataObject *output, double t);
  /** One image per object, its accumulation texture or empty. */
  int FillTextures(vtkMultiBlockDataSet *output);

  gr_snow_accumulation *Simulation = nullptr;
};

#endif
