#include "vtkGraupelSimulation.h"

#include "vtkDataObject.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <cmath>
#include <vector>

vtkGraupelSimulation::vtkGraupelSimulation() = default;

vtkGraupelSimulation::~vtkGraupelSimulation() = default;

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
}

int vtkGraupelSimulation::RequestInformation(vtkInformation *request,
                                             vtkInformationVector **inputVector,
                                             vtkInformationVector *outputVector) {
  // Geometry (whole extent, spacing, origin) comes from the terrain input.
  if (!this->Superclass::RequestInformation(request, inputVector, outputVector)) {
    return 0;
  }
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
  // Every rank simulates the whole domain and hands out any piece of it.
  outInfo->Set(vtkAlgorithm::CAN_PRODUCE_SUB_EXTENT(), 1);
  return 1;
}

int vtkGraupelSimulation::RequestUpdateExtent(vtkInformation *, vtkInformationVector **inputVector,
                                              vtkInformationVector *) {
  for (int port = 0; port < this->GetNumberOfInputPorts(); ++port) {
    for (int c = 0; c < inputVector[port]->GetNumberOfInformationObjects(); ++c) {
      vtkInformation *inInfo = inputVector[port]->GetInformationObject(c);
      // The whole input, at its first time: the simulation needs all of it,
      // and a time request for the simulation is not one for the terrain.
      // Asking for piece 0 of 1 as well: a source that can split its output
      // turns a piece request into its extent, whatever extent was set.
      inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER(), 0);
      inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES(), 1);
      inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS(), 0);
      if (inInfo->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT())) {
        inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(),
                    inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()), 6);
      }
      inInfo->Remove(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
    }
  }
  return 1;
}

bool vtkGraupelSimulation::StateIsCurrent() {
  if (this->StateIndex < 0 || this->GetMTime() != this->StateFilterMTime) {
    return false;
  }
  for (int port = 0; port < std::min(2, this->GetNumberOfInputPorts()); ++port) {
    vtkDataObject *in = this->GetInputDataObject(port, 0);
    const vtkMTimeType t = in ? in->GetMTime() : 0;
    if (t != this->StateInputMTime[port]) {
      return false;
    }
  }
  return true;
}

int vtkGraupelSimulation::RequestData(vtkInformation *, vtkInformationVector **inputVector,
                                      vtkInformationVector *outputVector) {
  vtkInformation *outInfo = outputVector->GetInformationObject(0);
  vtkImageData *output = vtkImageData::GetData(outInfo);
  output->Initialize();
  if (!this->CheckTimes()) {
    this->InvalidateState();
    return 0;
  }

  // The requested time, snapped to the last output time at or before it.
  const int n = this->GetNumberOfOutputTimes();
  int target = 0;
  if (outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP())) {
    const double t = outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
    if (std::isfinite(t)) {
      target = static_cast<int>(
          std::max(0.0, std::min(n - 1.0, std::floor(t / this->OutputInterval + 1e-6))));
      // The last output (EndTime) may come less than an interval after the one before.
      const double slack = 1e-9 * std::max(1.0, std::fabs(t));
      while (target + 1 < n && this->GetOutputTime(target + 1) <= t + slack) {
        ++target;
      }
    }
  }

  if (!this->StateIsCurrent()) {
    this->InvalidateState();
    if (!this->GetContext()) {
      return 0;
    }
    ++this->RestartCount;
    if (!this->SetUpState(inputVector)) {
      this->ReleaseState();
      return 0;
    }
    this->StateIndex = 0;
    this->StateFilterMTime = this->GetMTime();
    for (int port = 0; port < std::min(2, this->GetNumberOfInputPorts()); ++port) {
      vtkDataObject *in = this->GetInputDataObject(port, 0);
      this->StateInputMTime[port] = in ? in->GetMTime() : 0;
    }
  } else if (target < this->StateIndex) {
    // Earlier than the state: start again from time 0.
    ++this->RestartCount;
    if (!this->ResetState()) {
      this->InvalidateState();
      return 0;
    }
    this->StateIndex = 0;
  }

  const int first = this->StateIndex;
  this->UpdateProgress(0.0);
  while (this->StateIndex < target) {
    const double seconds =
        this->GetOutputTime(this->StateIndex + 1) - this->GetOutputTime(this->StateIndex);
    if (!this->AdvanceState(seconds)) {
      this->InvalidateState();
      return 0;
    }
    ++this->StateIndex;
    this->UpdateProgress(static_cast<double>(this->StateIndex - first) / (target - first));
    if (this->StateIndex < target && this->GetAbortExecute()) {
      vtkWarningMacro(<< this->GetClassName()
                      << ": the update was aborted at t = " << this->GetOutputTime(this->StateIndex)
                      << " s; the output is empty and the next update goes on from there.");
      // Honour the abort, then make sure the next request runs again; the
      // state reached so far stays valid for it.
      this->AbortExecute = 0;
      this->Modified();
      this->StateFilterMTime = this->GetMTime();
      return 1;
    }
  }

  int extent[6];
  outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), extent);
  vtkImageData *input = vtkImageData::GetData(inputVector[0]);
  output->SetExtent(extent);
  output->SetSpacing(input->GetSpacing());
  output->SetOrigin(input->GetOrigin());
  if (!this->FillOutput(output, extent)) {
    output->Initialize();
    return 0;
  }
  output->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(),
                                this->GetOutputTime(this->StateIndex));
  this->AddDeviceFieldData(output);
  return 1;
}

void vtkGraupelSimulation::PrintSelf(ostream &os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  os << indent << "EndTime: " << this->EndTime << "\n";
  os << indent << "OutputInterval: " << this->OutputInterval << "\n";
  os << indent << "StateIndex: " << this->StateIndex << "\n";
  os << indent << "RestartCount: " << this->RestartCount << "\n";
}
