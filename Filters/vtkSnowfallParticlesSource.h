/**
 * @class   vtkSnowfallParticlesSource
 * @brief   Snowflakes (seed 001) at the requested time, computed by OpenCL.
 *
 * Each flake falls at its own speed of 0.5-1.5 m/s, drifts with the Wind and
 * sways sideways (flutter: a sine of its own phase, 0.2-0.8 Hz, and an
 * amplitude up to FlutterAmplitude); it respawns at the top once below the
 * region's bottom. Output: points with `velocity` (m/s), `size` (mm, 2-10)
 * and `streak` (m); see vtkGraupelParticlesSource for time and region and
 * kernels/include/graupel/particles.h for the model.
 */
#ifndef vtkSnowfallParticlesSource_h
#define vtkSnowfallParticlesSource_h

#include "GraupelFiltersModule.h"
#include "vtkGraupelParticlesSource.h"

class GRAUPELFILTERS_EXPORT vtkSnowfallParticlesSource : public vtkGraupelParticlesSource {
public:
  static vtkSnowfallParticlesSource *New();
  vtkTypeMacro(vtkSnowfallParticlesSource, vtkGraupelParticlesSource);
  void PrintSelf(ostream &os, vtkIndent indent) override;

  ///@{
  /** Metres: the largest sideways sway of a flake, 0 to 10 (default 0.3). */
  virtual void SetFlutterAmplitude(double value);
  vtkGetMacro(FlutterAmplitude, double);
  ///@}

protected:
  vtkSnowfallParticlesSource();
  ~vtkSnowfallParticlesSource() override = default;

  void FillParameters(gr_particles_params *p) override;
  const char *GetLabel() const override { return "Snowfall Particles"; }

  double FlutterAmplitude = 0.0;

private:
  vtkSnowfallParticlesSource(const vtkSnowfallParticlesSource &) = delete;
  void operator=(const vtkSnowfallParticlesSource &) = delete;
};

#endif
