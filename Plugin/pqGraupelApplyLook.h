/**
 * @class   pqGraupelApplyLook
 * @brief   On the first Apply of a Graupel terrain output in the GUI, shows it as a Terrain
 * Surface.
 *
 * A Graupel terrain output (a proxy whose XML hints hold <GraupelSurface/>:
 * Procedural Terrain, the EXR reader, Rain Runoff, Snow Deformation, Snow
 * Accumulation, Terrain Analysis, Terrain Shadow, Water Surface) is a flat
 * 2-D image. When the user applies one for the first time and ParaView has
 * shown that image in a render view, this component adds a Terrain Surface
 * below it and shows that instead: the flat image is hidden, as are the
 * Terrain Surfaces this starter added below the new output's inputs (as
 * ParaView hides a filter's input), the surface is coloured by its active
 * scalars with the plugin's colour maps, a legend titled with units
 * ("water depth (m)") is shown, and when the surface is all the view shows,
 * the camera looks at it from the south-east and above.
 *
 * The look waits for the first update that gives the output points: an
 * Apply that failed (a wrong input, then Change Input) gets the look on the
 * first one that works. With objects attached (Snow Deformation, Snow
 * Accumulation), the heights are drawn true (no exaggeration, so the
 * objects sit on the snow as they are), the objects' output port is shown at
 * its pose in a colour that stands out from snow, and the source the
 * objects came from is hidden; otherwise the legend says the exaggeration
 * ("snow depth (m), heights x2"). Legends' range labels are plain numbers.
 * A property value a Graupel filter moved into its range (it warns once)
 * is shown in the panel as the value used, after the update.
 * A simulation's view gets the simulated time in its upper left corner
 * (an Annotate Time source, "t = 600 s"), once a view.
 * When a surface this component added changes its extent (a reader given
 * another spacing), the camera looks at it again.
 *
 * Rain Runoff's Hydrograph shown in a line chart (from the GUI or its
 * Python shell; not from a state file) plots the discharge series (m^3/s)
 * on the left axis and the volumes (m^3) on the right one, hidden until
 * chosen, with axis titles in units.
 *
 * Only the GUI's Apply path triggers the surface: ParaView's pqObjectBuilder marks a
 * source made from a menu UNINITIALIZED until its first Apply
 * (pqApplyBehavior sets it UNMODIFIED after showing it). Sources made by
 * Python (the GUI's shell, pvpython, pvbatch) or by loading a state file
 * never are, so scripts and states keep exactly what they build. The work
 * is done once the Apply has returned (a zero-time timer), so the image
 * ParaView showed exists; a timer that fires inside an update (the abort
 * button lets Qt process events there, pqGraupelAbortStarter) waits for it
 * to end.
 *
 * Lives in the module GraupelGui, started by graupel_gui_start().
 */
#ifndef pqGraupelApplyLook_h
#define pqGraupelApplyLook_h

#include <QMap>
#include <QObject>
#include <QPointer>
#include <QSet>
#include <QVector>

class pqPipelineSource;
class pqRepresentation;
class vtkSMProxy;
class vtkSMViewProxy;

class pqGraupelApplyLook : public QObject {
  typedef QObject Superclass;

public:
  pqGraupelApplyLook(QObject *p = nullptr);
  ~pqGraupelApplyLook() override = default;

  void onStartup();

  /** The legend title of a colour array: "water depth (m)"; the name itself when unknown. */
  static const char *legendTitle(const char *array);

  /** Whether the look is adding a surface now (its updates run inside a timer's handler). */
  static bool busy();

private:
  void onSourceAdded(pqPipelineSource *source);
  void onModifiedStateChanged(pqPipelineSource *source);
  void showSurfaceLater(QPointer<pqPipelineSource> source, int tries);
  void showSurface(pqPipelineSource *source);
  bool showObjects(pqPipelineSource *source, vtkSMProxy *surface, vtkSMViewProxy *view);
  void onDataUpdated(pqPipelineSource *source);
  void showUsedValues(pqPipelineSource *source);
  void showTime(pqPipelineSource *source, vtkSMViewProxy *view);
  void onSurfaceUpdated(pqPipelineSource *surface);
  void onRepresentationAdded(pqRepresentation *repr);

  Q_DISABLE_COPY(pqGraupelApplyLook)
  QSet<pqPipelineSource *> Pending;                  // made from a menu, not applied yet
  QSet<pqPipelineSource *> Waiting;                  // applied, but no update has given points yet
  QMap<pqPipelineSource *, QVector<double>> Extents; // surfaces added: x and y bounds
  bool Updating = false;
  static bool Busy; // between progress start and end
};

#endif
