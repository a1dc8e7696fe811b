#include "vtkGraupelAlgorithm.h"

#include "GraupelRanges.h"
#include "GraupelRemoteAbort.h"
#include "GraupelTerrain.h"
#include "vtkImageData.h"
#include "vtkPointData.h"

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

namespace {
// The name of the array the heights come from.
std::string HeightsName(vtkImageData *terrain, const graupel::HeightsChoice &choice) {
  int association = 0;
  vtkDataArray *a = graupel::FindHeights(terrain, choice, &association, nullptr);
  return a && a->GetName() ? a->GetName() : "elevation";
}
} // namespace

struct vtkGraupelAlgorithm::TerrainViews {
  std::vector<graupel::TerrainView> ports;
  // The last refusal and the last warning, said once: what they were about.
  std::string failedKey, warnedKey;
  // The Height Array that holds for the Input of the running update.
  graupel::HeightsChoice effective;
};

vtkGraupelAlgorithm::~vtkGraupelAlgorithm() {
  delete this->Views;
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

bool vtkGraupelAlgorithm::SendRemoteAbort(vtkMultiProcessController *toServer) {
  return graupel::SendRemoteAbort(toServer);
}

void vtkGraupelAlgorithm::SetRemoteClientLookup(vtkMultiProcessController *(*lookup)()) {
  graupel::SetClientLookup(lookup);
}

void vtkGraupelAlgorithm::BeginRemoteRequest() {
  graupel::BeginRemoteRequest();
}

void vtkGraupelAlgorithm::EndRemoteRequest() {
  graupel::EndRemoteRequest();
}

bool vtkGraupelAlgorithm::AbortRequested(const char *label, bool started) {
  // A band-wise update has no time of its own: the abort holds for this algorithm.
  if (graupel::RemoteAbortAsked(this, 0.0, !started)) {
    this->SetAbortExecute(1);
  }
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
    const int port = this->GetTerrainPort();
    bool imageOut = false;
    for (int i = 0; i < this->GetNumberOfOutputPorts(); ++i) {
      vtkInformation *p = this->GetOutputPortInformation(i);
      imageOut =
          imageOut || (p->Has(vtkDataObject::DATA_TYPE_NAME()) &&
                       std::strcmp(p->Get(vtkDataObject::DATA_TYPE_NAME()), "vtkImageData") == 0);
    }
    // Heights in cells: the outputs are the cells' centres (GraupelTerrain.h).
    this->TerrainCells =
        !this->InformationFailed && imageOut && port >= 0 && graupel::HeightsAreCells(this, port);
    if (this->TerrainCells) {
      graupel::CellCentreInformation(inInfo[port]->GetInformationObject(0), outInfo);
    }
    // Graupel's images are point data: a filter after this one need not run
    // it to learn where its heights are (HeightsAreCells).
    for (int i = 0; imageOut && !this->InformationFailed && i < this->GetNumberOfOutputPorts();
         ++i) {
      vtkInformation *p = this->GetOutputPortInformation(i);
      if (p->Has(vtkDataObject::DATA_TYPE_NAME()) &&
          std::strcmp(p->Get(vtkDataObject::DATA_TYPE_NAME()), "vtkImageData") == 0) {
        vtkDataObject::SetPointDataActiveScalarInfo(outInfo->GetInformationObject(i), VTK_FLOAT, 1);
      }
    }
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
    std::vector<std::pair<vtkInformation *, vtkSmartPointer<vtkDataObject>>> restore;
    const bool viewed = !this->InformationFailed && this->SwapInViews(inInfo, restore);
    if (this->InformationFailed || !viewed || !this->RequestData(request, inInfo, outInfo)) {
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
    for (auto &r : restore) {
      r.first->Set(vtkDataObject::DATA_OBJECT(), r.second);
    }
    return 1;
  }
  return this->Superclass::ProcessRequest(request, inInfo, outInfo);
}

vtkDataArray *vtkGraupelAlgorithm::TerrainHeights(vtkImageData *terrain, std::string *why) {
  const int port = this->GetTerrainPort();
  if (terrain && this->Views && port >= 0 &&
      static_cast<size_t>(port) < this->Views->ports.size() &&
      this->Views->ports[static_cast<size_t>(port)].Current() == terrain) {
    return terrain->GetPointData()->GetArray("elevation");
  }
  int association = vtkDataObject::FIELD_ASSOCIATION_POINTS;
  bool replaced = false;
  const graupel::HeightsChoice choice =
      this->Views ? this->Views->effective
                  : graupel::EffectiveHeights(terrain, graupel::ChosenHeights(this), &replaced);
  vtkDataArray *a = graupel::FindHeights(terrain, choice, &association, why);
  if (a && association != vtkDataObject::FIELD_ASSOCIATION_POINTS) {
    if (why) {
      *why = "holds its heights as cell data where points were expected";
    }
    return nullptr;
  }
  return a;
}

bool vtkGraupelAlgorithm::SwapInViews(
    vtkInformationVector **inInfo,
    std::vector<std::pair<vtkInformation *, vtkSmartPointer<vtkDataObject>>> &restore) {
  const int port = this->GetTerrainPort();
  vtkInformation *info = port >= 0 && this->GetNumberOfInputConnections(port) > 0
                             ? inInfo[port]->GetInformationObject(0)
                             : nullptr;
  auto *terrain = info ? vtkImageData::GetData(info) : nullptr;
  if (!terrain) {
    return true;
  }
  if (!this->Views) {
    this->Views = new TerrainViews;
  }
  this->Views->ports.resize(static_cast<size_t>(this->GetNumberOfInputPorts()));
  auto put = [&](vtkInformation *where, vtkImageData *original, vtkImageData *view) {
    if (view != original) {
      restore.emplace_back(where, original);
      where->Set(vtkDataObject::DATA_OBJECT(), view);
    }
  };
  bool replaced = false;
  const graupel::HeightsChoice chosen = graupel::ChosenHeights(this);
  const graupel::HeightsChoice choice = graupel::EffectiveHeights(terrain, chosen, &replaced);
  this->Views->effective = choice;
  // A refusal is said once while this filter's settings stay (ParaView asks
  // for the same output several times, and some readers run again each time).
  auto refuse = [&](const std::string &sentence) {
    const std::string key = std::to_string(this->GetMTime()) + ' ' + sentence;
    if (this->Views->failedKey != key) {
      this->Views->failedKey = key;
      this->ReportError(sentence);
    }
    return false;
  };
  int association = vtkDataObject::FIELD_ASSOCIATION_POINTS;
  if (replaced && graupel::FindHeights(terrain, choice, &association, nullptr)) {
    // ParaView keeps a Height Array when the Input changes: said once.
    const std::string sentence = this->Label() + ": the Input has no array '" + chosen.name +
                                 "' (its Height Array); its heights are taken from '" +
                                 HeightsName(terrain, choice) + "' instead.";
    if (this->Views->warnedKey != std::to_string(this->GetMTime()) + sentence) {
      this->Views->warnedKey = std::to_string(this->GetMTime()) + sentence;
      vtkWarningMacro(<< sentence);
    }
  }
  std::string error;
  vtkImageData *view = this->Views->ports[static_cast<size_t>(port)].Get(
      terrain, choice, this->Label(), "Input", &error);
  if (!view) {
    return refuse(error);
  }
  this->Views->failedKey.clear();
  const bool cells = view != terrain && view->GetNumberOfPoints() != terrain->GetNumberOfPoints();
  if (cells != this->TerrainCells && association >= 0 &&
      graupel::FindHeights(terrain, choice, &association, nullptr)) {
    // The input's arrays changed kind after this filter's information pass
    // (its extent was announced for the other kind): the next update sees them.
    this->Modified();
    this->ReportError(this->Label() + "'s Input now holds its heights as " +
                      (cells ? "cell" : "point") +
                      " data, which it did not when its extent was announced; update it again.");
    return false;
  }
  put(info, terrain, view);
  int dims[3];
  terrain->GetDimensions(dims);
  for (int p = 0; cells && p < this->GetNumberOfInputPorts(); ++p) {
    for (int c = 0; p != port && c < this->GetNumberOfInputConnections(p); ++c) {
      vtkInformation *other = inInfo[p]->GetInformationObject(c);
      auto *image = vtkImageData::GetData(other);
      if (image && c == 0) {
        put(other, image, this->Views->ports[static_cast<size_t>(p)].Other(image, dims));
      }
    }
  }
  return true;
}

void vtkGraupelAlgorithm::PrintSelf(ostream &os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Device: " << (this->Device ? this->Device : "(none)") << "\n";
  os << indent << "DeviceName: " << this->GetDeviceName() << "\n";
}
