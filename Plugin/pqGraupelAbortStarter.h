/**
 * @class   pqGraupelAbortStarter
 * @brief   Makes the status bar's abort button stop a running update (ParaView < 6.1, builtin).
 *
 * ParaView 5.11's GUI never enables the abort button (nothing calls
 * pqProgressManager::setEnableAbort), nothing listens to
 * pqProgressManager::abort(), and Qt processes no events while the
 * pipeline updates on the GUI thread, so a click is not even seen until the
 * update has ended. ParaView 6.1 fixed this (commit 8789e8b2d6, "enable
 * abort button functionality"); this auto-start does the same from the
 * plugin, for builtin sessions only:
 * - while progress is shown, the abort button is enabled;
 * - on each progress event the GUI forwards (vtkPVProgressHandler lets one
 *   through every 0.1 s at most) from a Graupel algorithm or Terrain
 *   Surface, Qt processes pending events, with all user input except the
 *   abort button's (and Pause's while an animation plays) held back, so the
 *   click is delivered but nothing else can start a second update inside
 *   this one; never under a representation's update, nor while the look
 *   adds a surface from its timer (events processed there broke QMainWindow's
 *   dock animation);
 * - a click sets AbortExecute on the algorithm that reported progress last
 *   in this update (the one running), as ParaView 6.1 does;
 * - that algorithm gets AbortExecute again each time it starts to execute
 *   until the event loop is idle again: ParaView's Render asks for the data more than
 *   once, and an aborted output (VTK's ABORTED flag) makes the next request
 *   execute again. A Graupel simulation then returns its empty output at
 *   once; the next Render (a new time, Apply) runs it. The flag is cleared
 *   once the event loop is idle again after the progress ended (a Render's
 *   later passes would run the algorithm again), for filters that do not
 *   clear it themselves.
 * An algorithm honours an abort at its next abort check: a Graupel
 * simulation within about 0.1 s of simulated stepping.
 *
 * Events processed during an update include timers; ParaView defers renders
 * while progress is pending, but a plugin's timer could start one.
 * GRAUPEL_GUI_TEST_ABORT_MS makes the component click the button itself,
 * for the GUI test (see ArmTestClick in the .cxx).
 *
 * Lives in its own module, GraupelGui, loaded by the plugin initializer
 * graupel_plugin_start_gui (vtkGraupelGuiLoader.h) in the Qt client only,
 * not as a UI_INTERFACES auto-start: that would link pqComponents, whose
 * CMake package asks for the development files of all of VTK's rendering
 * dependencies, and would load Qt into pvpython and pvbatch. No Q_OBJECT
 * (no moc): the connections are lambdas.
 */
#ifndef pqGraupelAbortStarter_h
#define pqGraupelAbortStarter_h

#include <QObject>

class pqPipelineSource;

/** Creates the starter once, in the GUI (a QApplication with a pqApplicationCore). */
extern "C" __attribute__((visibility("default"))) void graupel_gui_start();

class pqGraupelAbortStarter : public QObject {
  typedef QObject Superclass;

public:
  pqGraupelAbortStarter(QObject *p = nullptr);
  ~pqGraupelAbortStarter() override;

  void onStartup();

protected:
  bool eventFilter(QObject *obj, QEvent *event) override;

private:
  void onSourceAdded(pqPipelineSource *source);
  void onProgressStart();
  void onProgressEnd();
  void onProgress(const QString &text, int percent);
  void onAbort();
  void releaseAbort();

  Q_DISABLE_COPY(pqGraupelAbortStarter)
  bool Active = false;     // an update shows progress now
  bool Remote = false;     // ... on a remote server
  bool Processing = false; // inside our processEvents
  bool TestArmed = false;  // GRAUPEL_GUI_TEST_ABORT_MS looked at
};

#endif
