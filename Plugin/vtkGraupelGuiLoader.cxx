#include "vtkGraupelGuiLoader.h"

#include "vtkLogger.h"

#include <string>

#if defined(__unix__) || defined(__APPLE__)
#include <dlfcn.h>
#define GRAUPEL_HAVE_DLFCN 1
#endif

void graupel_plugin_start_gui() {
#if defined(GRAUPEL_HAVE_DLFCN) && defined(GRAUPEL_GUI_MODULE)
  // pqApplicationCore::instance(): exported by pqCore, which only the Qt
  // client links. Its absence means pvpython, pvbatch or pvserver.
  if (!dlsym(RTLD_DEFAULT, "_ZN17pqApplicationCore8instanceEv")) {
    return;
  }
  Dl_info self;
  if (!dladdr(reinterpret_cast<void *>(&graupel_plugin_start_gui), &self) || !self.dli_fname) {
    return;
  }
  std::string path = self.dli_fname;
  path = path.substr(0, path.find_last_of('/') + 1) + GRAUPEL_GUI_MODULE;
  // Never closed: the starter it creates lives as long as the application.
  void *module = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  void *start = module ? dlsym(module, "graupel_gui_start") : nullptr;
  if (!start) {
    vtkLog(WARNING, "Graupel: the abort button stays disabled: cannot load "
                        << path << " (" << dlerror()
                        << "); rebuild the plugin with the same ParaView as this GUI.");
    return;
  }
  reinterpret_cast<void (*)()>(start)();
#endif
}
