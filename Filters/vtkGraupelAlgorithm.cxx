#include "vtkGraupelAlgorithm.h"

#include "GraupelRanges.h"

#include "vtkDataObject.h"
#include "vtkDemandDrivenPipeline.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkLogger.h"
#include "vtkNew.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStringArray.h"

#include "graupel/runtime.h"

#include "GraupelPieces.h"

#include <cctype>
#include <cmath>
#include <cstring>
#include <sstream>
#include <string>

namespace {
void LogFromCore(void *, gr_log_level level, const char *message) {
  if (level == GR_LOG_WARNING) {
    vtkLog(WARNING, << message);
  } else {
    vtkLog(INFO, << message);
  }
}
} // namespace

vtkGraupelAlgorithm::vtkGraupelAlgorithm() {
  this->SetNumberOfInputPorts(1);
  this->SetNumberOfOutputPorts(1);
  this->SetDevice("auto");
}

vtkGraupelAlgorithm::~vtkGraupelAlgorithm() {
  gr_context_release(this->Context);
  delete[] this->Device;
}

void vtkGraupelAlgorithm::SetDevice(const char *device) {
  const char *value = (device && *device) ? device : "auto";
  if (this->Device && std::strcmp(this->Device, value) == 0) {
    return;
  }
  delete[] this->Device;
  this->Device = new char[std::strlen(value) + 1];
  std::strcpy(this->Device, value);
  // The next update acquires the context of the newly chosen device.
  gr_context_release(this->Context);
  this->Context = nullptr;
  this->Modified();
}

const char *vtkGraupelAlgorithm::GetDeviceName() const {
  return this->Context ? gr_context_device_name(this->Context) : "";
}

vtkTypeInt64 vtkGraupelAlgorithm::GetDeviceMaxBufferBytes() {
  gr_device_info info;
  gr_context *ctx = this->GetContext();
  if (!ctx || gr_context_device_info(ctx, &info) != GR_OK) {
    return 0;
  }
  return static_cast<vtkTypeInt64>(info.max_alloc_bytes);
}

gr_context *vtkGraupelAlgorithm::GetContext() {
  if (!this->Context) {
    gr_context_options opt;
    gr_context_options_init(&opt);
    // One device per local rank of an MPI run (gpu:N); the Device itself otherwise.
    const std::string request = graupel::RankDeviceRequest(this->Device);
    opt.device = request.c_str();
    opt.log = LogFromCore;
    if (gr_context_acquire(&opt, &this->Context) != GR_OK) {
      vtkErrorMacro("No OpenCL device for " << this->GetClassName() << ": "
                                            << gr_last_error(nullptr));
      this->Context = nullptr;
    }
  }
  return this->Context;
}

int vtkGraupelAlgorithm::ReportFailure(int status, const char *what, const char *detail) {
  if (!detail || !*detail) {
    detail = gr_last_error(this->Context);
  }
  vtkErrorMacro(<< what << ": " << (detail && *detail ? detail : "") << " ["
                << gr_status_string(static_cast<gr_status>(status)) << "]");
  return 0;
}

void vtkGraupelAlgorithm::NoteSetting(const char *property, double value, double used,
                                      double current, const char *unit, double min, double max) {
  if (value == used || (std::isnan(value) && std::isnan(used))) {
    if (used != current) {
      this->Clamped.erase(property); // a new value in range
    }
    return;
  }
  const std::string u = unit && *unit ? std::string(" ") + unit : std::string();
  std::ostringstream msg;
  msg << property << " must be from " << min << " to " << max << u << "; it was set to " << value
      << u << ", so " << used << u << " is used. Set it within that range.";
  this->Clamped[property] = {msg.str(), false, used};
}

std::string vtkGraupelAlgorithm::Label() const {
  std::string name = this->GetClassName();
  if (name.rfind("vtk", 0) == 0) {
    name = name.substr(3);
  }
  for (const char *suffix : {"Filter", "Source"}) {
    const size_t n = strlen(suffix);
    if (name.size() > n && name.compare(name.size() - n, n, suffix) == 0) {
      name.resize(name.size() - n);
    }
  }
  std::string label;
  for (size_t i = 0; i < name.size(); ++i) {
    if (i > 0 && isupper(static_cast<unsigned char>(name[i]))) {
      label += ' ';
    }
    label += name[i];
  }
  return label;
}

int vtkGraupelAlgorithm::ReportError(const std::string &sentence) {
  if (sentence.empty()) {
    return 1;
  }
  vtkErrorMacro(<< sentence);
  return 0;
}

bool vtkGraupelAlgorithm::AbortRequested(const char *label, bool started) {
  if (!this->GetAbortExecute()) {
    return false;
  }
  if (started) {
    vtkWarningMacro(<< label << ": the update was aborted; the output is empty.");
  }
#if GRAUPEL_VTK_ABORT_OUTPUT
  // Consumed, and the output marked aborted: the executive empties it and
  // the next request computes again.
  this->AbortExecute = 0;
  this->SetAbortOutput(true);
#else
  this->SetAbortExecute(0);
  this->Modified();
#endif
  return true;
}

void vtkGraupelAlgorithm::AddDeviceFieldData(vtkDataObject *output) {
  vtkNew<vtkStringArray> device;
  device->SetName("graupel_device");
  device->InsertNextValue(this->GetDeviceName());
  output->GetFieldData()->AddArray(device);
}

vtkDataObject *vtkGraupelAlgorithm::GetOutput() {
  return this->GetOutput(0);
}

vtkDataObject *vtkGraupelAlgorithm::GetOutput(int port) {
  return this->GetOutputDataObject(port);
}

int vtkGraupelAlgorithm::FillInputPortInformation(int, vtkInformation *info) {
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkImageData");
  return 1;
}

int vtkGraupelAlgorithm::FillOutputPortInformation(int, vtkInformation *info) {
  info->Set(vtkDataObject::DATA_TYPE_NAME(), "vtkImageData");
  return 1;
}

void vtkGraupelAlgorithm::EmptyOutputs(vtkInformationVector *outInfo) {
  for (int i = 0; i < outInfo->GetNumberOfInformationObjects(); ++i) {
    vtkInformation *info = outInfo->GetInformationObject(i);
    vtkDataObject *data = info->Get(vtkDataObject::DATA_OBJECT());
    if (!data) {
      continue;
    }
    data->Initialize();
    // Stamped with the requested time, the empty output answers that request:
    // the executive does not run the filter again (and repeat its error)
    // until a property, an input or the time changes.
    if (info->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP())) {
      data->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(),
                                  info->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP()));
    }
  }
}

vtkTypeBool vtkGraupelAlgorithm::ProcessRequest(vtkInformation *request,
                                                vtkInformationVector **inInfo,
                                                vtkInformationVector *outInfo) {
  if (request->Has(vtkDemandDrivenPipeline::REQUEST_INFORMATION())) {
    this->InformationFailed = !this->RequestInformation(request, inInfo, outInfo);
    if (this->InformationFailed) {
      // Said why already; an empty extent lets the data pass go through quietly.
      static const int empty[6] = {0, -1, 0, -1, 0, -1};
      for (int i = 0; i < outInfo->GetNumberOfInformationObjects(); ++i) {
        outInfo->GetInformationObject(i)->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(),
                                              empty, 6);
      }
    }
    return 1;
  }
  if (request->Has(vtkStreamingDemandDrivenPipeline::REQUEST_UPDATE_EXTENT())) {
    return this->InformationFailed ? 1 : this->RequestUpdateExtent(request, inInfo, outInfo);
  }
  if (request->Has(vtkDemandDrivenPipeline::REQUEST_DATA())) {
    for (auto &note : this->Clamped) {
      if (!note.second.said) {
        vtkWarningMacro(<< this->Label() << ": " << note.second.sentence);
        note.second.said = true;
      }
    }
    if (this->InformationFailed || !this->RequestData(request, inInfo, outInfo)) {
      // The sentence was reported where the failure happened; see the header
      // for why this is not returned as 0.
      this->EmptyOutputs(outInfo);
    } else if (vtkDataObject *out = outInfo->GetNumberOfInformationObjects() > 0
                                        ? vtkDataObject::GetData(outInfo, 0)
                                        : nullptr) {
      for (const auto &note : this->Clamped) {
        vtkNew<vtkDoubleArray> used;
        used->SetName(("graupel_used_" + note.first).c_str());
        used->InsertNextValue(note.second.used);
        out->GetFieldData()->AddArray(used);
      }
      // The CRS a GIS raster brought (vtkGISRasterReader) goes on with the
      // data, for vtkGeoTIFFWriter to write it back.
      vtkDataObject *in =
          this->GetNumberOfInputPorts() > 0 && inInfo[0]->GetNumberOfInformationObjects() > 0
              ? vtkDataObject::GetData(inInfo[0], 0)
              : nullptr;
      vtkAbstractArray *crs = in ? in->GetFieldData()->GetAbstractArray("graupel_crs") : nullptr;
      for (int i = 0; i < outInfo->GetNumberOfInformationObjects(); ++i) {
        vtkDataObject *data = vtkDataObject::GetData(outInfo, i);
        graupel::CacheRanges(data);
        if (crs && data && !data->GetFieldData()->GetAbstractArray("graupel_crs")) {
          data->GetFieldData()->AddArray(crs);
        }
      }
    }
    return 1;
  }
  return this->Superclass::ProcessRequest(request, inInfo, outInfo);
}

void vtkGraupelAlgorithm::PrintSelf(ostream &os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Device: " << (this->Device ? this->Device : "(none)") << "\n";
  os << indent << "DeviceName: " << this->GetDeviceName() << "\n";
}
