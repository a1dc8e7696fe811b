#include "vtkTerrainShadowFilter.h"

#include "vtkObjectFactory.h"

vtkStandardNewMacro(vtkTerrainShadowFilter);

void vtkTerrainShadowFilter::PrintSelf(ostream &os, vtkIndent indent) {
  // The parent prints the sun; the cover properties are not this filter's.
  this->vtkGraupelAlgorithm::PrintSelf(os, indent);
  os << indent << "SunAzimuth: " << this->SunAzimuth << "\n";
  os << indent << "SunElevation: " << this->SunElevation << "\n";
  os << indent << "PenumbraWidth: " << this->PenumbraWidth << "\n";
}
