#include "pqGraupelApplyLook.h"

#include "pqApplicationCore.h"
#include "pqDataRepresentation.h"
#include "pqOutputPort.h"
#include "pqPipelineFilter.h"
#include "pqPipelineSource.h"
#include "pqProgressManager.h"
#include "pqRenderView.h"
#include "pqServer.h"
#include "pqServerManagerModel.h"
#include "vtkPVDataInformation.h"
#include "vtkPVXMLElement.h"
#include "vtkSMPVRepresentationProxy.h"
#include "vtkSMParaViewPipelineControllerWithRendering.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxySelectionModel.h"
#include "vtkSMRenderViewProxy.h"
#include "vtkSMSessionProxyManager.h"
#include "vtkSMSourceProxy.h"
#include "vtkSMTransferFunctionProxy.h"
#include "vtkSmartPointer.h"

#include <QTimer>

#include <algorithm>
#include <cstring>

namespace {
bool WantsSurface(vtkSMProxy *proxy) {
  vtkPVXMLElement *hints = proxy ? proxy->GetHints() : nullptr;
  return hints && hints->FindNestedElementByName("GraupelSurface");
}

bool IsTerrainSurface(pqPipelineSource *source) {
  vtkSMProxy *proxy = source ? source->getProxy() : nullptr;
  return proxy && proxy->GetXMLName() && strcmp(proxy->GetXMLName(), "TerrainSurface") == 0;
}

// The render view that shows `source`'s image: where Apply put it.
pqRenderView *ShownIn(pqPipelineSource *source) {
  pqOutputPort *port = source->getOutputPort(0);
  for (pqView *view : port ? port->getViews() : QList<pqView *>()) {
    auto *rview = qobject_cast<pqRenderView *>(view);
    pqDataRepresentation *repr = rview ? port->getRepresentation(rview) : nullptr;
    if (repr && repr->isVisible()) {
      return rview;
    }
  }
  return nullptr;
}

// From the south-east and above, as the example scenes look
// (Examples/graupel_scene.py, _camera): the direction set, the distance
// fitted to the bounds, then 1.3 times closer.
void LookAt(vtkSMRenderViewProxy *view, const double b[6]) {
  const double cx = 0.5 * (b[0] + b[1]), cy = 0.5 * (b[2] + b[3]);
  const double span = std::max(b[1] - b[0], b[3] - b[2]);
  const double focal[3] = {cx, cy, 0.5 * (b[4] + b[5])};
  const double position[3] = {cx + 0.9 * span, cy - 1.1 * span, b[5] + 0.9 * span};
  const double up[3] = {0, 0, 1};
  vtkSMPropertyHelper(view, "CameraFocalPoint").Set(focal, 3);
  vtkSMPropertyHelper(view, "CameraPosition").Set(position, 3);
  vtkSMPropertyHelper(view, "CameraViewUp").Set(up, 3);
  view->UpdateVTKObjects();
  double bounds[6] = {b[0], b[1], b[2], b[3], b[4], b[5]};
  view->ResetCamera(bounds);
  view->SynchronizeCameraProperties();
  double fitted[3], at[3];
  vtkSMPropertyHelper(view, "CameraPosition").Get(fitted, 3);
  vtkSMPropertyHelper(view, "CameraFocalPoint").Get(at, 3);
  for (int i = 0; i < 3; ++i) {
    fitted[i] = at[i] + (fitted[i] - at[i]) / 1.3;
  }
  vtkSMPropertyHelper(view, "CameraPosition").Set(fitted, 3);
  view->UpdateVTKObjects();
}
} // namespace

const char *pqGraupelApplyLook::legendTitle(const char *array) {
  // The same titles as Examples/graupel_scene.py's TITLES.
  static const char *const titles[][2] = {
      {"elevation", "elevation (m)"},
      {"water_depth", "water depth (m)"},
      {"water_depth_display", "water depth (m)"},
      {"max_depth", "largest water depth (m)"},
      {"snow_depth", "snow depth (m)"},
      {"snow_density", "snow density (kg/m\xc2\xb3)"},
      {"cover_class", "cover"},
      {"shadow", "sunlight (0 shadow, 1 sun)"},
      {"wave_height", "wave height (m)"},
  };
  for (const auto &t : titles) {
    if (array && strcmp(array, t[0]) == 0) {
      return t[1];
    }
  }
  return array;
}

pqGraupelApplyLook::pqGraupelApplyLook(QObject *p) : Superclass(p) {}

void pqGraupelApplyLook::onStartup() {
  pqApplicationCore *core = pqApplicationCore::instance();
  pqServerManagerModel *smm = core->getServerManagerModel();
  pqProgressManager *pm = core->getProgressManager();
  if (!smm || !pm) {
    return;
  }
  QObject::connect(pm, &pqProgressManager::progressStartEvent, this,
                   [this]() { this->Updating = true; });
  QObject::connect(pm, &pqProgressManager::progressEndEvent, this,
                   [this]() { this->Updating = false; });
  QObject::connect(smm, &pqServerManagerModel::sourceAdded, this,
                   [this](pqPipelineSource *source) { this->onSourceAdded(source); });
  QObject::connect(smm, &pqServerManagerModel::sourceRemoved, this,
                   [this](pqPipelineSource *source) { this->Pending.remove(source); });
}

void pqGraupelApplyLook::onSourceAdded(pqPipelineSource *source) {
  if (!source || !WantsSurface(source->getProxy())) {
    return;
  }
  QObject::connect(source, &pqProxy::modifiedStateChanged, this,
                   [this, source]() { this->onModifiedStateChanged(source); });
}

void pqGraupelApplyLook::onModifiedStateChanged(pqPipelineSource *source) {
  // pqObjectBuilder marks a source made from a menu UNINITIALIZED just after
  // it is registered; pqApplyBehavior marks it UNMODIFIED on its first Apply,
  // after showing it.
  if (source->modifiedState() == pqProxy::UNINITIALIZED) {
    this->Pending.insert(source);
  } else if (source->modifiedState() == pqProxy::UNMODIFIED && this->Pending.remove(source)) {
    QPointer<pqPipelineSource> later(source);
    QTimer::singleShot(0, this, [this, later]() { this->showSurfaceLater(later, 1200); });
  }
}

void pqGraupelApplyLook::showSurfaceLater(QPointer<pqPipelineSource> source, int tries) {
  if (!source) {
    return;
  }
  if (this->Updating) {
    // Inside an update (Qt processes events there for the abort button):
    // wait for it to end, for at most a minute.
    if (tries > 0) {
      QTimer::singleShot(50, this,
                         [this, source, tries]() { this->showSurfaceLater(source, tries - 1); });
    }
    return;
  }
  this->showSurface(source);
}

void pqGraupelApplyLook::showSurface(pqPipelineSource *source) {
  pqRenderView *view = ShownIn(source);
  pqServer *server = source->getServer();
  if (!view || !server) {
    return; // shown elsewhere (a spreadsheet) or not at all: leave it so
  }
  vtkSMSessionProxyManager *pxm = server->proxyManager();
  vtkSmartPointer<vtkSMProxy> surface;
  surface.TakeReference(pxm->NewProxy("filters", "TerrainSurface"));
  auto *surfaceSource = vtkSMSourceProxy::SafeDownCast(surface);
  if (!surfaceSource) {
    return;
  }
  vtkNew<vtkSMParaViewPipelineControllerWithRendering> controller;
  controller->PreInitializeProxy(surface);
  vtkSMPropertyHelper(surface, "Input").Set(source->getProxy(), 0);
  controller->PostInitializeProxy(surface);
  // Registering makes the surface the active source; the user's source
  // stays active instead: its panel stays open and the Filters menu (Rain
  // Runoff below a terrain) applies to its image, not to the surface.
  controller->RegisterPipelineProxy(surface);
  if (vtkSMProxySelectionModel *active = pxm->GetSelectionModel("ActiveSources")) {
    active->SetCurrentProxy(source->getProxy(), vtkSMProxySelectionModel::CLEAR_AND_SELECT);
  }

  vtkSMViewProxy *viewProxy = view->getViewProxy();
  vtkSMProxy *repr = controller->Show(surfaceSource, 0, viewProxy);
  if (!repr) {
    return;
  }
  // The flat image, and the surfaces of this output's inputs (as ParaView
  // hides a filter's input): one surface, not two drawn in one place.
  controller->Hide(vtkSMSourceProxy::SafeDownCast(source->getProxy()), 0, viewProxy);
  if (auto *filter = qobject_cast<pqPipelineFilter *>(source)) {
    for (pqOutputPort *input : filter->getAllInputs()) {
      for (pqPipelineSource *sibling : input->getConsumers()) {
        if (IsTerrainSurface(sibling)) {
          controller->Hide(vtkSMSourceProxy::SafeDownCast(sibling->getProxy()), 0, viewProxy);
        }
      }
    }
  }

  if (vtkSMPVRepresentationProxy::GetUsingScalarColoring(repr)) {
    vtkSMPVRepresentationProxy::SetScalarBarVisibility(repr, viewProxy, true);
    const char *array = vtkSMPropertyHelper(repr, "ColorArrayName").GetInputArrayNameToProcess();
    vtkSMProxy *lut = vtkSMPropertyHelper(repr, "LookupTable", true).GetAsProxy();
    if (vtkSMProxy *bar = vtkSMTransferFunctionProxy::FindScalarBarRepresentation(lut, viewProxy)) {
      vtkSMPropertyHelper(bar, "Title").Set(legendTitle(array));
      vtkSMPropertyHelper(bar, "ComponentTitle").Set("");
      bar->UpdateVTKObjects();
    }
  }
  if (view->getNumberOfVisibleDataRepresentations() == 1) {
    double bounds[6];
    surfaceSource->GetDataInformation(0)->GetBounds(bounds);
    if (bounds[0] <= bounds[1]) {
      LookAt(view->getRenderViewProxy(), bounds);
    }
  }
  view->render();
}
