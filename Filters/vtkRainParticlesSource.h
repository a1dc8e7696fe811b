/**
 * @class   vtkRainParticlesSource
 * @brief   Rain drops (seed 004) at the requested time, computed by OpenCL.
 *
 * Drop diameters follow Marshall and Palmer's distribution for RainRate
 * (truncated to 0.1-6 mm), each drop falls at its terminal speed by
 * diameter (Gunn and Kinzer's data as fitted by Atlas et al. 1973) and
 * drifts with the Wind. Output: points with `velocity` (m/s), `diameter`
 * (mm) and `streak` (m); see vtkGraupelParticlesSource for time and region
 * and kernels/include/graupel/particles.h for the model.
 */
#ifndef vtkRainParticlesSource_h
#define vtkRainParticlesSource_h

#include "GraupelFiltersModule.h"
#include "vtkGraupelParticlesSource.h"

class GRAUPELFILTERS_EXPORT vtkRainParticlesSource : public vtkGraupelParticlesSource {
public:
  static vtkRainParticlesSource *New();
  vtkTypeMacro(vtkRainParticlesSource, vtkGraupelParticlesSource);
  void PrintSelf(ostream &os, vtkIndent indent) override;

  ///@{
  /** Rain intensity, mm/h, above 0 and at most 500 (default 10): sets the drop sizes. */
  virtual void SetRainRate(double value);
  vtkGetMacro(RainRate, double);
  ///@}

protected:
  vtkRainParticlesSource();
  ~vtkRainParticlesSource() override = default;

  void FillParameters(gr_particles_params *p) override;
  const char *GetLabel() const override { return "Rain Particles"; }

  double RainRate = 0.0;

private:
  vtkRainParticlesSource(const vtkRainParticlesSource &) = delete;
  void operator=(const vtkRainParticlesSource &) = delete;
};

#endif
