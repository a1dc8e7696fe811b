#include "vtkGraupelPythonInit.h"

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkNew.h"
#include "vtkPythonInterpreter.h"

namespace {
// Without the package on sys.path there is nothing to import and nothing
// can be wrapped from it either, so failing quietly is right.
void ImportGraupel() {
  vtkPythonInterpreter::RunSimpleString("try:\n"
                                        "    import graupel\n"
                                        "except ImportError:\n"
                                        "    pass\n");
}

void OnPythonStart(vtkObject *, unsigned long, void *, void *) {
  ImportGraupel();
}
} // namespace

void graupel_plugin_import_python() {
  if (vtkPythonInterpreter::IsInitialized()) {
    ImportGraupel();
    return;
  }
  // The interpreter notifies its instances when Python starts. This one is
  // never deleted: plugins are never unloaded, and deleting it during static
  // destruction could outlive the interpreter's own list of instances.
  static vtkPythonInterpreter *watcher = nullptr;
  if (!watcher) {
    watcher = vtkPythonInterpreter::New();
    vtkNew<vtkCallbackCommand> cb;
    cb->SetCallback(&OnPythonStart);
    watcher->AddObserver(vtkCommand::EnterEvent, cb);
  }
}
