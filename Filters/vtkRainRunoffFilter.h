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
 * Flood maps (point arrays of output 0, cumulative since time 0, the core's
 * gr_rain_runoff_get_map, documented in rain_runoff.h): `max_depth` (m),
 * `max_speed` (m/s), `arrival_time` (s, NaN where the depth never exceeded
 * WettingDepth), `wet_duration` (s), `hazard_rating` (the largest UK
 * Defra/EA FD2321 rating h (v + 0.5) + DF, DF = DebrisFactor where h > 0.25
 * m) and `hazard_class` (0 low, 1 moderate, 2 significant, 3 extreme).
 * They live in the core's checkpointed state, so they are the same
 * whatever the order in which times are requested.
 *
 * Output 1 (`Hydrograph`) is a vtkTable with one row per output time up to
 * the requested one: `time` (s), `rain_volume_rate`, `inflow_rate`,
 * `infiltration_rate` and `outflow_rate` (m^3/s over the domain: row k's is
 * the mean over the output interval that ends at its time, the ledger's
 * volume difference over the interval, so rate times interval sums to the
 * ledger's volume exactly; row 0's rates are NaN: no interval ends there),
 * `stored_volume`,
 * `outflow_volume` and `balance_error` (m^3, the ledger at that time).
 * inflow_rate is what enters through the edges (level boundaries). Every row is the ledger
 * recorded when the state passed that output time; a checkpoint restored
 * or a restart re-records the same values (the steps are the same), so the
 * table does not depend on the order of requests either.
 *
 * Input 2 (`Gauges`, optional) is a point set: each point is snapped to the
 * nearest terrain point (a point beyond the terrain is refused with a
 * sentence), and the hydrograph gets three columns per gauge k,
 * `gauge<k>_depth` (m), `gauge<k>_surface` (m) and `gauge<k>_discharge`
 * (m^2/s, |q|), the output fields' values there at each output time (read
 * with gr_rain_runoff_sample: a few floats per output, whatever the grid).
 * Gauges are a static input: moving them sets the simulation up again.
 *
 * Inflows: Input 3 (`Inflows`, optional) is a point set with the point
 * array `discharge` (m^3/s, 0 to 1e6; a temporal input's time steps each
 * hold until the next, read while stepping): each point is snapped to the nearest terrain point and
 * lets that much water in there (a river, a culvert; points on one terrain point add up); a point
 * off the terrain or a bad discharge is refused with a sentence. And per edge an inflow hydrograph
 * (InflowWest ... InflowNorth): rows of time (s) and discharge (m^3/s), times strictly increasing,
 * linear in between, held before the first and after the last row, spread evenly along the edge.
 * Both count as the ledger's inflow_volume.
 *
 * MPI (pvbatch, pvserver): each rank simulates its strip of the grid with
 * the core's ring (GR_RAIN_RUNOFF_GHOST rows for the local inertial model,
 * GR_RAIN_RUNOFF_GHOST_SW for shallow water; see vtkGraupelSimulation,
 * "Distributed runs"): every input array goes up as the strip's rows and
 * ring, point inflows and gauges keep the whole grid's points (a gauge is
 * read by the rank that owns its row and shared with the others), the core
 * reduces the stable step and the ledger over the ranks, so every rank's
 * field data and hydrograph are the whole grid's, bit for bit, and the flood
 * maps come per piece like the fields. Field data `piece_cells` gives the
 * grid points the rank simulated, ring included.
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

private:
  vtkRainRunoffFilter(const vtkRainRunoffFilter &) = delete;
  void operator=(const vtkRainRunoffFilter &) = delete;

  /** 0 with one sentence in the user's unit when a property is out of its range. */
  int CheckParameters();

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
