/**
 * @class   vtkSnowAccumulationFilter
 * @brief   Snowfall from a direction onto terrain and objects (seed 002:
 *          occlusion-based accumulation), stepped on OpenCL.
 *
 * Input 0 (`Input`) is the terrain: a 2-D vtkImageData with the point array
 * `elevation` (m) and, optionally, `snow_depth` (m), the snow at time 0.
 *
 * Input 1 (`Objects`, optional) is triangle meshes (vtkPolyData, whose
 * polygons and strips are split into triangles here; open surfaces such as
 * a roof are fine) or a multiblock of them, one object per non-empty leaf.
 * They shadow the terrain and each other and keep their own snow on their
 * faces (each triangle exposed, growing and shedding with its own normal),
 * shown as one depth per point of the polydata (so the output's point
 * arrays match the input's points): the mean of the point's faces weighted
 * by the area each turns to the sky. Polygons wound counter-clockwise seen from outside (VTK's
 * sources are) receive snow on their outer side. Each object is handed to
 * the core in its own frame, about the centre of its bounds, with a pose
 * that puts it in the world.
 * - Objects that do not advertise time steps stand still, or move by the
 *   properties (vtkGraupelMotion): the centre moves at ObjectVelocity (m/s)
 *   and the object turns at ObjectAngularVelocity (deg/s) about
 *   RotationAxis through its centre; with a Path (input 2, a polyline) the
 *   centre follows the path at the speed |ObjectVelocity|, the object's +x
 *   turned along the path's tangent. A leaf's field data `velocity` (3
 *   values, m/s) replaces ObjectVelocity for that object. Their snow moves
 *   with them.
 * - Objects that advertise time steps are read at each (sample and hold,
 *   see vtkGraupelSimulation): their geometry is the pose. An object keeps
 *   its snow from one time step to the next while it keeps its number of
 *   points.
 *
 * Time: every interval between the simulation's knots (output times, the
 * objects' time steps) is stepped in TimeStep-sized steps, the last one
 * shortened to end on the knot; each step takes the objects at their pose at
 * the step's end. A request without a time (a consumer that reads this
 * output once, such as Snow Deformation's Input) gets the last output,
 * EndTime: the snow that has fallen, not the bare ground of time 0.
 *
 * Output 0 has the terrain's geometry and the point arrays `snow_depth` (m,
 * active scalars), `snow_surface` (m), `snow_density` (kg/m^3: SnowDensity),
 * `exposure` (0 or 1, the last step's) and `elevation`, the arrays Snow
 * Deformation reads; field data `time` (s), `steps`, `initial_volume`,
 * `snowfall_volume`, `stored_volume`, `stored_volume_terrain`,
 * `stored_volume_objects`, `shed_volume`, `dropped_volume` (m^3) and
 * `balance_error` (m^3: initial + snowfall - shed - dropped - stored).
 * Output 1 is the objects at their pose at the output time (vtkPolyData, or
 * a multiblock of the same structure as the input) with the point arrays
 * `snow_depth` (m, along the faces' normals) and `snow_offset` (3
 * components, m: the faces' mean world normal times the depth, for Warp By
 * Vector).
 * Output 2, Textures, is a multiblock with one vtkImageData per object:
 * for an object whose polydata has texture coordinates (its point data's
 * TCoords), its accumulation texture (the thesis' per-object texture:
 * AccumulationTextureSize x AccumulationTextureSize texels spanning UV
 * [0, 1]^2, origin and spacing in UV units, point array `snow_depth` in m,
 * 0 on texels no triangle covers); an empty image for the others, or for
 * all with AccumulationTextureSize 0. See
 * gr_snow_accumulation_set_object_texture: the texels are samples on the
 * surface stepped like the faces, a finer picture of the same snow
 * kept out of the ledger.
 *
 * Time defaults (SetTimeDefaults): EndTime 6 h (21600 s), OutputInterval
 * 15 min (900 s), in TimeSteps of 5 min: a snowfall of a few hours.
 *
 * MPI (pvbatch, pvserver): each rank simulates its strip of the grid with
 * the core's ring of BlurRadius + 2 rows (gr_snow_accumulation_ghost; see
 * vtkGraupelSimulation, "Distributed runs"); every rank keeps every object,
 * the core combines the ranks' exposure views and ledger rows over the
 * ranks, and every rank's snow, objects and ledger are the whole grid's,
 * bit for bit. Field data `piece_cells` gives the grid points the rank
 * simulated, ring included; outputs 1 and 2 come on piece 0 only.
 *
 * The model is described in kernels/include/graupel/snow_accumulation.h;
 * the setters clamp to its parameter table
 * (gr_snow_accumulation_param_bounds).
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
