#include "vtkGraupelAlgorithm.h"

#include "vtkDataObject.h"
#include "vtkFieldData.h"
#include "vtkLogger.h"
#include "vtkNew.h"
#include "vtkStringArray.h"

#include "graupel/runtime.h"

#include <cstring>
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
    opt.device = this->Device;
    opt.log = LogFromCore;
    if (gr_context_acquire(&opt, &this->Context) != GR_OK) {
      vtkErrorMacro("No OpenCL device for " << this->GetClassName() << ": "
                                            << gr_last_error(nullptr));
      this->Context = nullptr;
    }
  }
  return this->Context;
}

int vtkGraupelAlgorithm::ReportFailure(int status, const char *what) {
  const char *detail = gr_last_error(this->Context);
  vtkErrorMacro(<< what << ": " << (detail && *detail ? detail : "") << " ["
                << gr_status_string(static_cast<gr_status>(status)) << "]");
  return 0;
}

void vtkGraupelAlgorithm::AddDeviceFieldData(vtkDataObject *output) {
  vtkNew<vtkStringArray> device;
  device->SetName("graupel_device");
  device->InsertNextValue(this->GetDeviceName());
  output->GetFieldData()->AddArray(device);
}

void vtkGraupelAlgorithm::PrintSelf(ostream &os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Device: " << (this->Device ? this->Device : "(none)") << "\n";
  os << indent << "DeviceName: " << this->GetDeviceName() << "\n";
}
