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
#include "pqRepresentation.h"
#include "pqView.h"
#include "vtkPVArrayInformation.h"
#include "vtkPVDataInformation.h"
#include "vtkPVDataSetAttributesInformation.h"
#include "vtkPVXMLElement.h"
#include "vtkSMPVRepresentationProxy.h"
#include "vtkSMProperty.h"
#include "vtkSMParaViewPipelineControllerWithRendering.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxySelectionModel.h"
#include "vtkSMRenderViewProxy.h"
#include "vtkSMSessionProxyManager.h"
#include "vtkSMSourceProxy.h"
#include "vtkSMTransferFunctionProxy.h"
#include "vtkSmartPointer.h"
#include "vtkSMViewProxy.h"

#include <QTimer>

#include <cmath>

#include <algorithm>
#include <cstring>

namespace {
bool WantsSurface(vtkSMProxy *proxy) {
  vtkPVXMLElement *hints = proxy ? proxy->GetHints() : nullptr;
  return hints && hints->FindNestedElementByName("GraupelSurface");
}

// A proxy of the plugin: its menu category is Graupel.
bool IsGraupel(vtkSMProxy *proxy) {
  vtkPVXMLElement *hints = proxy ? proxy->GetHints() : nullptr;
  vtkPVXMLElement *menu = hints ? hints->FindNestedElementByName("ShowInMenu") : nullptr;
  const char *category = menu ? menu->GetAttribute("category") : nullptr;
  return category && strcmp(category, "Graupel") == 0;
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

// The x and y bounds of a port's data; empty when it has no points.
QVector<double> Extent(pqOutputPort *port) {
  vtkPVDataInformation *info = port ? port->getDataInformation() : nullptr;
  if (!info || info->GetNumberOfPoints() <= 0) {
    return QVector<double>();
  }
  double b[6];
  info->GetBounds(b);
  return QVector<double>{b[0], b[1], b[2], b[3]};
}

// Whether two x-y extents differ by more than 1 % of the larger span.
bool ExtentChanged(const QVector<double> &a, const QVector<double> &b) {
  if (a.size() != 4 || b.size() != 4) {
    return a.size() != b.size();
  }
  const double span = std::max({a[1] - a[0], a[3] - a[2], b[1] - b[0], b[3] - b[2]});
  for (int i = 0; i < 4; ++i) {
    if (std::fabs(a[i] - b[i]) > 0.01 * span) {
      return true;
    }
  }
  return false;
}

// The legend's title: the array's name in words and units, and the
// vertical exaggeration where the heights are not drawn true.
QString LegendTitle(const char *array, double exaggeration) {
  QString title = QString::fromUtf8(pqGraupelApplyLook::legendTitle(array));
  if (exaggeration != 1.0) {
    title += QString::fromUtf8(", heights \xc3\x97") + QString::number(exaggeration, 'g', 3);
  }
  return title;
}

// Rain Runoff's Hydrograph columns in a line chart: label, shown by
// default, on the right axis (the volumes, m^3).
struct HydrographSeries {
  const char *name, *label;
  bool shown, right;
};
const HydrographSeries Hydrograph[] = {
    {"rain_volume_rate", "rain", true, false},
    {"inflow_rate", "inflow through the edges", true, false},
    {"infiltration_rate", "infiltration", true, false},
    {"outflow_rate", "outflow", true, false},
    {"stored_volume", "stored (m\xc2\xb3)", false, true},
    {"outflow_volume", "outflow so far (m\xc2\xb3)", false, true},
    {"balance_error", "balance error (m\xc2\xb3)", false, true},
    {"time", "time", false, false},
};
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
                   [this](pqPipelineSource *source) {
                     this->Pending.remove(source);
                     this->Waiting.remove(source);
                     this->Extents.remove(source);
                   });
  // A representation joins its view after it is registered: the view's
  // signal is the one that knows both.
  QObject::connect(smm, &pqServerManagerModel::viewAdded, this, [this](pqView *view) {
    QObject::connect(view, &pqView::representationAdded, this,
                     [this](pqRepresentation *repr) { this->onRepresentationAdded(repr); });
  });
}

void pqGraupelApplyLook::onSourceAdded(pqPipelineSource *source) {
  if (!source || !IsGraupel(source->getProxy())) {
    return;
  }
  QObject::connect(source, QOverload<pqPipelineSource *>::of(&pqPipelineSource::dataUpdated), this,
                   [this](pqPipelineSource *updated) { this->onDataUpdated(updated); });
  if (WantsSurface(source->getProxy())) {
    QObject::connect(source, &pqProxy::modifiedStateChanged, this,
                     [this, source]() { this->onModifiedStateChanged(source); });
  }
}

void pqGraupelApplyLook::showUsedValues(pqPipelineSource *source) {
  // A value the filter moved into its range (it warned once): the panel
  // shows the value used, which the output's field data carries as
  // graupel_used_<property> (vtkGraupelAlgorithm::NoteSetting).
  pqOutputPort *port = source->getOutputPort(0);
  vtkPVDataInformation *info = port ? port->getDataInformation() : nullptr;
  vtkPVDataSetAttributesInformation *fields = info ? info->GetFieldDataInformation() : nullptr;
  vtkSMProxy *proxy = source->getProxy();
  bool changed = false;
  for (int i = 0; fields && i < fields->GetNumberOfArrays(); ++i) {
    vtkPVArrayInformation *array = fields->GetArrayInformation(i);
    const char *name = array ? array->GetName() : nullptr;
    const size_t prefix = strlen("graupel_used_");
    if (!name || strncmp(name, "graupel_used_", prefix) != 0) {
      continue;
    }
    vtkSMProperty *property = proxy->GetProperty(name + prefix);
    if (!property || property->GetInformationOnly()) {
      continue;
    }
    const double used = array->GetComponentRange(0)[0];
    vtkSMPropertyHelper helper(property);
    if (helper.GetNumberOfElements() == 1 && helper.GetAsDouble(0) != used) {
      helper.Set(0, used);
      changed = true;
    }
  }
  if (changed) {
    proxy->UpdateVTKObjects();
  }
}

void pqGraupelApplyLook::onDataUpdated(pqPipelineSource *source) {
  QPointer<pqPipelineSource> shown(source);
  QTimer::singleShot(0, this, [this, shown]() {
    if (shown) {
      this->showUsedValues(shown);
    }
  });
  // An Apply whose update failed (no points): the look comes with the first
  // update that gives points, once that update has returned.
  if (this->Waiting.contains(source) && !Extent(source->getOutputPort(0)).isEmpty()) {
    this->Waiting.remove(source);
    QPointer<pqPipelineSource> later(source);
    QTimer::singleShot(0, this, [this, later]() { this->showSurfaceLater(later, 1200); });
  }
}

void pqGraupelApplyLook::onSurfaceUpdated(pqPipelineSource *surface) {
  // Another extent (a reader's spacing or origin changed): look again.
  const QVector<double> now = Extent(surface->getOutputPort(0));
  if (now.isEmpty() || !ExtentChanged(this->Extents.value(surface), now)) {
    return;
  }
  this->Extents[surface] = now;
  pqRenderView *view = ShownIn(surface);
  if (view && view->getNumberOfVisibleDataRepresentations() == 1) {
    double bounds[6];
    surface->getOutputPort(0)->getDataInformation()->GetBounds(bounds);
    LookAt(view->getRenderViewProxy(), bounds);
    view->render();
  }
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
  // The surface's update runs inside this timer's handler: no events are
  // processed under it (pqGraupelAbortStarter asks busy()).
  Busy = true;
  this->showSurface(source);
  Busy = false;
}

bool pqGraupelApplyLook::Busy = false;

bool pqGraupelApplyLook::busy() {
  return Busy;
}

void pqGraupelApplyLook::showSurface(pqPipelineSource *source) {
  if (Extent(source->getOutputPort(0)).isEmpty()) {
    this->Waiting.insert(source); // refused, or nothing yet: wait for points
    return;
  }
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
  vtkSMViewProxy *viewProxy = view->getViewProxy();
  this->showTime(source, viewProxy);
  if (vtkSMProxySelectionModel *active = pxm->GetSelectionModel("ActiveSources")) {
    active->SetCurrentProxy(source->getProxy(), vtkSMProxySelectionModel::CLEAR_AND_SELECT);
  }

  const bool objects = this->showObjects(source, surface, viewProxy);
  vtkSMProxy *repr = controller->Show(surfaceSource, 0, viewProxy);
  if (!repr) {
    return;
  }
  // The flat image, and the surfaces of this output's inputs (as ParaView
  // hides a filter's input): one surface, not two drawn in one place.
  controller->Hide(vtkSMSourceProxy::SafeDownCast(source->getProxy()), 0, viewProxy);
  // The representation toolbar shows the active source's: say Surface, what
  // is drawn, not Slice.
  if (vtkSMProxy *image =
          viewProxy->FindRepresentation(vtkSMSourceProxy::SafeDownCast(source->getProxy()), 0)) {
    vtkSMPropertyHelper(image, "Representation").Set("Surface");
    image->UpdateVTKObjects();
  }
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
      const double exaggeration =
          vtkSMPropertyHelper(surface, "VerticalExaggeration").GetAsDouble();
      vtkSMPropertyHelper(bar, "Title").Set(LegendTitle(array, exaggeration).toUtf8().constData());
      vtkSMPropertyHelper(bar, "ComponentTitle").Set("");
      // 120 and 0.01, not 1.2e+02 and 1.0e-02.
      vtkSMPropertyHelper(bar, "RangeLabelFormat").Set("%.4g");
      bar->UpdateVTKObjects();
    }
  }
  const int shown = view->getNumberOfVisibleDataRepresentations();
  pqServerManagerModel *smm = pqApplicationCore::instance()->getServerManagerModel();
  if (auto *added = smm->findItem<pqPipelineSource *>(surface.GetPointer())) {
    this->Extents[added] = Extent(added->getOutputPort(0));
    QObject::connect(added, QOverload<pqPipelineSource *>::of(&pqPipelineSource::dataUpdated), this,
                     [this](pqPipelineSource *updated) { this->onSurfaceUpdated(updated); });
  }
  // The surface alone, or with the objects' port beside it.
  if (shown == 1 || (shown == 2 && objects)) {
    double bounds[6];
    surfaceSource->GetDataInformation(0)->GetBounds(bounds);
    if (bounds[0] <= bounds[1]) {
      LookAt(view->getRenderViewProxy(), bounds);
    }
  }
  view->render();
}

bool pqGraupelApplyLook::showObjects(pqPipelineSource *source, vtkSMProxy *surface,
                                     vtkSMViewProxy *view) {
  vtkSMProxy *proxy = source->getProxy();
  auto *producer = vtkSMSourceProxy::SafeDownCast(proxy);
  if (!producer || !proxy->GetProperty("Objects") || producer->GetNumberOfOutputPorts() < 2) {
    return false;
  }
  vtkSMPropertyHelper objects(proxy, "Objects");
  auto *input = objects.GetNumberOfElements() > 0
                    ? vtkSMSourceProxy::SafeDownCast(objects.GetAsProxy(0))
                    : nullptr;
  if (!input) {
    return false;
  }
  // True heights: the objects are drawn at their pose, so the snow must be too.
  vtkSMPropertyHelper(surface, "VerticalExaggeration").Set(1.0);
  surface->UpdateVTKObjects();
  vtkNew<vtkSMParaViewPipelineControllerWithRendering> controller;
  // The objects at their pose (output port 1), and not the mesh they came
  // from at its start as well.
  controller->Hide(input, objects.GetOutputPort(0), view);
  vtkSMProxy *repr = controller->Show(producer, 1, view);
  if (!repr) {
    return false;
  }
  // A brick red that reads against white snow and the terrain's greens.
  const double red[3] = {0.78, 0.30, 0.20};
  vtkSMPropertyHelper(repr, "DiffuseColor").Set(red, 3);
  vtkSMPropertyHelper(repr, "AmbientColor").Set(red, 3);
  vtkSMPVRepresentationProxy::SetScalarColoring(repr, nullptr, 0);
  repr->UpdateVTKObjects();
  return true;
}

void pqGraupelApplyLook::onRepresentationAdded(pqRepresentation *added) {
  // Rain Runoff's Hydrograph (output port 1) in a line chart: the discharge
  // series on the left axis with units, the volumes on the right one,
  // hidden until chosen (they are 10^4 to 10^7 times the rates).
  // A state file keeps the chart it saved.
  if (pqApplicationCore::instance()->isLoadingState()) {
    return;
  }
  auto *repr = qobject_cast<pqDataRepresentation *>(added);
  pqView *view = repr ? repr->getView() : nullptr;
  pqOutputPort *port = repr ? repr->getOutputPortFromInput() : nullptr;
  vtkSMProxy *producer = port && port->getSource() ? port->getSource()->getProxy() : nullptr;
  if (!view || view->getViewType() != QLatin1String("XYChartView") || !producer ||
      !producer->GetXMLName() || strcmp(producer->GetXMLName(), "RainRunoff") != 0 ||
      port->getPortNumber() != 1) {
    return;
  }
  vtkSMProxy *proxy = repr->getProxy();
  vtkSMPropertyHelper visibility(proxy, "SeriesVisibility");
  vtkSMPropertyHelper labels(proxy, "SeriesLabel");
  vtkSMPropertyHelper corners(proxy, "SeriesPlotCorner");
  visibility.SetNumberOfElements(0);
  labels.SetNumberOfElements(0);
  corners.SetNumberOfElements(0);
  unsigned int k = 0;
  for (const auto &series : Hydrograph) {
    visibility.Set(2 * k, series.name);
    visibility.Set(2 * k + 1, series.shown ? "1" : "0");
    labels.Set(2 * k, series.name);
    labels.Set(2 * k + 1, series.label);
    corners.Set(2 * k, series.name);
    corners.Set(2 * k + 1, series.right ? "1" : "0");
    ++k;
  }
  vtkSMPropertyHelper(proxy, "UseIndexForXAxis").Set(0);
  vtkSMPropertyHelper(proxy, "XArrayName").Set("time");
  proxy->UpdateVTKObjects();
  vtkSMProxy *chart = view->getProxy();
  vtkSMPropertyHelper(chart, "ChartTitle").Set("Rain Runoff: hydrograph");
  vtkSMPropertyHelper(chart, "LeftAxisTitle").Set("discharge (m\xc2\xb3/s)");
  vtkSMPropertyHelper(chart, "RightAxisTitle").Set("volume (m\xc2\xb3)");
  vtkSMPropertyHelper(chart, "BottomAxisTitle").Set("time (s)");
  chart->UpdateVTKObjects();
}

void pqGraupelApplyLook::showTime(pqPipelineSource *source, vtkSMViewProxy *view) {
  // A simulation (a time source: it has an EndTime) gets the simulated time
  // in the view's upper left corner, once a view.
  vtkSMProxy *proxy = source->getProxy();
  if (!proxy->GetProperty("EndTime")) {
    return;
  }
  pqServerManagerModel *smm = pqApplicationCore::instance()->getServerManagerModel();
  for (pqPipelineSource *other : smm->findItems<pqPipelineSource *>(source->getServer())) {
    vtkSMProxy *p = other->getProxy();
    if (p && p->GetXMLName() && strcmp(p->GetXMLName(), "TimeToTextConvertorSource") == 0 &&
        ShownIn(other)) {
      return;
    }
  }
  vtkSMSessionProxyManager *pxm = source->getServer()->proxyManager();
  vtkSmartPointer<vtkSMProxy> text;
  text.TakeReference(pxm->NewProxy("sources", "TimeToTextConvertorSource"));
  auto *textSource = vtkSMSourceProxy::SafeDownCast(text);
  if (!textSource) {
    return;
  }
  vtkNew<vtkSMParaViewPipelineControllerWithRendering> controller;
  controller->PreInitializeProxy(text);
  vtkSMPropertyHelper(text, "Format").Set("t = {time:.0f} s");
  controller->PostInitializeProxy(text);
  controller->RegisterPipelineProxy(text, "Simulated Time");
  if (vtkSMProxy *repr = controller->Show(textSource, 0, view)) {
    vtkSMPropertyHelper(repr, "WindowLocation").Set("Upper Left Corner");
    repr->UpdateVTKObjects();
  }
}
