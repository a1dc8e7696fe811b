#include "vtkGraupelObjectsSimulation.h"

#include "vtkAlgorithmOutput.h"
#include "vtkDemandDrivenPipeline.h"
#include "vtkGraupelMotion.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkPolyData.h"

#include "GraupelObjects.h"

#include <string>

vtkGraupelObjectsSimulation::vtkGraupelObjectsSimulation(size_t maxObjects, bool mergePoints,
                                                         int closed)
    : MaxObjects(maxObjects), MergePoints(mergePoints), ClosedObjects(closed) {
  this->SetNumberOfInputPorts(3);
  // Objects with time steps are read in time; others stand or are posed by the properties.
  this->SetInputPortPolicy(1, TEMPORAL_INPUT);
}

vtkGraupelObjectsSimulation::~vtkGraupelObjectsSimulation() = default;

void vtkGraupelObjectsSimulation::SetObjectsConnection(vtkAlgorithmOutput *output) {
  this->SetInputConnection(1, output);
}

void vtkGraupelObjectsSimulation::SetPathConnection(vtkAlgorithmOutput *output) {
  this->SetInputConnection(2, output);
}

int vtkGraupelObjectsSimulation::FillInputPortInformation(int port, vtkInformation *info) {
  if (port == 0) {
    info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkImageData");
    return 1;
  }
  // A multiblock is taken whole (one object per leaf): a composite pipeline
  // would otherwise run the filter once per block.
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPolyData");
  if (port == 1) {
    info->Append(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkMultiBlockDataSet");
  }
  info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
  return 1;
}

vtkTypeBool vtkGraupelObjectsSimulation::ProcessRequest(vtkInformation *request,
                                                        vtkInformationVector **inInfo,
                                                        vtkInformationVector *outInfo) {
  if (request->Has(vtkDemandDrivenPipeline::REQUEST_DATA_OBJECT())) {
    graupel::MatchObjectsOutput(inInfo, outInfo, 1);
  }
  return this->Superclass::ProcessRequest(request, inInfo, outInfo);
}

int vtkGraupelObjectsSimulation::CheckObjectMotion() {
  return this->ReportError(
      vtkGraupelMotion::CheckObjectMotion(this->GetSimulationLabel(), this->ObjectVelocity,
                                          this->ObjectAngularVelocity, this->RotationAxis));
}

int vtkGraupelObjectsSimulation::ReadObjectInputs(vtkInformationVector **inputVector) {
  vtkPolyData *path =
      this->GetNumberOfInputConnections(2) ? vtkPolyData::GetData(inputVector[2]) : nullptr;
  if (!this->ReportError(
          vtkGraupelMotion::ReadPath(this->GetSimulationLabel(), path, this->Path)) ||
      !this->ReadObjects(this->GetNumberOfInputConnections(1)
                             ? vtkDataObject::GetData(inputVector[1])
                             : nullptr)) {
    return 0;
  }
  this->ObjectsReadAt = this->GetTemporalInputTime(1);
  return 1;
}

int vtkGraupelObjectsSimulation::ReadObjects(vtkDataObject *objects) {
  return this->ReportError(graupel::ReadObjects(
      this->GetSimulationLabel(), objects, this->MaxObjects, this->ObjectVelocity,
      this->MergePoints ? graupel::Vertices::Merged : graupel::Vertices::PerPoint,
      this->ClosedObjects, this->IsInputTemporal(1), this->Path, this->Objects,
      this->ObjectsTemporal));
}

void vtkGraupelObjectsSimulation::Pose(size_t k, double t, double m[16]) const {
  graupel::PoseObject(this->Objects[k], this->ObjectsTemporal, this->ObjectAngularVelocity,
                      this->RotationAxis, this->Path, t, m);
}

int vtkGraupelObjectsSimulation::FillObjectOutputs() {
  if (!this->OutputVector) {
    return 1;
  }
  if (graupel::RequestedPiece(this->OutputVector->GetInformationObject(1)) == 0) {
    for (int port = 1; port < this->GetNumberOfOutputPorts(); ++port) {
      vtkDataObject *output =
          this->OutputVector->GetInformationObject(port)->Get(vtkDataObject::DATA_OBJECT());
      if (!this->FillObjectOutput(port, output, this->GetStateTime())) {
        return 0;
      }
    }
  }
  this->OutputsFilled = true;
  return 1;
}

void vtkGraupelObjectsSimulation::PrintObjectMotion(ostream &os, vtkIndent indent) {
  os << indent << "ObjectVelocity: " << this->ObjectVelocity[0] << " " << this->ObjectVelocity[1]
     << " " << this->ObjectVelocity[2] << " m/s\n";
  os << indent << "ObjectAngularVelocity: " << this->ObjectAngularVelocity << " deg/s\n";
  os << indent << "RotationAxis: " << this->RotationAxis[0] << " " << this->RotationAxis[1] << " "
     << this->RotationAxis[2] << "\n";
}

void vtkGraupelObjectsSimulation::PrintSelf(ostream &os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
}
