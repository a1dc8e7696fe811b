/**
 * @class   vtkRainRunoffFilter
 * @brief   Rain on a terrain: rain gain, infiltration, runoff and pooling
 *          (seed 004's water simulation), stepped on OpenCL.
 *
 * Input 0 is the terrain (a 2-D image with the point array `elevation`, m,
 * and optionally the water, its velocity and a `rain_rate` map at time 0),
 * input 1 an optional PermeabilityMap (`permeability`, `manning_n`), input 2
 * optional Gauges (points), input 3 optional Inflows (points with a
 * `discharge`, static or temporal). Output 0 is the terrain's grid with the
 * water (`water_depth`, `water_surface`, `velocity`, `discharge`,
 * `infiltrated`), the flood maps and the ledger as field data; output 1 the
 * Hydrograph, a table with a row per output time (rank 0's in an MPI run).
 * The page docs/RainRunoff.md gives every array, property and unit; the
 * model, its departures from the seed and its conservation are the core's
 * header, kernels/include/graupel/rain_runoff.h.
 *
 * Time, checkpoints, temporal inputs, aborts and MPI pieces are
 * vtkGraupelSimulation's (request a time with UpdateTimeStep). The setters
 * clamp to the core's parameter table (gr_rain_runoff_param_bounds, in the
 * user's units); a value that is not a number, or at the open end of a
 * range, is refused at the next update with one sentence.
 */
#ifndef vtkRainRunoffFilter_h
#define vtkRainRunoffFilter_h

#include "GraupelFiltersModule.h"
#include "vtkGraupelSimulation.h"

#include <array>
#include <vector>

struct gr_rain_runoff;
class vtkImageData;
class vtkPointSet;

class GRAUPELFILTERS_EXPORT vtkRainRunoffFilter : public vtkGraupelSimulation {
public:
  static vtkRainRunoffFilter *New();
  vtkTypeMacro(vtkRainRunoffFilter, vtkGraupelSimulation);
  void PrintSelf(ostream &os, vtkIndent indent) override;

  enum Boundaries { OPEN = 0, CLOSED = 1, TRANSMISSIVE = 2, LEVEL = 3 };
  enum FlowModels { SHALLOW_WATER = 0, LOCAL_INERTIAL = 1 };
  enum RainFramesKinds { FRAME_FROM_ITS_TIME = 0, FRAME_OVER_INTERVAL_BEFORE = 1 };

  ///@{
  /** Rain intensity, mm/h (default 100: a cloudburst that shows on real terrain in 600 s). */
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
  /**
   * The kind of each edge of the terrain (west: lowest x, east: highest x,
   * south: lowest y, north: highest y): 0 open, a free outfall (default);
   * 1 closed, a wall; 2 transmissive, the edge's depth, velocity and bed
   * slope continue (uniform flow leaves at its normal depth); 3 level, the
   * water surface beyond the edge stands at the edge's Level (m).
   */
  virtual void SetBoundaryWest(int value);
  vtkGetMacro(BoundaryWest, int);
  virtual void SetBoundaryEast(int value);
  vtkGetMacro(BoundaryEast, int);
  virtual void SetBoundarySouth(int value);
  vtkGetMacro(BoundarySouth, int);
  virtual void SetBoundaryNorth(int value);
  vtkGetMacro(BoundaryNorth, int);
  ///@}

  ///@{
  /** The water level beyond an edge of kind LEVEL, m, as the elevations (default 0). */
  virtual void SetLevelWest(double value);
  vtkGetMacro(LevelWest, double);
  virtual void SetLevelEast(double value);
  vtkGetMacro(LevelEast, double);
  virtual void SetLevelSouth(double value);
  vtkGetMacro(LevelSouth, double);
  virtual void SetLevelNorth(double value);
  vtkGetMacro(LevelNorth, double);
  ///@}

  ///@{
  /** What no-data points (NaN elevations) are: 1 closed, walls (default); 0
   *  open, outfalls that water pours into and leaves by. Their outputs are NaN. */
  virtual void SetNoDataBoundary(int value);
  vtkGetMacro(NoDataBoundary, int);
  ///@}

  ///@{
  /** Every edge the same kind (the single Boundary of earlier versions);
   *  GetBoundary: the common kind, or -1 when the edges differ. */
  void SetBoundary(int value);
  int GetBoundary();
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

  ///@{
  /** Depth above which a point is wet for arrival_time and wet_duration, m (default 0.01). */
  virtual void SetWettingDepth(double value);
  vtkGetMacro(WettingDepth, double);
  ///@}

  ///@{
  /** FD2321's debris factor, added to the hazard rating where the depth exceeds 0.25 m (default 0).
   */
  virtual void SetDebrisFactor(double value);
  vtkGetMacro(DebrisFactor, double);
  ///@}

  ///@{
  /**
   * With FollowInputTime, over which simulated times each frame's
   * `rain_rate` (a time step of the Input) rains. 0 (default), from its
   * time on: the frame at t_k over [t_k, t_k+1) (sample and hold, radar
   * frames). 1, over the interval before it: the frame at t_k over
   * (t_k-1, t_k], for rates that are a mean over the interval ending at
   * their time (Snow Melt's water release). Either way the first frame
   * rains before the first time and the last after the last.
   */
  void SetRainFrames(int value);
  vtkGetMacro(RainFrames, int);
  ///@}

  /** Connects the optional permeability map (input port 1). */
  void SetPermeabilityMapConnection(vtkAlgorithmOutput *output);
  /** Connects the optional gauge points (input port 2). */
  void SetGaugesConnection(vtkAlgorithmOutput *output);
  /** Connects the optional point inflows (input port 3, point array `discharge` in m^3/s). */
  void SetInflowsConnection(vtkAlgorithmOutput *output);

  ///@{
  /**
   * The inflow hydrograph along an edge: Add appends a row (time s,
   * discharge m^3/s), RemoveAll clears it (no inflow, the default). Times
   * must increase from row to row and discharges lie between 0 and 1e6
   * m^3/s, or the next update is refused with a sentence naming the row.
   */
  void AddInflowWest(double time, double discharge);
  void RemoveAllInflowWest();
  void AddInflowEast(double time, double discharge);
  void RemoveAllInflowEast();
  void AddInflowSouth(double time, double discharge);
  void RemoveAllInflowSouth();
  void AddInflowNorth(double time, double discharge);
  void RemoveAllInflowNorth();
  /** The rows of edge `side` (0 west, 1 east, 2 south, 3 north). */
  int GetNumberOfInflowRows(int side);
  ///@}

  ///@{
  /**
   * The hyetograph: rain over time, rows of (time s, rain rate mm/h), linear
   * in between, the first rate before the first time and the last after the
   * last; while it has rows it rains in place of RainRate (a rain_rate array
   * on the Input still wins). Times must increase from row to row and rates
   * lie within RainRate's range, or the next update is refused with a
   * sentence naming the row.
   */
  void AddHyetograph(double time, double rate);
  void RemoveAllHyetograph();
  int GetNumberOfHyetographRows();
  ///@}

protected:
  vtkRainRunoffFilter();
  ~vtkRainRunoffFilter() override;

  int FillInputPortInformation(int port, vtkInformation *info) override;
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
  const char *GetSimulationLabel() override { return "Rain Runoff"; }

  double RainRate = 100.0;
  double Permeability = 0.0;
  double ManningN = 0.03;
  int BoundaryWest = OPEN;
  int BoundaryEast = OPEN;
  int BoundarySouth = OPEN;
  int BoundaryNorth = OPEN;
  double LevelWest = 0.0;
  double LevelEast = 0.0;
  double LevelSouth = 0.0;
  double LevelNorth = 0.0;
  int NoDataBoundary = CLOSED;
  int FlowModel = SHALLOW_WATER;
  double MaxTimeStep = 3600.0; /* no cap: the stability limit sets the step */
  double CourantNumber = 0.7;
  double WettingDepth = 0.01;
  double DebrisFactor = 0.0;
  int RainFrames = FRAME_FROM_ITS_TIME;

private:
  vtkRainRunoffFilter(const vtkRainRunoffFilter &) = delete;
  void operator=(const vtkRainRunoffFilter &) = delete;

  /** 0 with one sentence in the user's unit when a property is out of its range. */
  int CheckParameters();

  // SetUpState's parts, each 0 after one sentence: the input fields and the
  // Manning map, validated; the properties as the core's parameters; the
  // gauges at their terrain points; the core with its pieces and inputs;
  // the hyetograph and the edges' inflow hydrographs.
  struct Upload;
  struct Inputs;
  int CollectInputs(vtkImageData *terrain, vtkImageData *map, vtkDataArray *elevation, Inputs &in);
  int CoreParams(struct gr_rain_runoff_params *p);
  int SnapGauges(vtkImageData *terrain, vtkPointSet *gauges);
  int CreateCore(vtkImageData *terrain, const struct gr_rain_runoff_params &p, const Inputs &in);
  int SetTimeSeries();

  /** Records the ledger as the hydrograph's row `index`; 0 with the core's sentence. */
  int RecordLedger(int index);
  /** Fills the hydrograph table with rows 0 to the state's output index. */
  int FillHydrograph(vtkDataObject *table);
  /** Adds the flood maps to the image output, on its extent. */
  int AddMaps(vtkDataObject *output);

  /**
   * Refuses (one sentence, 0) a terrain whose simulation would not fit in
   * memory, with the optional inputs it has: before anything is copied.
   */
  int CheckStateMemory(vtkImageData *terrain, vtkImageData *map,
                       vtkInformationVector **inputVector);
  /** Gives the core the Inflows points (snapped to the terrain; none: nothing); 0 with a sentence.
   */
  int SetPointInflows(vtkPointSet *points, vtkImageData *terrain);
  /** The Inflows input's time step the core's point inflows came from (NaN: set them again). */
  double InflowsReadAt = 0.0;
  /**
   * With FollowInputTime, the Input's `rain_rate` of its time step now, to
   * the core (nothing when the Input has none); 0 with a sentence.
   */
  int SetRainFromInput(vtkImageData *terrain);
  /** The Input's time step the core's rain field came from (NaN: set it again). */
  double RainReadAt = 0.0;
  /** Whether the set-up's Input had a rain_rate (then every time step must have one). */
  bool RainFollowed = false;
  void AddInflow(int side, double time, double discharge);
  void RemoveAllInflow(int side);

  gr_rain_runoff *Simulation = nullptr;
  /** Per edge (west, east, south, north) the hydrograph's times and discharges. */
  std::vector<double> InflowTimes[4], InflowDischarges[4];
  /** The hyetograph's times (s) and rain rates (mm/h). */
  std::vector<double> HyetographTimes, HyetographRates;
  /** The ledger's volumes at each output time passed: time, rain, infiltrated,
   *  outflow, stored, balance error, inflow. */
  std::vector<std::array<double, 7>> Ledgers;
  /** The gauges' grid points, (i, j) pairs, and per output time their depth,
   *  surface and discharge (3 floats per gauge). */
  std::vector<int> GaugeCells;
  std::vector<std::vector<float>> GaugeRows;
};

#endif
