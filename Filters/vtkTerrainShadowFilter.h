/**
 * @class   vtkTerrainShadowFilter
 * @brief   Ray-marched cast shadows of a height field (seed 001), computed
 *          by OpenCL.
 *
 * Input: as vtkTerrainAnalysisFilter (a 2-D image with a point array of
 * heights in metres, `elevation` unless another is chosen). Output: the
 * input's arrays plus `shadow` (the active scalars): 1 where the sun at
 * SunAzimuth (degrees clockwise from north) and SunElevation (degrees above
 * the horizon) is visible, 0 where the terrain hides it, and between the two
 * over a soft edge PenumbraWidth degrees of sun elevation wide. Rays that
 * leave the grid see the sky. A spike of height h casts a shadow h /
 * tan(SunElevation) long.
 *
 * It is vtkTerrainAnalysisFilter reduced to the shadow: the cover
 * properties it inherits are not used.
 */
#ifndef vtkTerrainShadowFilter_h
#define vtkTerrainShadowFilter_h

#include "GraupelFiltersModule.h"
#include "vtkTerrainAnalysisFilter.h"

class GRAUPELFILTERS_EXPORT vtkTerrainShadowFilter : public vtkTerrainAnalysisFilter {
public:
  static vtkTerrainShadowFilter *New();
  vtkTypeMacro(vtkTerrainShadowFilter, vtkTerrainAnalysisFilter);
  void PrintSelf(ostream &os, vtkIndent indent) override;

protected:
  vtkTerrainShadowFilter() = default;
  ~vtkTerrainShadowFilter() override = default;

  const char *GetLabel() const override { return "Terrain Shadow"; }
  bool GetShadowOnly() const override { return true; }

private:
  vtkTerrainShadowFilter(const vtkTerrainShadowFilter &) = delete;
  void operator=(const vtkTerrainShadowFilter &) = delete;
};

#endif
