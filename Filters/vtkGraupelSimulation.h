/**
 * @class   vtkGraupelSimulation
 * @brief   Base of every Graupel filter that steps a simulation through time.
 *
 * A simulation filter is a time source (TIME_STEPS 0, OutputInterval, ...,
 * EndTime) whose state stays on the device between updates: a later time
 * advances it, an earlier one restores the nearest checkpoint kept on the
 * host (or starts again from time 0), and a changed property or static
 * input sets it up again. Temporal inputs (moving objects, rain frames) are
 * read at the simulated time, one input time step per pipeline pass, held
 * until the next; the result at a time never depends on the order in which
 * times were asked. It also writes and reads checkpoint files
 * (CheckpointFile, RestartFile), reports progress and honours an abort,
 * reports errors once, and splits the grid into strips over MPI ranks.
 *
 * A subclass implements the hooks below (SetUpState, ResetState,
 * AdvanceState, FillOutput, SaveState, LoadState): they translate between
 * VTK data and a core, they do not compute. The rules each part follows
 * (the knots an advance stops at, the checkpoint ring and files, the abort
 * protocol, the piece contract) are in Filters/README.md; what a user sees
 * is in docs/Simulations.md.
 */
#ifndef vtkGraupelSimulation_h
#define vtkGraupelSimulation_h

#include "GraupelFiltersModule.h"
#include "vtkGraupelAlgorithm.h" // GRAUPEL_VTK_ABORT_OUTPUT

#include <deque>
#include <functional>
#include <string>
#include <vector>

class vtkDataArray;
class vtkImageData;
namespace graupel {
class Pieces;
}

struct gr_grid;
struct gr_memory_need;
class GRAUPELFILTERS_EXPORT vtkGraupelSimulation : public vtkGraupelAlgorithm {
public:
  vtkTypeMacro(vtkGraupelSimulation, vtkGraupelAlgorithm);
  void PrintSelf(ostream &os, vtkIndent indent) override;

  /** The most output times a simulation advertises. */
  static constexpr int MaximumOutputSteps = 100000;

  /** Input port policies (see "Inputs in time" in Filters/README.md). */
  enum InputPolicy { STATIC_INPUT = 0, TEMPORAL_INPUT = 1 };

  /**
   * Over which simulated times a temporal input's time step tau_k holds
   * (see "Inputs in time" in Filters/README.md): HOLD_FROM_TIME, [tau_k,
   * tau_k+1), sample and hold, the default; HOLD_INTERVAL_BEFORE, (tau_k-1,
   * tau_k], for data that are a mean over the interval before their time
   * (an upstream simulation's rate between its outputs). Either way the
   * first step holds before the first time and the last after the last.
   */
  enum InputFrameHold { HOLD_FROM_TIME = 0, HOLD_INTERVAL_BEFORE = 1 };

  ///@{
  /** Simulated time at the last output, seconds (default 600). */
  vtkSetMacro(EndTime, double);
  vtkGetMacro(EndTime, double);
  ///@}

  ///@{
  /** Simulated time between outputs, seconds (default 10). */
  vtkSetMacro(OutputInterval, double);
  vtkGetMacro(OutputInterval, double);
  ///@}

  ///@{
  /**
   * The time at which a static input that has times of its own (another
   * simulation's output: the snow of a Snow Accumulation, the water of a
   * Rain Runoff) is read, seconds of that input's time; negative (the
   * default, -1): its last time, the upstream's EndTime. Whatever time this
   * simulation is asked for and whatever was updated before: two
   * simulations on their own time axes (hours of snowfall, seconds of a
   * vehicle) chain end to start.
   */
  vtkSetMacro(InputTime, double);
  vtkGetMacro(InputTime, double);
  ///@}

  ///@{
  /**
   * 1: the Input (port 0) follows the simulated time instead: read at each
   * of its time steps while stepping (sample and hold; Water Surface's
   * ripples on Rain Runoff's changing water). 0 (default): read once, at
   * InputTime.
   */
  vtkSetClampMacro(FollowInputTime, int, 0, 1);
  vtkGetMacro(FollowInputTime, int);
  vtkBooleanMacro(FollowInputTime, int);
  ///@}

  ///@{
  /**
   * The EndTime and OutputInterval a new object of this class starts with,
   * seconds: a simulation whose time scale differs sets its own in its
   * constructor (SetTimeDefaults). ParaView's EndTime and OutputInterval
   * (Plugin/GraupelBase.xml, shared by every simulation) take their defaults
   * from these, so each class's defaults are stated once, here in C++.
   */
  vtkGetMacro(DefaultEndTime, double);
  vtkGetMacro(DefaultOutputInterval, double);
  ///@}

  ///@{
  /** A checkpoint every this many outputs (default 10; 0: none). */
  virtual void SetCheckpointInterval(int value);
  vtkGetMacro(CheckpointInterval, int);
  ///@}

  ///@{
  /**
   * Most host memory the checkpoints may hold, MiB (default 1024); a quarter
   * of the host's physical memory applies when that is less.
   */
  virtual void SetCheckpointMemoryLimit(double value);
  vtkGetMacro(CheckpointMemoryLimit, double);
  ///@}

  ///@{
  /**
   * A checkpoint on disk (see "Checkpoint files" in Filters/README.md): while
   * set, every update writes the state it outputs to this manifest (JSON)
   * and one .vti per rank beside it, replacing what was there. Setting it
   * does not set the simulation up again. Empty (the default): nothing is
   * written.
   */
  virtual void SetCheckpointFile(const char *path);

  /**
   * The Height Array (input array 0) as vtkAlgorithm's; setting one that
   * means the same heights (ParaView fills in the association of the
   * default, elevation, after the first update) keeps the state.
   */
  using Superclass::SetInputArrayToProcess;
  void SetInputArrayToProcess(int idx, int port, int connection, int fieldAssociation,
                              const char *name) override;
  void SetInputArrayToProcess(int idx, int port, int connection, const char *fieldAssociation,
                              const char *name) override;
  void SetInputArrayToProcess(int idx, vtkInformation *info) override;
  vtkGetStringMacro(CheckpointFile);
  ///@}

  ///@{
  /**
   * A manifest written through CheckpointFile to start from: the next set-up
   * loads each rank's piece of it and goes on from its time, bit for bit as
   * the run that wrote it went on. Needs the same inputs, properties, output
   * times and number of ranks as that run; a manifest that does not fit is
   * refused with a sentence and an empty output. Empty (the default): start
   * at time 0.
   */
  vtkSetStringMacro(RestartFile);
  vtkGetStringMacro(RestartFile);
  ///@}

  /** How many checkpoints this rank wrote to CheckpointFile (its piece, and the manifest on rank
   * 0). */
  vtkGetMacro(CheckpointFileCount, int);
  /** The output index the state was loaded at from RestartFile at the last set-up; -1 if none. */
  vtkGetMacro(RestartIndex, int);

  /** The limit in force, bytes: CheckpointMemoryLimit capped by physical memory. */
  vtkTypeInt64 GetCheckpointMemoryLimitBytes() const;

  /** Number of output times: intervals up to EndTime, plus time 0. */
  int GetNumberOfOutputTimes() const;
  /** Output time k (0 <= k < GetNumberOfOutputTimes()), seconds. */
  double GetOutputTime(int k) const;
  /** Whether t (s) is one of the output times (an AdvanceState's t0 or t1 may be). */
  bool IsOutputTime(double t) const;

  /** Output index at or before the state kept on the device; -1 when there is none. */
  vtkGetMacro(StateIndex, int);
  /** Absolute time of the state kept on the device, s (meaningful when StateIndex >= 0). */
  vtkGetMacro(StateTime, double);
  /** How many times the state was set up or went back to time 0. */
  vtkGetMacro(RestartCount, int);
  /** How many times a checkpoint was restored. */
  vtkGetMacro(RestoreCount, int);
  /** How many pipeline passes were taken for temporal inputs (beyond one per update). */
  vtkGetMacro(ExtraPassCount, int);
  /** Checkpoints held now, and their bytes. */
  int GetNumberOfCheckpoints() const { return static_cast<int>(this->Checkpoints.size()); }
  vtkTypeInt64 GetCheckpointBytes() const;
  /** Output index of checkpoint i (0 <= i < GetNumberOfCheckpoints()), oldest first. */
  int GetCheckpointIndex(int i) const;

  /**
   * Seconds the last update spent in halo exchanges of a split run (part 0),
   * of which reading the strips from the device (1: this waits for the
   * step's kernels), the messages and the waiting for the neighbours (2) and
   * writing the rings (3); and how many exchanges. 0 when the run is not
   * split. For timing runs (Testing/Benchmarks/mpi_scaling.py).
   */
  double GetHaloExchangeSeconds(int part);
  long GetHaloExchangeCount() const;

  /** Whether input port is read in time now (policy TEMPORAL and >= 2 time steps). */
  bool IsInputTemporal(int port) const;

  /**
   * A request from an output other than 0 (objects, textures, a
   * hydrograph) asks for the simulation's time it names: output 0 gets it,
   * which the time logic reads.
   */
  vtkTypeBool ProcessRequest(vtkInformation *request, vtkInformationVector **inInfo,
                             vtkInformationVector *outInfo) override;

protected:
  vtkGraupelSimulation();
  ~vtkGraupelSimulation() override;

  /** Results of AdvanceState. */
  enum AdvanceResult { ADVANCE_FAILED = 0, ADVANCE_DONE = 1, ADVANCE_ABORTED = 2 };

  /** The time a static input with times of its own is read at (InputTime, else its last). */
  double StaticInputTime(vtkInformation *inInfo) const;

  /** Sets a port's policy (STATIC_INPUT by default); call in the constructor. */
  void SetInputPortPolicy(int port, int policy);

  /**
   * Sets a temporal port's InputFrameHold (HOLD_FROM_TIME by default): in
   * the constructor, or from a property's setter (the filter's MTime then
   * sets the simulation up again).
   */
  void SetInputFrameHold(int port, int hold);
  int GetInputFrameHold(int port) const;

  /** Sets EndTime and OutputInterval, the class's defaults; call in the constructor. */
  void SetTimeDefaults(double endTime, double outputInterval);

  /**
   * Validates the inputs and creates the device state at time 0. Reports
   * its own error (one sentence naming the input, array and fix) and
   * returns 0 on failure; nothing may be left half set up then. Temporal
   * inputs hold their data at some time step (GetTemporalInputTime).
   */
  virtual int SetUpState(vtkInformationVector **inputVector) = 0;
  /** Back to the time-0 state of the last set-up. 0 on failure. */
  virtual int ResetState() = 0;
  /**
   * Advances the state from absolute time t0 to t1 (seconds, t1 > t0),
   * reading temporal inputs with GetTemporalInput: their data holds over
   * the whole of [t0, t1]. ADVANCE_DONE, ADVANCE_FAILED (error reported) or
   * ADVANCE_ABORTED (the core stopped inside because CoreProgress asked).
   */
  virtual int AdvanceState(double t0, double t1) = 0;
  /**
   * Fills output (empty, of the port's type) with the current state;
   * outInfo holds the request (UPDATE_EXTENT, piece). 0 on failure.
   */
  virtual int FillOutput(vtkDataObject *output, vtkInformation *outInfo) = 0;

  /** The core's grid of a 2-D terrain image: its points, spacing and origin (a whole grid). */
  static void TerrainGrid(vtkImageData *terrain, gr_grid *grid);

  /** One float point array of FillImage: name, components, and its read. */
  struct ImageArray {
    std::string name;
    int components;
    // Reads the core's own points (the whole grid, or a split run's own
    // rows) into values; a gr_status.
    std::function<int(float *)> read;
  };

  /**
   * For a grid simulation's FillOutput (vtkGraupelSimulationImage.cxx):
   * gives output (an image) the terrain input's geometry, cropped to the
   * extent outInfo requests, and the arrays, each read from the core and in
   * a split run assembled into the requested rows; the first becomes the
   * active scalars; `piece_cells` when the core runs as pieces. A failed read
   * is reported with detail() (the core's own sentence); returns 0 then.
   */
  int FillImage(vtkDataObject *output, vtkInformation *outInfo,
                const std::vector<ImageArray> &arrays, const std::function<const char *()> &detail);
  /** The same for gr_field outputs, each read by read(field, values). */
  int FillImage(vtkDataObject *output, vtkInformation *outInfo, const int *fields, int count,
                const std::function<int(int, float *)> &read,
                const std::function<const char *()> &detail);
  /** Frees the device state; must accept being called without state. */
  virtual void ReleaseState() = 0;

  /**
   * The core's ring for a split run, grid points (its GHOST; 0, the
   * default: the simulation runs whole on every rank). Call in the
   * constructor, and again when the ring changes with a property.
   */
  void SetPieceRing(int ring) { this->PieceRing = ring; }
  int GetPieceRing() const { return this->PieceRing; }
  /** This update's layout (see "Distributed runs"); valid from SetUpState on. */
  graupel::Pieces &GetPieces() { return *this->PieceLayout; }

  ///@{
  /**
   * Checkpoint hooks: SaveState replaces bytes with the whole evolving
   * state; LoadState puts such bytes back, after which every step must be
   * bit-identical to those that followed the save. Return 1 on success; the
   * defaults return 0 (no checkpoints: going back restarts from time 0).
   */
  virtual int SaveState(std::vector<unsigned char> &bytes);
  virtual int LoadState(const std::vector<unsigned char> &bytes);
  ///@}

  /** The name progress and messages use ("Rain Runoff"); the class name by default. */
  virtual const char *GetSimulationLabel();

  /** A temporal input's data now (its data at GetTemporalInputTime), or a static input's. */
  vtkDataObject *GetTemporalInput(int port);
  /** The input time step GetTemporalInput holds, s. */
  double GetTemporalInputTime(int port) const;

  /**
   * Progress from inside AdvanceState at absolute time t (s): sets the
   * progress text and fraction; returns 1 when the user asked to abort.
   */
  int ReportProgress(double t);
  /** ReportProgress as a gr_progress_fn; user is the filter. */
  static int CoreProgress(void *user, double time);
  /**
   * CoreProgress for a core that reports every step (many a second): an
   * abort is seen at every step, the text and the event come at most every
   * 0.1 s of wall time.
   */
  static int ThrottledProgress(void *user, double time);

  /**
   * The steps of dt (s) from t0 to t1: at least one, the last shortened to
   * end on t1. Step k of n (1..n) ends at StepEnd, t0 + k dt (not a running
   * sum, so the ends depend on t0, t1 and dt only) and t1 for the last.
   */
  static long long CountSteps(double t0, double t1, double dt);
  static double StepEnd(double t0, double t1, double dt, long long k, long long n);

  /**
   * The terrain's `elevation` point array: refuses an input without it (one
   * sentence naming the array and the fix) and warns, once per terrain, when
   * the spacing is still 1 m while the heights span 100 m or more (a
   * forgotten Spacing). nullptr after the error.
   */
  vtkDataArray *GetElevation(vtkImageData *terrain, const char *inputName);
  // After a Height Array is set: keeps the state when it means the same heights.
  void KeepStateIfSameHeights(const std::string &before, vtkMTimeType was);

  /**
   * The terrain on the Input: refuses none, one that is not 2-D with at
   * least 2 x 2 points, or a spacing not above 0 (one sentence naming the
   * simulation, what it got and the fix). 0 after the error.
   */
  int CheckTerrain(vtkImageData *terrain);

  /**
   * For SetUpState, before it copies or allocates anything: refuses a
   * set-up that would not fit in memory with one sentence ("Rain Runoff: a
   * 20000 x 20000 grid needs 75.2 GB (188 bytes a point) but this process
   * can use 21.9 GB; ...") and returns 0; else 1. core is the core's need
   * (gr_<core>_memory) on grid, the piece this rank simulates (PieceGrid of
   * the terrain's grid); hostBytes is what the filter adds a point of that
   * piece: its output's fields, the uploads' float copies. A checkpoint's
   * copy of the state (core.state) is added when checkpoints are made.
   */
  int CheckMemory(const gr_grid &grid, const gr_memory_need &core, double hostBytes);

  /** Forgets the state, so the next update sets it up again. */
  void InvalidateState();

  int RequestInformation(vtkInformation *, vtkInformationVector **,
                         vtkInformationVector *) override;
  int RequestUpdateExtent(vtkInformation *, vtkInformationVector **,
                          vtkInformationVector *) override;
  int RequestData(vtkInformation *, vtkInformationVector **, vtkInformationVector *) override;

#if GRAUPEL_VTK_ABORT_OUTPUT
public:
  /** Without Modified(): see "Progress and abort" in Filters/README.md. */
  void SetAbortExecute(vtkTypeBool abort) override;
  /** Keeps the state: the executive resets it before every execution. */
  void SetAbortOutput(bool abort) override;
#endif

protected:
  double EndTime = 600.0;
  double OutputInterval = 10.0;
  double InputTime = -1.0;
  int FollowInputTime = 0;
  int CheckpointInterval = 10;
  double CheckpointMemoryLimit = 1024.0;

  /**
   * Outputs 1 and up: RequestData empties them before each pass and holds
   * the outputs here while it runs (nullptr otherwise), so that FillOutput
   * can fill them; it sets OutputsFilled when it did, and they then take
   * output 0's time. They advertise the simulation's times.
   */
  vtkInformationVector *OutputVector = nullptr;
  bool OutputsFilled = false;

private:
  vtkGraupelSimulation(const vtkGraupelSimulation &) = delete;
  void operator=(const vtkGraupelSimulation &) = delete;

  /** RequestInformation for output 0: the input times read, the output times advertised. */
  int AdvertiseTimes(vtkInformationVector **inputVector, vtkInformationVector *outputVector);
  /** RequestData for output 0: the state brought to the requested time and filled in. */
  int UpdateState(vtkInformation *request, vtkInformationVector **inputVector,
                  vtkInformationVector *outputVector);
  /**
   * UpdateState's first pass of a request: the failure seen before, the
   * times, the target output, a set-up (and restart file) when the key or
   * the pieces changed, the rewind to a checkpoint. 0 after one sentence.
   */
  int PlanRequest(vtkInformation *outInfo, vtkInformationVector **inputVector);
  enum { KNOT_READY, KNOT_WAIT, KNOT_FAILED };
  /**
   * The next knot after the state's time (the next output time or temporal
   * input time step): KNOT_READY with next set; KNOT_WAIT when a temporal
   * input must be read at another time first (another pass is asked for);
   * KNOT_FAILED after one sentence when an input did not honour that.
   */
  int NextKnot(vtkInformation *request, double &next);

  double DefaultEndTime = EndTime; // the base's, until SetTimeDefaults
  double DefaultOutputInterval = OutputInterval;

  /** What the state was built from: the filter's and its inputs' present values. */
  struct Key {
    vtkMTimeType filter = 0;
    std::vector<vtkMTimeType> inputs;
    std::vector<std::vector<double>> times;
    bool operator==(const Key &o) const {
      return filter == o.filter && inputs == o.inputs && times == o.times;
    }
  };
  struct Checkpoint {
    int index;
    std::vector<unsigned char> bytes;
  };

  int CheckTimes();
  Key CurrentKey();
  int TargetIndex(vtkInformation *outInfo) const;
  /** The time the next update for target starts stepping from. */
  double PlannedStart(int target) const;
  /**
   * Input time step of a temporal port that holds over the advance that
   * starts at time t (by its InputFrameHold: the last at or before t, or
   * the first after t).
   */
  double InputTimeAt(int port, double t) const;
  /** Goes to the best kept state for target: the state, a checkpoint or time 0. */
  int Rewind(int target);
  void KeepCheckpoint();
  /** Ends a request: no further pass. */
  void Finish(vtkInformation *request);
  /** Writes the state at the output index StateIndex to CheckpointFile; 0 after an error. */
  int WriteCheckpointFile(vtkDataObject *output);
  /** Puts the state of RestartFile in place after a set-up; 0 after an error. */
  int ReadRestartFile();

  std::vector<int> Policies;
  std::vector<int> FrameHolds;                 // per port: InputFrameHold
  std::vector<std::vector<double>> InputTimes; // per port; empty when static
  std::vector<double> DeliveredTime;           // per port: time asked of it this pass
  std::vector<double> PendingTime;             // per port: time to ask of it next pass
  int StateIndex = -1;
  double StateTime = 0.0;
  bool StateLost = false; // an abort inside AdvanceState left it between knots
  int RestartCount = 0;
  int RestoreCount = 0;
  int ExtraPassCount = 0;
  bool Continuing = false;
  int Target = 0;
  double LastProgressWall = 0.0; // s, steady clock: ThrottledProgress's last report
  Key StateKey;
  Key FailedKey;
  bool HasFailed = false;
  vtkMTimeType WarnedSpacingFor = 0;
  std::deque<Checkpoint> Checkpoints;
  int PieceRing = 0;
  graupel::Pieces *PieceLayout = nullptr;
  std::vector<int> StateLayout; // the layout the state was set up for
  char *CheckpointFile = nullptr;
  char *RestartFile = nullptr;
  int CheckpointFileCount = 0;
  int RestartIndex = -1;
  int WrittenIndex = -1; // output index last written to WrittenFile since the set-up
  std::string WrittenFile;
};

#endif
