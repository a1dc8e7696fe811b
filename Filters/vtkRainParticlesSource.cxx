#include "vtkRainParticlesSource.h"

#include "vtkObjectFactory.h"

#include "graupel/particles.h"

#include "GraupelParameterTable.h"

vtkStandardNewMacro(vtkRainParticlesSource);

namespace {
// The table's RainRate row (its default and its mm/h to m/s factor).
const gr_param_bound *RainRateRow() {
  int n = 0;
  const gr_param_bound *table = gr_particles_param_bounds(&n);
  return gr_param_find(table, n, "RainRate");
}
} // namespace

GRAUPEL_TABLE_SETTER(vtkRainParticlesSource, RainRate, double, gr_particles_param_bounds)

vtkRainParticlesSource::vtkRainParticlesSource() {
  this->SetNumberOfInputPorts(1);
  this->RainRate = RainRateRow()->default_value;
}

void vtkRainParticlesSource::FillParameters(gr_particles_params *p) {
  p->kind = GR_PARTICLES_RAIN;
  p->rain_rate = this->RainRate * RainRateRow()->to_core;
}

void vtkRainParticlesSource::PrintSelf(ostream &os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  os << indent << "RainRate: " << this->RainRate << " mm/h\n";
}
