/**
 * Plugin initializer: imports the `graupel` Python package as soon as the
 * plugin is loaded into a process with Python (at once, or when Python
 * starts later, as in the GUI).
 *
 * Why: VTK's Python wrapping, when it first wraps an object whose class no
 * imported module declares (a vtkProceduralTerrainSource reached through
 * GetClientSideObject() before `import graupel`), records that class name
 * as its nearest wrapped base class (vtkImageAlgorithm). A later
 * `import graupel` then gets that abstract base back for the name, so every
 * such class "is an abstract class and cannot be instantiated". Importing
 * the package before any Graupel object can be wrapped avoids it.
 */
#ifndef vtkGraupelPythonInit_h
#define vtkGraupelPythonInit_h

void graupel_plugin_import_python();

#endif
