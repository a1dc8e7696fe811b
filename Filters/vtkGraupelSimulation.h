/**
 * @class   vtkGraupelSimulation
 * @brief   Base of every Graupel filter that steps a simulation through time.
 *
 * A simulation filter is a time source: it advertises `TIME_STEPS` (0,
 * OutputInterval, 2 OutputInterval, ..., EndTime) and `TIME_RANGE` [0,
 * EndTime]. A requested time is snapped to the last output time at or
 * before it. The output may be any data type (an image for a grid core,
 * vtkPolyData for particles): the subclass declares it in
 * FillOutputPortInformation and fills it in FillOutput; the time logic here
 * never looks at it.
 *
 * **The state.** It stays on the device between updates, at an absolute
 * time. A request for a later time advances it; a request for an earlier
 * time goes back to the nearest kept checkpoint at or before that time (see
 * below), or to time 0 when there is none; a changed property or a changed
 * static input sets the simulation up again.
 *
 * **Inputs in time.** Each input port has a policy (SetInputPortPolicy):
 * - STATIC: read once (a terrain). An input with times of its own (another
 *   simulation's output) is read at InputTime, by default its last time;
 *   one without at no time. A change of its data sets the simulation up
 *   again. The Input (port 0) is static unless its class declares it
 *   temporal or FollowInputTime is on.
 * - TEMPORAL: read at the simulated time while stepping (a moving object,
 *   rain that varies). Its data at input time step tau_i holds from tau_i
 *   until the next input time step (sample and hold; before the first step
 *   the first holds). A temporal input that advertises fewer than 2 time
 *   steps is static. A change upstream of it (its pipeline MTime) or of its
 *   time steps sets the simulation up again; a new time of it does not.
 *
 * The simulation gets its temporal inputs through ParaView's own idiom for
 * filters that consume many input times, CONTINUE_EXECUTING (as
 * vtkTemporalStatistics does): one input time per pipeline pass.
 * RequestUpdateExtent asks each temporal input for the time step the state
 * needs next; RequestData advances the state up to the next input time step
 * or output time, whichever comes first, then asks the executive for
 * another pass until the requested output time is reached. Chosen over a
 * cache of the input's time steps because (a) memory stays one input time
 * step per port whatever the number of steps (a mesh sequence or rain maps
 * of hundreds of steps would not fit a cache), (b) the upstream pipeline
 * runs as ParaView expects (its own caching, progress and MPI pieces
 * apply), and (c) no filter calls Update() on its input from inside
 * RequestData, which breaks in client-server pipelines. The cost is one
 * upstream execution per input time step passed, paid again when going back
 * in time beyond a checkpoint.
 *
 * Every AdvanceState(t0, t1) call covers one piece between consecutive
 * "knots": output times and the temporal inputs' time steps. The knots
 * depend on properties and inputs only, so the calls made to reach a time
 * are the same whatever the order in which times were requested, and a
 * deterministic core gives the same bits (Testing/Cxx and
 * Testing/Python/test_rain_runoff.py check it).
 *
 * **Checkpoints.** Every CheckpointInterval (K, default 10) outputs, the
 * state is saved on the host through SaveState into a ring bounded by
 * CheckpointMemoryLimit (MiB, default 1024, never more than a quarter of the
 * host's physical memory): when a new snapshot would exceed it, the oldest
 * ones are dropped; a snapshot larger than the limit is not kept. Going
 * back restores the nearest snapshot at or before the requested time with
 * LoadState, so it re-steps at most K output intervals; going forward past
 * a snapshot that is ahead of the state uses it too. K = 10 keeps a
 * 60-output run (600 s at 10 s) to six snapshots and a replay to at most ten
 * intervals; a Rain Runoff snapshot is about 60 bytes per grid point (15 arrays with the flood
 * maps), so a 1024 x 1024 grid keeps 17 of them under 1 GiB. Snapshots are dropped when the
 * simulation is set up again. RestartCount counts set-ups and returns to time 0; RestoreCount
 * counts snapshot loads.
 *
 * **Checkpoint files.** With CheckpointFile set (a path ending in .json),
 * every update also writes the state it outputs: each rank writes
 * `<stem>.<output index>.<rank>.vti` beside the manifest, its output (the requested piece,
 * every array, viewable as it is) with the core's state as SaveState gives
 * it, byte for byte, in the field array `graupel_state` (an unsigned char
 * array; the .vti is written raw and zlib-compressed, which is lossless);
 * then rank 0 writes the manifest `<stem>.json`: the format, the
 * simulation's label, the output index, time and interval, the grid, the
 * number of ranks and whether they split the grid, and per rank its own
 * rows, its file and its state's bytes (plus `steps` where the output has
 * it). Each file is written under a temporary name, flushed and renamed,
 * the manifest last, and the pieces of earlier outputs are removed only
 * once it is in place: a kill at any moment leaves the previous checkpoint
 * or the new one whole. RestartFile names such a manifest: after the set-up each rank checks
 * it against this run (simulation, grid, ranks, its own rows, the output
 * time), reads its piece and loads the state (LoadState), so the run goes on
 * from that output time; the loaded state is also kept as a checkpoint, so
 * later times come from it and earlier ones from time 0. Every rank takes
 * the same decision (a piece that fails on one rank fails them all).
 *
 * **Progress and abort.** Progress text names what happens ("Rain Runoff:
 * t = 420 s of 1800 s", the second time being the requested one) and is
 * updated after every AdvanceState and, through CoreProgress, from inside a
 * core's long advance. An abort is honoured between AdvanceState calls and,
 * where the core supports it, inside one (CoreProgress returns nonzero when
 * GetAbortExecute()). An aborted update uses VTK's aborted-output protocol
 * rather than Modified(): RequestData consumes AbortExecute and sets
 * AbortOutput, so the executive empties the output, stamps it with the
 * requested time and marks the port ABORTED, and the next request executes
 * again although no parameter changed. An update that starts with
 * AbortExecute (or AbortOutput, from an aborted input) already set returns
 * that empty output at once. ParaView's Render asks for the data more than
 * once; in ParaView 5.11's GUI the plugin's pqGraupelAbortStarter sets
 * AbortExecute again whenever the aborted filter starts executing until
 * that Render ends, so the Render returns at once and the next one (a new
 * time, Apply) runs the simulation. An abort is execution state, not a
 * parameter: setting AbortExecute does not modify the filter, and setting
 * AbortOutput (whose vtkAlgorithm setter does) keeps the state. On VTK
 * without that protocol (9.1) the filter calls Modified() instead. After an
 * abort between calls the state is kept and the
 * next update goes on from it. After an abort inside a call the core stopped
 * at a step that is not a knot: going on from there would take other steps
 * than an uninterrupted run, so that state is dropped and the next update
 * restores the nearest checkpoint (or restarts), and results stay
 * bit-identical.
 *
 * **Errors** are reported once (see vtkGraupelAlgorithm): a failed set-up or
 * step gives one sentence and an empty output, and the same request is not
 * tried again (nor its sentence repeated) until a property or input changes.
 *
 * **Distributed runs.** A simulation whose core follows the piece/halo
 * contract declares its ring (SetPieceRing, the core's ghost width); in an
 * MPI run whose request is one piece per rank (pvbatch, pvserver) each rank
 * then simulates only its strip along y with that ring (graupel::Pieces,
 * Filters/GraupelPieces.h): SetUpState builds the core on GetPieces()'s
 * grid (PieceGrid) and local arrays (LocalField) and, when IsSplit(), binds
 * the core's halo calls (BindHalo) and sets Pieces::Exchange and
 * Pieces::Allreduce on the core, and FillImage outputs the requested extent, taking
 * the row a strip shares with the next from that rank. Field data
 * `piece_cells` gives the grid points the rank simulated, ring included.
 * Aborts between knots are agreed by every rank (the cores agree inside a
 * call), so no rank waits alone in a collective call; a failure on one rank
 * (a device error) leaves the others waiting in their next collective call,
 * as MPI programs do. A simulation without a ring (SetPieceRing(0), the
 * default), a request that is not one piece per rank, or strips narrower
 * than the ring: every rank simulates the whole domain and outputs the
 * requested piece, so pieces equal the whole. Subclasses implement the
 * hooks below; they translate, they do not compute.
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

  /** Input port policies (see the class comment). */
  enum InputPolicy { STATIC_INPUT = 0, TEMPORAL_INPUT = 1 };

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
   * A checkpoint on disk (see "Checkpoint files" in the class comment): while
   * set, every update writes the state it outputs to this manifest (JSON)
   * and one .vti per rank beside it, replacing what was there. Setting it
   * does not set the simulation up again. Empty (the default): nothing is
   * written.
   */
  virtual void SetCheckpointFile(const char *path);
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

  /**
   * For a grid simulation's FillOutput: gives output (an image) the terrain
   * input's geometry, cropped to the extent outInfo requests, and one float
   * point array per field (gr_field values), each read from the core by
   * read(field, values) into the whole grid (a gr_status). The first field
   * becomes the active scalars. A failed read is reported with detail() (the
   * core's own sentence); returns 0 then.
   */
  /** The core's grid of a 2-D terrain image: its points, spacing and origin (a whole grid). */
  static void TerrainGrid(vtkImageData *terrain, gr_grid *grid);

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
  /** Without Modified(): see "Progress and abort" in the class comment. */
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
  /** Input time step of a temporal port that holds at time t. */
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
