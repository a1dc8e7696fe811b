#include "vtkGraupelRemote.h"

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkCompositeMultiProcessController.h"
#include "vtkGraupelAlgorithm.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkPVProgressHandler.h"
#include "vtkPVSession.h"
#include "vtkProcessModule.h"
#include "vtkWeakPointer.h"

namespace {

void OnRequestBracket(vtkObject *, unsigned long event, void *, void *) {
  if (event == vtkCommand::StartEvent) {
    vtkGraupelAlgorithm::BeginRemoteRequest();
  } else {
    vtkGraupelAlgorithm::EndRemoteRequest();
  }
}

vtkMultiProcessController *ClientOfServer() {
  vtkProcessModule *pm = vtkProcessModule::GetProcessModule();
  if (!pm) {
    return nullptr;
  }
  vtkPVSession *session = vtkPVSession::SafeDownCast(pm->GetActiveSession());
  if (!session) {
    session = vtkPVSession::SafeDownCast(pm->GetSession());
  }
  if (!session) {
    return nullptr;
  }
  // A client's requests are bracketed by their progress (PrepareProgress,
  // CleanupPendingProgress): how long an abort holds follows them.
  static vtkWeakPointer<vtkPVProgressHandler> observed;
  vtkPVProgressHandler *progress = session->GetProgressHandler();
  if (progress && observed != progress) {
    vtkNew<vtkCallbackCommand> end;
    end->SetCallback(&OnRequestBracket);
    progress->AddObserver(vtkCommand::StartEvent, end);
    progress->AddObserver(vtkCommand::EndEvent, end);
    observed = progress;
  }
  vtkMultiProcessController *client = session->GetController(vtkPVSession::CLIENT);
  if (auto *several = vtkCompositeMultiProcessController::SafeDownCast(client)) {
    client = several->GetActiveController();
  }
  return client;
}

} // namespace

void graupel_plugin_remote_abort() {
  switch (vtkProcessModule::GetProcessType()) {
  case vtkProcessModule::PROCESS_SERVER:
  case vtkProcessModule::PROCESS_DATA_SERVER:
    vtkGraupelAlgorithm::SetRemoteClientLookup(&ClientOfServer);
    break;
  default:
    break;
  }
}
