#include "vtkSnowfallParticlesSource.h"

#include "vtkObjectFactory.h"

#include "graupel/particles.h"

#include "GraupelParameterTable.h"

vtkStandardNewMacro(vtkSnowfallParticlesSource);

GRAUPEL_TABLE_SETTER(vtkSnowfallParticlesSource, FlutterAmplitude, double,
                     gr_particles_param_bounds)

vtkSnowfallParticlesSource::vtkSnowfallParticlesSource() {
  this->SetNumberOfInputPorts(1);
  gr_particles_params p;
  gr_particles_params_init(&p);
  this->FlutterAmplitude = p.flutter_amplitude;
}

void vtkSnowfallParticlesSource::FillParameters(gr_particles_params *p) {
  p->kind = GR_PARTICLES_SNOW;
  p->flutter_amplitude = this->FlutterAmplitude;
}

void vtkSnowfallParticlesSource::PrintSelf(ostream &os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FlutterAmplitude: " << this->FlutterAmplitude << " m\n";
}
