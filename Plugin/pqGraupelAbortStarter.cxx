#include "pqGraupelAbortStarter.h"
#include "pqGraupelApplyLook.h"

#include "pqApplicationCore.h"
#include "pqPipelineSource.h"
#include "pqProgressManager.h"
#include "pqServer.h"
#include "pqServerManagerModel.h"
#include "vtkAlgorithm.h"
#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkGraupelAlgorithm.h"
#include "vtkNew.h"
#include "vtkPVSession.h"
#include "vtkSMProxy.h"
#include "vtkSMSession.h"
#include "vtkWeakPointer.h"

#include <QAbstractButton>
#include <QAction>
#include <QToolButton>
#include <QApplication>
#include <QDateTime>
#include <QFile>
#include <QEvent>
#include <QMouseEvent>
#include <QPointer>
#include <QTimer>

namespace {
// The algorithm that reported progress last: the one running. A free
// function and a weak pointer, so that an observer left on an algorithm
// after this object is gone touches nothing freed.
vtkWeakPointer<vtkAlgorithm> LastProgressing;
// The algorithm aborted in the progress now shown; null when none.
vtkWeakPointer<vtkAlgorithm> Aborted;

void RememberProgressing(vtkObject *caller, unsigned long, void *, void *) {
  LastProgressing = vtkAlgorithm::SafeDownCast(caller);
}

void AbortAgain(vtkObject *caller, unsigned long, void *, void *) {
  if (caller && caller == Aborted.GetPointer()) {
    Aborted->SetAbortExecuteAndUpdateTime();
  }
}

pqServer *ActiveServer() {
  return pqApplicationCore::instance()->getActiveServer();
}

// For the GUI test (Testing/Python/check_gui_plugin.py): with
// GRAUPEL_GUI_TEST_ABORT_MS=N, clicks the abort button N ms after the first
// progress of a Graupel simulation, once per process, and writes the time of
// the click (seconds since the epoch) to GRAUPEL_GUI_TEST_ABORT_LOG. The
// timer fires only if Qt processes events during the update, as the real
// click needs. A button still disabled then (on a busy machine the update
// that reported the progress may have ended and the next not yet begun) is
// looked at again every 50 ms, for up to 60 s, and clicked once enabled.
void ClickWhenEnabled(int tries) {
  for (QWidget *w : QApplication::allWidgets()) {
    auto *button = qobject_cast<QAbstractButton *>(w);
    if (button && button->objectName() == QLatin1String("AbortButton")) {
      if (!button->isEnabled() && tries > 0) {
        QTimer::singleShot(50, QCoreApplication::instance(),
                           [tries]() { ClickWhenEnabled(tries - 1); });
        return;
      }
      const QString log = qEnvironmentVariable("GRAUPEL_GUI_TEST_ABORT_LOG");
      QFile file(log);
      if (!log.isEmpty() && file.open(QIODevice::WriteOnly)) {
        file.write(QByteArray::number(QDateTime::currentMSecsSinceEpoch() / 1000.0, 'f', 3) +
                   (button->isEnabled() ? " enabled\n" : " disabled\n"));
      }
      button->click();
      return;
    }
  }
}

void ArmTestClick() {
  const int ms = qEnvironmentVariableIntValue("GRAUPEL_GUI_TEST_ABORT_MS");
  if (ms <= 0) {
    return;
  }
  QTimer::singleShot(ms, QCoreApplication::instance(), []() { ClickWhenEnabled(1200); });
}

bool IsAbortButton(QObject *obj) {
  for (QObject *o = obj; o; o = o->parent()) {
    if (o->objectName() == QLatin1String("AbortButton")) {
      return true;
    }
  }
  return false;
}

// The VCR toolbar's Play (or Reverse) button while an animation plays: it
// says Pause then (pqVCRToolbar::onPlaying) and only stops the scene. Any
// other button could start a second update inside this one.
bool IsPauseButton(QObject *obj) {
  for (QObject *o = obj; o; o = o->parent()) {
    auto *button = qobject_cast<QToolButton *>(o);
    QAction *action = button ? button->defaultAction() : nullptr;
    if (action) {
      const QString name = action->objectName();
      return (name == QLatin1String("actionVCRPlay") ||
              name == QLatin1String("actionVCRReverse")) &&
             action->text() == QLatin1String("Pa&use");
    }
  }
  return false;
}
} // namespace

void graupel_gui_start() {
  static QPointer<pqGraupelAbortStarter> started;
  static int tries = 0;
  auto *app = qobject_cast<QApplication *>(QCoreApplication::instance());
  if (started || !app) {
    return;
  }
  pqApplicationCore *core = pqApplicationCore::instance();
  if (!core) {
    // An autoloaded plugin loads while the application core is being made:
    // try again once the event loop runs (for at most 10 s).
    if (++tries <= 100) {
      QTimer::singleShot(100, app, []() { graupel_gui_start(); });
    }
    return;
  }
  started = new pqGraupelAbortStarter(core);
  started->onStartup();
  // The look on Apply (pqGraupelApplyLook.h): owned by the core as well.
  (new pqGraupelApplyLook(core))->onStartup();
}

pqGraupelAbortStarter::pqGraupelAbortStarter(QObject *p) : Superclass(p) {}

pqGraupelAbortStarter::~pqGraupelAbortStarter() {
  if (this->Active) {
    QApplication::instance()->removeEventFilter(this);
  }
}

void pqGraupelAbortStarter::onStartup() {
  pqApplicationCore *core = pqApplicationCore::instance();
  pqProgressManager *pm = core->getProgressManager();
  pqServerManagerModel *smm = core->getServerManagerModel();
  if (!pm || !smm) {
    return;
  }
  QObject::connect(pm, &pqProgressManager::progressStartEvent, this,
                   [this]() { this->onProgressStart(); });
  QObject::connect(pm, &pqProgressManager::progressEndEvent, this,
                   [this]() { this->onProgressEnd(); });
  QObject::connect(pm, &pqProgressManager::progress, this,
                   [this](const QString &text, int percent) { this->onProgress(text, percent); });
  QObject::connect(pm, &pqProgressManager::abort, this, [this]() { this->onAbort(); });
  QObject::connect(smm, &pqServerManagerModel::sourceAdded, this,
                   [this](pqPipelineSource *source) { this->onSourceAdded(source); });
  for (pqPipelineSource *source : smm->findItems<pqPipelineSource *>()) {
    this->onSourceAdded(source);
  }
}

void pqGraupelAbortStarter::onSourceAdded(pqPipelineSource *source) {
  vtkSMProxy *proxy = source ? source->getProxy() : nullptr;
  // Only a builtin session has the running algorithm in this process.
  if (!proxy || !source->getServer() || source->getServer()->isRemote()) {
    return;
  }
  if (auto *algorithm = vtkAlgorithm::SafeDownCast(proxy->GetClientSideObject())) {
    vtkNew<vtkCallbackCommand> remember;
    remember->SetCallback(RememberProgressing);
    algorithm->AddObserver(vtkCommand::ProgressEvent, remember);
    vtkNew<vtkCallbackCommand> again;
    again->SetCallback(AbortAgain);
    algorithm->AddObserver(vtkCommand::StartEvent, again);
  }
}

void pqGraupelAbortStarter::onProgressStart() {
  pqServer *server = ActiveServer();
  if (this->Active || !server) {
    return;
  }
  this->Active = true;
  this->Remote = server->isRemote();
  // Only an algorithm that reports progress in this update is aborted.
  LastProgressing = nullptr;
  QApplication::instance()->installEventFilter(this);
  pqApplicationCore::instance()->getProgressManager()->setEnableAbort(true);
}

void pqGraupelAbortStarter::onProgressEnd() {
  if (!this->Active) {
    return;
  }
  this->Active = false;
  if (Aborted) {
    // A Render updates in several passes, each with its own progress: the
    // abort holds until the event loop is idle again (no progress shown),
    // or the next pass would run the aborted algorithm again.
    QTimer::singleShot(0, this, [this]() { this->releaseAbort(); });
  }
  QApplication::instance()->removeEventFilter(this);
  pqApplicationCore::instance()->getProgressManager()->setEnableAbort(false);
}

void pqGraupelAbortStarter::onProgress(const QString &text, int percent) {
  // Not at 0 %: ParaView avoids processing events there because some of its
  // timers expect a fixed order (see pqProgressManager::setProgress).
  if (!this->Active || this->Processing || percent <= 0) {
    return;
  }
  // Only inside a Graupel algorithm's own update: the long ones, which
  // honour the abort. A representation or any other filter updating inside
  // a Qt handler (a render on resize, the look's timer) must not have the
  // event loop run under it: processing events inside the representation's
  // update that the look's render starts left QMainWindow's dock animator
  // with a deleted animation, and the next drag of a dock's separator
  // crashed (Testing/Python/check_gui_docks.py).
  // Terrain Surface (a polydata filter of the plugin) too, except while the
  // look adds one: that update runs inside a timer's handler.
  // With a remote server the algorithms run there: a Graupel simulation's
  // progress says "<Simulation>: t = 1200 s of 3600 s".
  const bool graupel =
      this->Remote
          ? text.contains(QLatin1String(": t = ")) && text.contains(QLatin1String(" s of "))
          : LastProgressing && (LastProgressing->IsA("vtkGraupelAlgorithm") ||
                                LastProgressing->IsA("vtkTerrainSurfaceFilter"));
  if (!graupel || pqGraupelApplyLook::busy()) {
    return;
  }
  if (!this->TestArmed && text.contains(QLatin1String(" s of "))) {
    this->TestArmed = true;
    ArmTestClick();
  }
  // pqProgressManager's own filter would drop the press on the top-level
  // window before it reaches the button: ours filters instead meanwhile.
  pqProgressManager *pm = pqApplicationCore::instance()->getProgressManager();
  const bool wasUnblocked = pm->unblockEvents(true);
  this->Processing = true;
  QApplication::processEvents();
  this->Processing = false;
  pm->unblockEvents(wasUnblocked);
}

void pqGraupelAbortStarter::releaseAbort() {
  if (this->Active) {
    return; // a pass is running: its own end posts this again
  }
  if (Aborted) {
    Aborted->SetAbortExecute(0);
    Aborted = nullptr;
  }
}

void pqGraupelAbortStarter::onAbort() {
  if (this->Active && this->Remote) {
    // The server's Graupel update listens for this (Filters/GraupelRemoteAbort.h).
    pqServer *server = ActiveServer();
    vtkSMSession *session = server ? server->session() : nullptr;
    if (session) {
      vtkGraupelAlgorithm::SendRemoteAbort(session->GetController(vtkPVSession::DATA_SERVER_ROOT));
    }
    return;
  }
  if (this->Active && LastProgressing) {
    Aborted = LastProgressing;
    Aborted->SetAbortExecuteAndUpdateTime();
  }
}

bool pqGraupelAbortStarter::eventFilter(QObject *obj, QEvent *event) {
  if (this->Processing) {
    switch (event->type()) {
    case QEvent::MouseButtonPress:
    case QEvent::MouseButtonRelease:
    case QEvent::MouseButtonDblClick:
    case QEvent::MouseMove: {
      // The abort button alone takes clicks during an update, and Pause
      // while an animation plays (one click, not one between two updates). A click
      // reaches the top-level QWindow first: look at what lies under it.
      auto *mouse = static_cast<QMouseEvent *>(event);
      QObject *target = obj->isWidgetType() ? obj : QApplication::widgetAt(mouse->globalPos());
      if (IsAbortButton(target) || IsPauseButton(target)) {
        break;
      }
      return true;
    }
    case QEvent::Wheel:
    case QEvent::KeyPress:
    case QEvent::KeyRelease:
    case QEvent::Shortcut:
    case QEvent::ShortcutOverride:
    case QEvent::ContextMenu:
    case QEvent::DragEnter:
    case QEvent::DragMove:
    case QEvent::Drop:
    case QEvent::TouchBegin:
    case QEvent::TouchUpdate:
    case QEvent::TouchEnd:
      return true;
    case QEvent::Close:
      // Closing the window inside an update would free what is running.
      event->ignore();
      return true;
    default:
      break;
    }
  }
  return this->Superclass::eventFilter(obj, event);
}
