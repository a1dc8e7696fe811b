#include "vtkGraupelSimulation.h"
#include "GraupelRemoteAbort.h"
#include "GraupelTerrain.h"

#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkDataObject.h"
#include "vtkDoubleArray.h"
#include "vtkDemandDrivenPipeline.h"
#include "vtkExtentTranslator.h"
#include "vtkExecutive.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationIntegerRequestKey.h"
#include "vtkInformationExecutivePortKey.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include "graupel/graupel.h"

#include "GraupelMemory.h"
#include "GraupelParameterTable.h"
#include "GraupelPieces.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <string>

#if defined(__unix__) || defined(__APPLE__)
#include <unistd.h>
#endif

namespace {
// Whether the state may serve an output at goal from time t (a kept state or
// a checkpoint). With an input read in time (inputTimes: per port, empty
// when static), the output shows what that input held over the advance that
// ends at goal (Water Surface's water, the objects' time step), which a state
// merely restored at goal did not read: it steps into goal from before, as a
// forward run does. Time 0, with nothing before it, is set up or reset.
bool ServesFrom(double t, double goal, const std::vector<std::vector<double>> &inputTimes) {
  const bool temporal = std::any_of(inputTimes.begin(), inputTimes.end(),
                                    [](const std::vector<double> &v) { return v.size() >= 2; });
  return (temporal && goal > 0.0) ? t < goal : t <= goal;
}

// The host's physical memory in bytes; 0 when unknown.
double PhysicalMemoryBytes() {
#if defined(_SC_PHYS_PAGES) && defined(_SC_PAGESIZE)
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long size = sysconf(_SC_PAGESIZE);
  if (pages > 0 && size > 0) {
    return static_cast<double>(pages) * static_cast<double>(size);
  }
#endif
  return 0.0;
}

// The progress text's times: the requested time as set (%g), the running
// time to about a thousandth of it without trailing zeros, so that it reads
// "92 s of 1800 s", "3.2 s of 60 s" and "30 s of 60 s" rather than
// "91.5385 s of 1800 s".
std::string ProgressTimes(double t, double goal) {
  const double scale = std::fabs(goal) > 0.0 ? std::fabs(goal) : 1.0;
  const int decimals =
      std::max(0, std::min(6, 2 - static_cast<int>(std::floor(std::log10(scale)))));
  char now[64];
  std::snprintf(now, sizeof(now), "%.*f", decimals, t);
  std::string text = now;
  if (text.find('.') != std::string::npos) {
    text.erase(text.find_last_not_of('0') + 1);
    if (text.back() == '.') {
      text.pop_back();
    }
  }
  if (text == "-0") {
    text = "0";
  }
  char end[64];
  std::snprintf(end, sizeof(end), "%g", goal);
  return "t = " + text + " s of " + end + " s";
}
} // namespace

vtkGraupelSimulation::vtkGraupelSimulation() : PieceLayout(new graupel::Pieces) {}

GRAUPEL_CLAMP_SETTER(vtkGraupelSimulation, CheckpointInterval, int, 0, MaximumOutputSteps,
                     "outputs")
GRAUPEL_CLAMP_SETTER(vtkGraupelSimulation, CheckpointMemoryLimit, double, 0.0, 1.0e9, "MiB")

vtkGraupelSimulation::~vtkGraupelSimulation() {
  delete this->PieceLayout;
  this->SetCheckpointFile(nullptr);
  this->SetRestartFile(nullptr);
}

void vtkGraupelSimulation::SetCheckpointFile(const char *path) {
  if ((!path && !this->CheckpointFile) ||
      (path && this->CheckpointFile && std::strcmp(path, this->CheckpointFile) == 0)) {
    return;
  }
  delete[] this->CheckpointFile;
  this->CheckpointFile = nullptr;
  if (path) {
    this->CheckpointFile = new char[std::strlen(path) + 1];
    std::strcpy(this->CheckpointFile, path);
  }
  // Where the state goes is no part of what it is: the pipeline runs again
  // (and writes), the state is kept (as SetAbortOutput does).
  const vtkMTimeType before = this->GetMTime();
  this->Modified();
  const vtkMTimeType after = this->GetMTime();
  if (this->StateKey.filter == before) {
    this->StateKey.filter = after;
  }
  if (this->FailedKey.filter == before) {
    this->FailedKey.filter = after;
  }
}

void vtkGraupelSimulation::SetTimeDefaults(double endTime, double outputInterval) {
  this->EndTime = this->DefaultEndTime = endTime;
  this->OutputInterval = this->DefaultOutputInterval = outputInterval;
  this->Modified();
}

void vtkGraupelSimulation::SetInputPortPolicy(int port, int policy) {
  if (port < 0) {
    return;
  }
  if (static_cast<size_t>(port) >= this->Policies.size()) {
    this->Policies.resize(static_cast<size_t>(port) + 1, STATIC_INPUT);
  }
  this->Policies[static_cast<size_t>(port)] = policy;
  this->Modified();
}

void vtkGraupelSimulation::SetInputFrameHold(int port, int hold) {
  if (port < 0 || this->GetInputFrameHold(port) == hold) {
    return;
  }
  if (static_cast<size_t>(port) >= this->FrameHolds.size()) {
    this->FrameHolds.resize(static_cast<size_t>(port) + 1, HOLD_FROM_TIME);
  }
  this->FrameHolds[static_cast<size_t>(port)] = hold;
  this->Modified();
}

int vtkGraupelSimulation::GetInputFrameHold(int port) const {
  return port >= 0 && static_cast<size_t>(port) < this->FrameHolds.size()
             ? this->FrameHolds[static_cast<size_t>(port)]
             : HOLD_FROM_TIME;
}

bool vtkGraupelSimulation::IsInputTemporal(int port) const {
  return port >= 0 && static_cast<size_t>(port) < this->InputTimes.size() &&
         this->InputTimes[static_cast<size_t>(port)].size() >= 2;
}

double vtkGraupelSimulation::GetHaloExchangeSeconds(int part) {
  return this->PieceLayout->GetExchangeSeconds(part);
}

long vtkGraupelSimulation::GetHaloExchangeCount() const {
  return this->PieceLayout->GetExchangeCalls();
}

int vtkGraupelSimulation::SaveState(std::vector<unsigned char> &) {
  return 0;
}

int vtkGraupelSimulation::LoadState(const std::vector<unsigned char> &) {
  return 0;
}

const char *vtkGraupelSimulation::GetSimulationLabel() {
  return this->GetClassName();
}

vtkTypeInt64 vtkGraupelSimulation::GetCheckpointMemoryLimitBytes() const {
  double limit = this->CheckpointMemoryLimit * 1048576.0;
  const double physical = PhysicalMemoryBytes();
  if (physical > 0.0) {
    limit = std::min(limit, 0.25 * physical);
  }
  return static_cast<vtkTypeInt64>(limit);
}

vtkTypeInt64 vtkGraupelSimulation::GetCheckpointBytes() const {
  vtkTypeInt64 bytes = 0;
  for (const Checkpoint &c : this->Checkpoints) {
    bytes += static_cast<vtkTypeInt64>(c.bytes.size());
  }
  return bytes;
}

int vtkGraupelSimulation::GetCheckpointIndex(int i) const {
  return i >= 0 && i < this->GetNumberOfCheckpoints()
             ? this->Checkpoints[static_cast<size_t>(i)].index
             : -1;
}

int vtkGraupelSimulation::GetNumberOfOutputTimes() const {
  if (!(this->EndTime >= 0.0) || !(this->OutputInterval > 0.0) || !std::isfinite(this->EndTime)) {
    return 0;
  }
  // A last interval shorter than OutputInterval ends exactly at EndTime; one
  // shorter than a millionth of an interval is rounding, not an interval.
  const double intervals = std::ceil(this->EndTime / this->OutputInterval - 1e-6);
  if (intervals + 1.0 > MaximumOutputSteps) {
    return 0;
  }
  return static_cast<int>(std::max(0.0, intervals)) + 1;
}

double vtkGraupelSimulation::GetOutputTime(int k) const {
  return std::min(k * this->OutputInterval, this->EndTime);
}

bool vtkGraupelSimulation::IsOutputTime(double t) const {
  const int n = this->GetNumberOfOutputTimes();
  if (n <= 0 || !(this->OutputInterval > 0.0)) {
    return false;
  }
  const double slack = 1e-9 * std::max(1.0, std::fabs(t));
  const int k = static_cast<int>(
      std::max(0.0, std::min(n - 1.0, std::floor(t / this->OutputInterval + 0.5))));
  for (int i = std::max(0, k - 1); i <= std::min(n - 1, k + 1); ++i) {
    if (std::fabs(this->GetOutputTime(i) - t) <= slack) {
      return true;
    }
  }
  return false;
}

int vtkGraupelSimulation::CheckTimes() {
  if (!(this->OutputInterval > 0.0) || !std::isfinite(this->OutputInterval)) {
    vtkErrorMacro(<< this->GetClassName() << ": OutputInterval must be above 0 s; it is "
                  << this->OutputInterval << ".");
    return 0;
  }
  if (!(this->EndTime >= 0.0) || !std::isfinite(this->EndTime)) {
    vtkErrorMacro(<< this->GetClassName() << ": EndTime must be 0 s or later; it is "
                  << this->EndTime << ".");
    return 0;
  }
  if (this->GetNumberOfOutputTimes() == 0) {
    vtkErrorMacro(<< this->GetClassName() << ": EndTime / OutputInterval gives more than "
                  << MaximumOutputSteps - 1
                  << " output intervals; raise OutputInterval or lower EndTime.");
    return 0;
  }
  return 1;
}

void vtkGraupelSimulation::InvalidateState() {
  this->ReleaseState();
  this->StateIndex = -1;
  this->Checkpoints.clear();
  this->WrittenIndex = -1;
}

vtkDataObject *vtkGraupelSimulation::GetTemporalInput(int port) {
  return this->GetInputDataObject(port, 0);
}

double vtkGraupelSimulation::GetTemporalInputTime(int port) const {
  return port >= 0 && static_cast<size_t>(port) < this->DeliveredTime.size()
             ? this->DeliveredTime[static_cast<size_t>(port)]
             : 0.0;
}

double vtkGraupelSimulation::InputTimeAt(int port, double t) const {
  const std::vector<double> &times = this->InputTimes[static_cast<size_t>(port)];
  // t is where an advance starts; it ends at the next knot, at most the
  // first time step after t (NextKnot), so one step holds over all of it.
  auto it = std::upper_bound(times.begin(), times.end(), t);
  if (this->GetInputFrameHold(port) == HOLD_INTERVAL_BEFORE) {
    // The step that ends the interval (t, next]: the first after t; after
    // the last, the last holds.
    return it == times.end() ? times.back() : *it;
  }
  // The last time step at or before t; before the first, the first holds.
  return it == times.begin() ? times.front() : *(it - 1);
}

vtkTypeBool vtkGraupelSimulation::ProcessRequest(vtkInformation *request,
                                                 vtkInformationVector **inInfo,
                                                 vtkInformationVector *outInfo) {
  if ((request->Has(vtkStreamingDemandDrivenPipeline::REQUEST_UPDATE_EXTENT()) ||
       request->Has(vtkDemandDrivenPipeline::REQUEST_DATA())) &&
      request->Has(vtkExecutive::FROM_OUTPUT_PORT()) &&
      request->Get(vtkExecutive::FROM_OUTPUT_PORT()) >= 1) {
    vtkInformation *from =
        outInfo->GetInformationObject(request->Get(vtkExecutive::FROM_OUTPUT_PORT()));
    if (from->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP())) {
      outInfo->GetInformationObject(0)->Set(
          vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP(),
          from->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP()));
    }
  }
  return this->Superclass::ProcessRequest(request, inInfo, outInfo);
}

int vtkGraupelSimulation::RequestInformation(vtkInformation *, vtkInformationVector **inputVector,
                                             vtkInformationVector *outputVector) {
  const int ok = this->AdvertiseTimes(inputVector, outputVector);
  // The other outputs have the simulation's times, not the input's.
  vtkInformation *image = outputVector->GetInformationObject(0);
  for (int port = 1; port < this->GetNumberOfOutputPorts(); ++port) {
    vtkInformation *info = outputVector->GetInformationObject(port);
    info->Remove(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
    info->Remove(vtkStreamingDemandDrivenPipeline::TIME_RANGE());
    if (image->Has(vtkStreamingDemandDrivenPipeline::TIME_STEPS())) {
      info->CopyEntry(image, vtkStreamingDemandDrivenPipeline::TIME_STEPS());
      info->CopyEntry(image, vtkStreamingDemandDrivenPipeline::TIME_RANGE());
    }
  }
  return ok;
}

int vtkGraupelSimulation::AdvertiseTimes(vtkInformationVector **inputVector,
                                         vtkInformationVector *outputVector) {
  const int nports = this->GetNumberOfInputPorts();
  this->InputTimes.assign(static_cast<size_t>(nports), std::vector<double>());
  this->DeliveredTime.resize(static_cast<size_t>(nports), 0.0);
  this->PendingTime.resize(static_cast<size_t>(nports), 0.0);
  for (int port = 0; port < nports; ++port) {
    // A port follows the simulated time by its policy (objects in motion,
    // inflows in time), the Input also when asked (FollowInputTime).
    const bool temporal = (static_cast<size_t>(port) < this->Policies.size() &&
                           this->Policies[static_cast<size_t>(port)] == TEMPORAL_INPUT) ||
                          (port == 0 && this->FollowInputTime != 0);
    vtkInformation *inInfo = inputVector[port]->GetInformationObject(0);
    if (!temporal || !inInfo || !inInfo->Has(vtkStreamingDemandDrivenPipeline::TIME_STEPS())) {
      continue;
    }
    const double *t = inInfo->Get(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
    std::vector<double> times(t,
                              t + inInfo->Length(vtkStreamingDemandDrivenPipeline::TIME_STEPS()));
    std::sort(times.begin(), times.end());
    times.erase(std::unique(times.begin(), times.end()), times.end());
    if (times.size() >= 2) {
      this->InputTimes[static_cast<size_t>(port)] = times;
    }
  }

  // The executive copied input 0's times to the output: replace them by ours.
  vtkInformation *outInfo = outputVector->GetInformationObject(0);
  outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
  outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_RANGE());
  const int n = this->GetNumberOfOutputTimes();
  if (n == 0) {
    // Unusable EndTime or OutputInterval: no times to advertise; RequestData
    // says why in one sentence and gives an empty output.
    return 1;
  }
  std::vector<double> times(static_cast<size_t>(n));
  for (int k = 0; k < n; ++k) {
    times[static_cast<size_t>(k)] = this->GetOutputTime(k);
  }
  double range[2] = {0.0, times.back()};
  outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_STEPS(), times.data(), n);
  outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), range, 2);
  // Any piece can be handed out (a strip's own rows or the whole grid's).
  outInfo->Set(vtkAlgorithm::CAN_PRODUCE_SUB_EXTENT(), 1);
  if (this->PieceRing > 0) {
    // Pieces as strips along y: the split graupel::Pieces simulates.
    outInfo->Set(vtkExtentTranslator::UPDATE_SPLIT_MODE(), vtkExtentTranslator::Y_SLAB_MODE);
  }
  return 1;
}

int vtkGraupelSimulation::TargetIndex(vtkInformation *outInfo) const {
  // The requested time, snapped to the last output time at or before it.
  const int n = this->GetNumberOfOutputTimes();
  int target = 0;
  if (n > 0 && outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP())) {
    const double t = outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
    if (std::isfinite(t)) {
      target = static_cast<int>(
          std::max(0.0, std::min(n - 1.0, std::floor(t / this->OutputInterval + 1e-6))));
      // The last output (EndTime) may come less than an interval after the one before.
      const double slack = 1e-9 * std::max(1.0, std::fabs(t));
      while (target + 1 < n && this->GetOutputTime(target + 1) <= t + slack) {
        ++target;
      }
    } else if (t > 0.0) {
      target = n - 1;
    }
  }
  return target;
}

double vtkGraupelSimulation::PlannedStart(int target) const {
  const double goal = this->GetOutputTime(target);
  double start = (this->StateIndex >= 0 && !this->StateLost &&
                  ServesFrom(this->StateTime, goal, this->InputTimes))
                     ? this->StateTime
                     : 0.0;
  for (const Checkpoint &c : this->Checkpoints) {
    const double tc = this->GetOutputTime(c.index);
    if (ServesFrom(tc, goal, this->InputTimes) && tc > start) {
      start = tc;
    }
  }
  return start;
}

int vtkGraupelSimulation::RequestUpdateExtent(vtkInformation *, vtkInformationVector **inputVector,
                                              vtkInformationVector *outputVector) {
  const int nports = this->GetNumberOfInputPorts();
  if (!this->Continuing) {
    // First pass of a request: guess the input times the state will need
    // first; a wrong guess costs one more pass, not a wrong result.
    const double start =
        this->PlannedStart(this->TargetIndex(outputVector->GetInformationObject(0)));
    for (int port = 0; port < nports; ++port) {
      if (this->IsInputTemporal(port)) {
        this->PendingTime[static_cast<size_t>(port)] = this->InputTimeAt(port, start);
      }
    }
  }
  for (int port = 0; port < nports; ++port) {
    for (int c = 0; c < inputVector[port]->GetNumberOfInformationObjects(); ++c) {
      vtkInformation *inInfo = inputVector[port]->GetInformationObject(c);
      // The whole input: the simulation needs all of it. Asking for piece 0
      // of 1 as well: a source that can split its output turns a piece
      // request into its extent, whatever extent was set.
      inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER(), 0);
      inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES(), 1);
      inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS(), 0);
      if (inInfo->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT())) {
        inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(),
                    inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()), 6);
      }
      if (this->IsInputTemporal(port)) {
        const double t = this->PendingTime[static_cast<size_t>(port)];
        inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP(), t);
        this->DeliveredTime[static_cast<size_t>(port)] = t;
      } else if (inInfo->Has(vtkStreamingDemandDrivenPipeline::TIME_STEPS()) ||
                 inInfo->Has(vtkStreamingDemandDrivenPipeline::TIME_RANGE())) {
        // A static input with times of its own (another simulation's
        // output) at InputTime, by default its end: a time request for this
        // simulation is not one for its input, and no earlier request
        // decides what it starts from.
        inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP(),
                    this->StaticInputTime(inInfo));
      } else {
        inInfo->Remove(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
      }
    }
  }
  return 1;
}

double vtkGraupelSimulation::StaticInputTime(vtkInformation *inInfo) const {
  if (this->InputTime >= 0.0) {
    return this->InputTime;
  }
  if (inInfo->Has(vtkStreamingDemandDrivenPipeline::TIME_STEPS())) {
    const int n = inInfo->Length(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
    if (n > 0) {
      return inInfo->Get(vtkStreamingDemandDrivenPipeline::TIME_STEPS())[n - 1];
    }
  }
  return inInfo->Get(vtkStreamingDemandDrivenPipeline::TIME_RANGE())[1];
}

vtkGraupelSimulation::Key vtkGraupelSimulation::CurrentKey() {
  Key key;
  key.filter = this->GetMTime();
  for (int port = 0; port < this->GetNumberOfInputPorts(); ++port) {
    // What an input is made from changes with its pipeline, not with its
    // data object: a temporal input's data change with every time read, and
    // a static one's when its producer merely runs again for another
    // request (ParaView asks an input for its data information at the
    // animation's time), which must not set the simulation up again.
    vtkMTimeType t = 0;
    vtkInformation *inInfo =
        this->GetNumberOfInputConnections(port) ? this->GetInputInformation(port, 0) : nullptr;
    vtkExecutive *producer = inInfo ? vtkExecutive::PRODUCER()->GetExecutive(inInfo) : nullptr;
    if (auto *ddp = vtkDemandDrivenPipeline::SafeDownCast(producer)) {
      t = ddp->GetPipelineMTime();
    } else if (vtkDataObject *in = inInfo ? this->GetInputDataObject(port, 0) : nullptr) {
      t = in->GetMTime();
    }
    if (this->IsInputTemporal(port)) {
      key.times.push_back(this->InputTimes[static_cast<size_t>(port)]);
    }
    key.inputs.push_back(t);
  }
  return key;
}

int vtkGraupelSimulation::Rewind(int target) {
  const double goal = this->GetOutputTime(target);
  const bool stateUsable = this->StateIndex >= 0 && !this->StateLost &&
                           ServesFrom(this->StateTime, goal, this->InputTimes);
  const Checkpoint *best = nullptr;
  for (const Checkpoint &c : this->Checkpoints) {
    const double tc = this->GetOutputTime(c.index);
    if (ServesFrom(tc, goal, this->InputTimes) && (!stateUsable || tc > this->StateTime) &&
        (!best || c.index > best->index)) {
      best = &c;
    }
  }
  if (best) {
    if (this->LoadState(best->bytes)) {
      ++this->RestoreCount;
      this->StateLost = false;
      this->StateIndex = best->index;
      this->StateTime = this->GetOutputTime(best->index);
      return 1;
    }
    // A snapshot that does not load is no use; time 0 still is.
    this->Checkpoints.clear();
  }
  if (stateUsable) {
    return 1;
  }
  ++this->RestartCount;
  if (!this->ResetState()) {
    return 0;
  }
  this->StateLost = false;
  this->StateIndex = 0;
  this->StateTime = 0.0;
  return 1;
}

void vtkGraupelSimulation::KeepCheckpoint() {
  const int k = this->StateIndex;
  if (this->CheckpointInterval <= 0 || k <= 0 || k % this->CheckpointInterval != 0 ||
      this->StateTime != this->GetOutputTime(k)) {
    return;
  }
  for (const Checkpoint &c : this->Checkpoints) {
    if (c.index == k) {
      return;
    }
  }
  Checkpoint c{k, {}};
  if (!this->SaveState(c.bytes)) {
    return;
  }
  const vtkTypeInt64 limit = this->GetCheckpointMemoryLimitBytes();
  const vtkTypeInt64 size = static_cast<vtkTypeInt64>(c.bytes.size());
  if (size > limit) {
    return;
  }
  while (!this->Checkpoints.empty() && this->GetCheckpointBytes() + size > limit) {
    this->Checkpoints.pop_front();
  }
  c.bytes.shrink_to_fit();
  this->Checkpoints.push_back(std::move(c));
}

int vtkGraupelSimulation::ReportProgress(double t) {
  // The bar says how far the simulated time is along the run to the goal,
  // as the text does ("t = 1000 s of 3600 s"), also when an update resumes
  // from a kept state.
  const double goal = this->GetOutputTime(this->Target);
  const double start = this->GetOutputTime(0);
  const double span = goal - start;
  const double fraction = span > 0.0 ? (t - start) / span : 1.0;
  const std::string text = std::string(this->GetSimulationLabel()) + ": " + ProgressTimes(t, goal);
  this->SetProgressText(text.c_str());
  this->UpdateProgress(std::max(0.0, std::min(1.0, fraction)));
  if (graupel::RemoteAbortAsked(this, goal, false)) {
    this->SetAbortExecute(1); // a remote client's abort, or the client gone
  }
  return this->GetAbortExecute() ? 1 : 0;
}

int vtkGraupelSimulation::CoreProgress(void *user, double time) {
  return static_cast<vtkGraupelSimulation *>(user)->ReportProgress(time);
}

int vtkGraupelSimulation::ThrottledProgress(void *user, double time) {
  auto *self = static_cast<vtkGraupelSimulation *>(user);
  if (self->GetAbortExecute()) {
    return 1;
  }
  const double now =
      std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  if (now - self->LastProgressWall < 0.1) {
    return 0;
  }
  self->LastProgressWall = now;
  return CoreProgress(user, time);
}

long long vtkGraupelSimulation::CountSteps(double t0, double t1, double dt) {
  const double count = std::ceil((t1 - t0) / dt - 1e-9);
  return count < 1.0 ? 1 : static_cast<long long>(count);
}

double vtkGraupelSimulation::StepEnd(double t0, double t1, double dt, long long k, long long n) {
  return k == n ? t1 : t0 + static_cast<double>(k) * dt;
}

int vtkGraupelSimulation::CheckTerrain(vtkImageData *terrain) {
  const char *label = this->GetSimulationLabel();
  if (!terrain) {
    vtkErrorMacro(<< label << " needs a terrain image on its Input.");
    return 0;
  }
  int dims[3];
  terrain->GetDimensions(dims);
  double spacing[3];
  terrain->GetSpacing(spacing);
  if (dims[0] < 2 || dims[1] < 2 || dims[2] != 1) {
    vtkErrorMacro(<< label << " needs a 2-D terrain of at least 2 x 2 points on its Input; it got "
                  << dims[0] << " x " << dims[1] << " x " << dims[2]
                  << ". Slice a volume or resample the terrain first.");
    return 0;
  }
  if (!(spacing[0] > 0.0) || !(spacing[1] > 0.0)) {
    vtkErrorMacro(<< label << " needs a terrain spacing above 0 m in x and y; the Input has "
                  << spacing[0] << " x " << spacing[1] << " m. Set the spacing on the source.");
    return 0;
  }
  return 1;
}

int vtkGraupelSimulation::CheckMemory(const gr_grid &grid, const gr_memory_need &core,
                                      double hostBytes) {
  const std::string fix = this->GetPieces().IsSplit()
                              ? "resample the terrain to fewer points (Resample To Image) or "
                                "split it over more MPI ranks"
                              : "resample the terrain to fewer points (Resample To Image) or "
                                "split it over MPI ranks (mpiexec ... pvbatch)";
  // A checkpoint is one copy of the state on the host while it is made (the
  // ones kept are capped by CheckpointMemoryLimit).
  gr_memory_need need = core;
  if (this->CheckpointInterval > 0 || (this->CheckpointFile && *this->CheckpointFile)) {
    need.host += core.state;
  }
  return this->ReportError(graupel::MemoryRefusal(
      this->GetContext(), this->GetSimulationLabel(), graupel::GridSubject(grid.nx, grid.ny),
      graupel::WithHostArrays(need, static_cast<double>(grid.nx) * grid.ny, hostBytes), fix));
}

namespace {
// What a Height Array means: "" for the default rule (none, or elevation).
std::string HeightsKey(vtkAlgorithm *alg) {
  const graupel::HeightsChoice c = graupel::ChosenHeights(alg);
  return (c.name.empty() || c.name == "elevation") ? std::string()
                                                   : c.name + '/' + std::to_string(c.association);
}
} // namespace

void vtkGraupelSimulation::KeepStateIfSameHeights(const std::string &before, vtkMTimeType was) {
  if (HeightsKey(this) != before) {
    return;
  }
  const vtkMTimeType now = this->GetMTime();
  if (this->StateKey.filter == was) {
    this->StateKey.filter = now;
  }
  if (this->FailedKey.filter == was) {
    this->FailedKey.filter = now;
  }
}

void vtkGraupelSimulation::SetInputArrayToProcess(int idx, int port, int connection,
                                                  int fieldAssociation, const char *name) {
  const std::string before = HeightsKey(this);
  const vtkMTimeType was = this->GetMTime();
  this->Superclass::SetInputArrayToProcess(idx, port, connection, fieldAssociation, name);
  this->KeepStateIfSameHeights(before, was);
}

void vtkGraupelSimulation::SetInputArrayToProcess(int idx, int port, int connection,
                                                  const char *fieldAssociation, const char *name) {
  const std::string before = HeightsKey(this);
  const vtkMTimeType was = this->GetMTime();
  this->Superclass::SetInputArrayToProcess(idx, port, connection, fieldAssociation, name);
  this->KeepStateIfSameHeights(before, was);
}

void vtkGraupelSimulation::SetInputArrayToProcess(int idx, vtkInformation *info) {
  const std::string before = HeightsKey(this);
  const vtkMTimeType was = this->GetMTime();
  this->Superclass::SetInputArrayToProcess(idx, info);
  this->KeepStateIfSameHeights(before, was);
}

vtkDataArray *vtkGraupelSimulation::GetElevation(vtkImageData *terrain, const char *inputName) {
  // The Input is the terrain or its view (vtkGraupelAlgorithm,
  // GraupelTerrain.h): the chosen heights as a point array.
  std::string why;
  vtkDataArray *a = this->TerrainHeights(terrain, &why);
  if (!a) {
    vtkErrorMacro(<< graupel::NoHeightsSentence(this->GetSimulationLabel(), inputName, why));
    return nullptr;
  }
  double spacing[3];
  terrain->GetSpacing(spacing);
  double range[2];
  a->GetRange(range, 0);
  const double span = range[1] - range[0];
  if (spacing[0] == 1.0 && spacing[1] == 1.0 && span >= 100.0 &&
      this->WarnedSpacingFor != terrain->GetMTime()) {
    this->WarnedSpacingFor = terrain->GetMTime();
    vtkWarningMacro(<< this->GetSimulationLabel() << "'s " << inputName
                    << " has a spacing of 1 m while its elevation spans " << span
                    << " m: if its points lie farther apart, set the terrain's Spacing (on "
                       "the reader or source) or its slopes are that many times too steep.");
  }
  return a;
}

void vtkGraupelSimulation::Finish(vtkInformation *request) {
  request->Remove(vtkStreamingDemandDrivenPipeline::CONTINUE_EXECUTING());
  this->Continuing = false;
}

int vtkGraupelSimulation::RequestData(vtkInformation *request, vtkInformationVector **inputVector,
                                      vtkInformationVector *outputVector) {
  const int outputs = this->GetNumberOfOutputPorts();
  for (int port = 1; port < outputs; ++port) {
    if (vtkDataObject *other =
            outputVector->GetInformationObject(port)->Get(vtkDataObject::DATA_OBJECT())) {
      other->Initialize();
    }
  }
  this->OutputVector = outputVector;
  this->OutputsFilled = false;
  const int ok = this->UpdateState(request, inputVector, outputVector);
  this->OutputVector = nullptr;
  vtkInformation *image =
      outputVector->GetInformationObject(0)->Get(vtkDataObject::DATA_OBJECT())->GetInformation();
  if (ok && this->OutputsFilled && image->Has(vtkDataObject::DATA_TIME_STEP())) {
    for (int port = 1; port < outputs; ++port) {
      if (vtkDataObject *other =
              outputVector->GetInformationObject(port)->Get(vtkDataObject::DATA_OBJECT())) {
        other->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(),
                                     image->Get(vtkDataObject::DATA_TIME_STEP()));
      }
    }
  }
  return ok;
}

int vtkGraupelSimulation::PlanRequest(vtkInformation *outInfo, vtkInformationVector **inputVector) {
  const Key key = this->CurrentKey();
  if (this->HasFailed && key == this->FailedKey) {
    // Said why already; nothing changed since.
    return 0;
  }
  this->HasFailed = false;
  this->FailedKey = key;
  if (!this->CheckTimes()) {
    this->InvalidateState();
    this->HasFailed = true;
    return 0;
  }
  this->Target = this->TargetIndex(outInfo);
  if (this->StateIndex < 0 || !(key == this->StateKey) ||
      this->StateLayout != this->PieceLayout->GetSignature()) {
    this->InvalidateState();
    if (!this->GetContext()) {
      this->HasFailed = true;
      return 0;
    }
    ++this->RestartCount;
    this->RestartIndex = -1;
    if (!this->SetUpState(inputVector)) {
      this->ReleaseState();
      this->HasFailed = true;
      return 0;
    }
    this->StateIndex = 0;
    this->StateTime = 0.0;
    this->StateLost = false;
    this->StateKey = key;
    this->StateLayout = this->PieceLayout->GetSignature();
    if (this->RestartFile && *this->RestartFile && !this->ReadRestartFile()) {
      this->InvalidateState();
      this->HasFailed = true;
      return 0;
    }
  }
  if (!this->Rewind(this->Target)) {
    this->InvalidateState();
    this->HasFailed = true;
    return 0;
  }
  this->ReportProgress(this->StateTime);
  return 1;
}

int vtkGraupelSimulation::NextKnot(vtkInformation *request, double &next) {
  // Each temporal input at the time step that holds now, else another pass.
  const int nports = this->GetNumberOfInputPorts();
  bool waiting = false;
  next = this->GetOutputTime(this->StateIndex + 1);
  for (int port = 0; port < nports; ++port) {
    if (!this->IsInputTemporal(port)) {
      continue;
    }
    const double need = this->InputTimeAt(port, this->StateTime);
    if (need != this->DeliveredTime[static_cast<size_t>(port)]) {
      if (this->Continuing && need == this->PendingTime[static_cast<size_t>(port)]) {
        this->Finish(request);
        this->InvalidateState();
        this->HasFailed = true;
        vtkErrorMacro(<< this->GetSimulationLabel() << ": input " << port
                      << " did not update to time " << need
                      << " s; the pipeline above it must honour time requests.");
        return KNOT_FAILED;
      }
      this->PendingTime[static_cast<size_t>(port)] = need;
      waiting = true;
    }
    const std::vector<double> &times = this->InputTimes[static_cast<size_t>(port)];
    auto after = std::upper_bound(times.begin(), times.end(), this->StateTime);
    if (after != times.end()) {
      next = std::min(next, *after);
    }
  }
  if (waiting) {
    request->Set(vtkStreamingDemandDrivenPipeline::CONTINUE_EXECUTING(), 1);
    this->Continuing = true;
    ++this->ExtraPassCount;
    return KNOT_WAIT;
  }
  return KNOT_READY;
}

int vtkGraupelSimulation::UpdateState(vtkInformation *request, vtkInformationVector **inputVector,
                                      vtkInformationVector *outputVector) {
  vtkInformation *outInfo = outputVector->GetInformationObject(0);
  vtkDataObject *output = outInfo->Get(vtkDataObject::DATA_OBJECT());
  output->Initialize();

  if (!this->Continuing) {
    // Collective on a parallel request: every rank plans at once.
    this->PieceLayout->Plan(outInfo, this->PieceRing);
  }
  if (!this->Continuing &&
      graupel::RemoteAbortAsked(this, this->GetOutputTime(this->TargetIndex(outInfo)), true)) {
    this->AbortExecute = 1; // a remote client's abort holds for the time it stopped
  }
#if GRAUPEL_VTK_ABORT_OUTPUT
  if (!this->Continuing &&
      this->PieceLayout->AnyRank(this->GetAbortExecute() != 0 || this->GetAbortOutput())) {
    // Aborted before it began (see "Progress and abort" in Filters/README.md): an empty output, no
    // warning, nothing touched (on every rank of a split run at once).
    this->AbortExecute = 0;
    this->SetAbortOutput(true);
    return 1;
  }
#endif
  if (!this->Continuing && !this->PlanRequest(outInfo, inputVector)) {
    return 0;
  }

  const double goal = this->GetOutputTime(this->Target);
  while (this->StateTime < goal) {
    double next = 0.0;
    const int knot = this->NextKnot(request, next);
    if (knot != KNOT_READY) {
      return knot == KNOT_WAIT ? 1 : 0;
    }
    const int result = this->AdvanceState(this->StateTime, next);
    if (result == ADVANCE_FAILED) {
      this->Finish(request);
      this->InvalidateState();
      this->HasFailed = true;
      return 0;
    }
    if (result == ADVANCE_ABORTED) {
      // Stopped between the knots: see Filters/README.md. The set-up and the
      // checkpoints stay; the device state is no longer one to go on from.
      this->StateLost = true;
    } else {
      this->StateTime = next;
      if (next == this->GetOutputTime(this->StateIndex + 1)) {
        ++this->StateIndex;
        this->KeepCheckpoint();
      }
      this->ReportProgress(this->StateTime);
    }
    // A split run's ranks agree on an abort between the knots (the cores
    // agree inside a call): a rank that stopped alone would leave the others
    // waiting in their next exchange.
    const bool abortNow =
        this->PieceLayout->AnyRank(this->StateTime < goal && this->GetAbortExecute());
    if (result == ADVANCE_ABORTED || abortNow) {
      vtkWarningMacro(<< this->GetSimulationLabel() << ": the update was aborted at t = "
                      << this->StateTime << " s; the output is empty and the next update "
                      << (result == ADVANCE_ABORTED ? "starts again from the last checkpoint."
                                                    : "goes on from there."));
      this->Finish(request);
      // Consume the abort; the executive empties the output and marks it
      // ABORTED, so the next request runs again (see Filters/README.md).
      this->AbortExecute = 0;
#if GRAUPEL_VTK_ABORT_OUTPUT
      this->SetAbortOutput(true);
#else
      this->Modified();
      this->StateKey.filter = this->GetMTime();
#endif
      return 1;
    }
  }

  this->Finish(request);
  if (!this->FillOutput(output, outInfo)) {
    output->Initialize();
    this->HasFailed = true;
    return 0;
  }
  output->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), goal);
  this->AddDeviceFieldData(output);
  if (this->CheckpointFile && *this->CheckpointFile && !this->WriteCheckpointFile(output)) {
    // A file that could not be written (a full disk) is no fault of the
    // state, which stays as it is: the next request tries again (HasFailed
    // would hold every later time until a property changed).
    output->Initialize();
    return 0;
  }
  return 1;
}

#if GRAUPEL_VTK_ABORT_OUTPUT
void vtkGraupelSimulation::SetAbortExecute(vtkTypeBool abort) {
  this->AbortExecute = abort;
}

void vtkGraupelSimulation::SetAbortOutput(bool abort) {
  // vtkAlgorithm's setter calls Modified() (and the member is private): an
  // abort is execution state, so the keys that were current stay current.
  const vtkMTimeType before = this->GetMTime();
  this->Superclass::SetAbortOutput(abort);
  const vtkMTimeType after = this->GetMTime();
  if (this->StateKey.filter == before) {
    this->StateKey.filter = after;
  }
  if (this->FailedKey.filter == before) {
    this->FailedKey.filter = after;
  }
}
#endif

void vtkGraupelSimulation::PrintSelf(ostream &os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  os << indent << "EndTime: " << this->EndTime << "\n";
  os << indent << "OutputInterval: " << this->OutputInterval << "\n";
  os << indent << "CheckpointInterval: " << this->CheckpointInterval << "\n";
  os << indent << "CheckpointMemoryLimit: " << this->CheckpointMemoryLimit << " MiB\n";
  os << indent << "StateIndex: " << this->StateIndex << "\n";
  os << indent << "StateTime: " << this->StateTime << "\n";
  os << indent << "RestartCount: " << this->RestartCount << "\n";
  os << indent << "RestoreCount: " << this->RestoreCount << "\n";
  os << indent << "Checkpoints: " << this->Checkpoints.size() << " (" << this->GetCheckpointBytes()
     << " bytes)\n";
}
