/**
 * @class   vtkGraupelParticlesSource
 * @brief   Base of Rain Particles and Snowfall Particles: particles at the
 *          requested time from the particles core (kernels/include/graupel/particles.h).
 *
 * The output is vtkPolyData: one point and one vertex per particle, with the
 * point arrays `velocity` (m/s, 3), the size (`diameter` or `size`, mm) and
 * `streak` (m, 3: the motion over ExposureTime, for line streaks or
 * oriented glyphs), and the field data `time` (s) and `graupel_device`.
 *
 * Time: the particles at time t are a pure function of (Seed, t), so the
 * source answers any UPDATE_TIME_STEP and scrubbing is consistent in any
 * order. It has no TIME_STEPS of its own: a terrain's steps (Rain Runoff's)
 * pass through; otherwise it advertises the continuous TIME_RANGE 0-60 s
 * (without a TIME_RANGE or TIME_STEPS the executive takes the output as
 * static and does not run the source again for a new time; the range also
 * gives ParaView's animation a minute of fall to play). Times outside it
 * are answered as well. Without a requested time it computes t = 0.
 *
 * Region: with a terrain image on the optional Input, x and y span the
 * terrain's bounds and z runs from its lowest point (of `elevation`, or of
 * its bounds without that array) to its highest point plus the height of
 * Region (Region[5] - Region[4]); without an Input, Region
 * [xmin xmax ymin ymax zmin zmax] (m) is the box. Particles fall through the
 * terrain to the box's bottom and respawn at its top.
 */
#ifndef vtkGraupelParticlesSource_h
#define vtkGraupelParticlesSource_h

#include "GraupelFiltersModule.h"
#include "vtkGraupelAlgorithm.h"
#include "vtkSmartPointer.h" // for the output arrays

class vtkFloatArray;
class vtkImageData;
class vtkPoints;

struct gr_particles;
struct gr_particles_params;
struct gr_context;

class GRAUPELFILTERS_EXPORT vtkGraupelParticlesSource : public vtkGraupelAlgorithm {
public:
  vtkTypeMacro(vtkGraupelParticlesSource, vtkGraupelAlgorithm);
  void PrintSelf(ostream &os, vtkIndent indent) override;

  ///@{
  /** Number of particles, 2^10 .. 2^24 (default 2^17). */
  virtual void SetCount(int value);
  vtkGetMacro(Count, int);
  ///@}

  ///@{
  /** Random seed: equal seeds give equal particles (default 0). */
  virtual void SetSeed(int value);
  vtkGetMacro(Seed, int);
  ///@}

  ///@{
  /** Seconds: the exposure the streaks cover (default 0.02). */
  virtual void SetExposureTime(double value);
  vtkGetMacro(ExposureTime, double);
  ///@}

  ///@{
  /** Wind, m/s, x east, y north, z up (default 0 0 0). */
  vtkSetVector3Macro(Wind, double);
  vtkGetVector3Macro(Wind, double);
  ///@}

  ///@{
  /** The box [xmin xmax ymin ymax zmin zmax], m, without an Input (default 0 100 0 100 0 50). */
  vtkSetVector6Macro(Region, double);
  vtkGetVector6Macro(Region, double);
  ///@}

protected:
  vtkGraupelParticlesSource();
  ~vtkGraupelParticlesSource() override;

  /** The kind and the subclass's own parameters. */
  virtual void FillParameters(gr_particles_params *p) = 0;
  /** "Rain Particles" or "Snowfall Particles", for messages. */
  virtual const char *GetLabel() const = 0;

  int FillInputPortInformation(int port, vtkInformation *info) override;
  int FillOutputPortInformation(int port, vtkInformation *info) override;
  int RequestInformation(vtkInformation *, vtkInformationVector **,
                         vtkInformationVector *) override;
  int RequestUpdateExtent(vtkInformation *, vtkInformationVector **,
                          vtkInformationVector *) override;
  int RequestData(vtkInformation *, vtkInformationVector **, vtkInformationVector *) override;

  int Count = 0;
  int Seed = 0;
  double ExposureTime = 0.0;
  double Wind[3] = {0.0, 0.0, 0.0};
  double Region[6] = {0.0, 100.0, 0.0, 100.0, 0.0, 50.0};

private:
  // RequestData's parts: the properties (and the Input's bounds) as the
  // core's parameters; the core run and its outputs read. false / 0 after
  // one sentence.
  bool CoreParams(vtkImageData *terrain, gr_particles_params *p);
  int Compute(gr_context *ctx, const gr_particles_params &p, double time, vtkPoints *points,
              vtkSmartPointer<vtkFloatArray> *arrays);

  vtkGraupelParticlesSource(const vtkGraupelParticlesSource &) = delete;
  void operator=(const vtkGraupelParticlesSource &) = delete;

  // The core of the last update and the context it was made on: kept, so
  // that scrubbing time reuses its buffers.
  gr_particles *Core = nullptr;
  gr_context *CoreContext = nullptr;
};

#endif
