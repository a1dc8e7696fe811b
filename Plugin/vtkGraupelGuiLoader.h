/**
 * Plugin initializer: starts the GUI's abort-button support
 * (pqGraupelAbortStarter, in the separate module GraupelGui) in ParaView's
 * Qt client only.
 *
 * Why a separate module: the plugin itself links no Qt, so pvpython,
 * pvbatch and pvserver load no Qt library and run no Qt code when they load
 * the plugin. The initializer looks for pqApplicationCore::instance() among
 * the symbols the process already has (only the Qt client links pqCore);
 * there it loads GraupelGui from GRAUPEL_GUI_MODULE (a path relative to the
 * plugin's own file) and calls its graupel_gui_start(). Elsewhere it
 * returns at once.
 */
#ifndef vtkGraupelGuiLoader_h
#define vtkGraupelGuiLoader_h

void graupel_plugin_start_gui();

#endif
