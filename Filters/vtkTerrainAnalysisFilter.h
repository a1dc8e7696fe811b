/**
 * @class   vtkTerrainAnalysisFilter
 * @brief   Normals, slope, aspect, hillshade and seed 001's snow cover and
 *          cover classes of a height field, computed by OpenCL.
 *
 * Input: a 2-D vtkImageData (nx x ny x 1 points, x east, y north, spacing in
 * metres) with a one-component point array of heights in metres: `elevation`
 * by default, or any other chosen with SetInputArrayToProcess(0, 0, 0,
 * POINTS, name), e.g. `snow_surface`.
 *
 * Output: the input's arrays plus the point arrays
 * - `normal` (3 components, unit vector; the output's active normals),
 * - `slope` (degrees, 0 flat .. 90),
 * - `aspect` (degrees clockwise from north, the downslope direction; -1
 *   where flat),
 * - `hillshade` (0..1: the Lambert term of a sun at SunAzimuth and
 *   SunElevation; a flat field gives sin(SunElevation)),
 * - `snow_cover` (0..1: n_z^SnowExponent, or 1 up to RockSlope and 0 above
 *   it with CoverMode THRESHOLD),
 * - `cover_class` (unsigned char: 0 ground, 1 snow, 2 rock, 3 ice; see
 *   kernels/include/graupel/terrain_analysis.h for the rules),
 * - `shadow` (0..1, 1 lit) when ModelShadows is on, which also multiplies
 *   the hillshade by it.
 * Central differences inside the grid, one-sided on its edges. The input's
 * active scalars stay the output's.
 *
 * The ranges and defaults of the properties are the core's parameter table
 * (gr_terrain_analysis_param_bounds): each setter clamps to its row. Bad
 * input (no height array, NaN heights, a 3-D image) gives one error
 * sentence and an empty output.
 */
#ifndef vtkTerrainAnalysisFilter_h
#define vtkTerrainAnalysisFilter_h

#include "GraupelFiltersModule.h"
#include "vtkGraupelAlgorithm.h"
#include "vtkSmartPointer.h" // for the output arrays

#include <string>
#include <vector>

class vtkDataArray;
class vtkImageData;
struct gr_context;
struct gr_grid;
struct gr_terrain_analysis_params;

class GRAUPELFILTERS_EXPORT vtkTerrainAnalysisFilter : public vtkGraupelAlgorithm {
public:
  static vtkTerrainAnalysisFilter *New();
  vtkTypeMacro(vtkTerrainAnalysisFilter, vtkGraupelAlgorithm);
  void PrintSelf(ostream &os, vtkIndent indent) override;

  enum CoverModes { SMOOTH = 0, THRESHOLD = 1 };

  ///@{
  /** Degrees clockwise from north: where the sun stands (default 315, north-west). */
  virtual void SetSunAzimuth(double value);
  vtkGetMacro(SunAzimuth, double);
  ///@}

  ///@{
  /** Degrees above the horizon, above 0 (default 45). */
  virtual void SetSunElevation(double value);
  vtkGetMacro(SunElevation, double);
  ///@}

  ///@{
  /** Degrees of sun elevation over which a shadow's edge fades; 0 is hard (default 0). */
  virtual void SetPenumbraWidth(double value);
  vtkGetMacro(PenumbraWidth, double);
  ///@}

  ///@{
  /** Multiply the hillshade by the cast shadow and output `shadow` (default off). */
  vtkSetMacro(ModelShadows, bool);
  vtkGetMacro(ModelShadows, bool);
  vtkBooleanMacro(ModelShadows, bool);
  ///@}

  ///@{
  /** SMOOTH: snow_cover = n_z^SnowExponent (default); THRESHOLD: 1 up to RockSlope, else 0. */
  virtual void SetCoverMode(int value);
  vtkGetMacro(CoverMode, int);
  ///@}

  ///@{
  /** The exponent k of the smooth cover n_z^k, above 0 (default 4). */
  virtual void SetSnowExponent(double value);
  vtkGetMacro(SnowExponent, double);
  ///@}

  ///@{
  /** The snow_cover from which a point is of class snow (default 0.5). */
  virtual void SetSnowCoverLimit(double value);
  vtkGetMacro(SnowCoverLimit, double);
  ///@}

  ///@{
  /** Degrees: steeper points are rock (default 45). */
  virtual void SetRockSlope(double value);
  vtkGetMacro(RockSlope, double);
  ///@}

  ///@{
  /** Metres: lower points are ice (default 0). */
  virtual void SetWaterLevel(double value);
  vtkGetMacro(WaterLevel, double);
  ///@}

protected:
  vtkTerrainAnalysisFilter();
  ~vtkTerrainAnalysisFilter() override = default;

  int RequestUpdateExtent(vtkInformation *, vtkInformationVector **,
                          vtkInformationVector *) override;
  int RequestData(vtkInformation *, vtkInformationVector **, vtkInformationVector *) override;

  /** The name in messages ("Terrain Analysis"). */
  virtual const char *GetLabel() const { return "Terrain Analysis"; }
  /** 1: compute and output the shadow only (vtkTerrainShadowFilter). */
  virtual bool GetShadowOnly() const { return false; }

  // The properties start at the core's defaults (the constructor).
  double SunAzimuth = 0.0;
  double SunElevation = 0.0;
  double PenumbraWidth = 0.0;
  bool ModelShadows = false;
  int CoverMode = SMOOTH;
  double SnowExponent = 0.0;
  double SnowCoverLimit = 0.0;
  double RockSlope = 0.0;
  double WaterLevel = 0.0;

private:
  // RequestData's parts: the Input's heights checked (and the array's name);
  // the properties as the core's parameters; the core run (1 done, 0 failed
  // after one sentence, -1 aborted) with its output arrays.
  vtkDataArray *Heights(vtkImageData *input, std::string &name);
  bool CoreParams(struct gr_terrain_analysis_params *p);
  int Compute(struct gr_context *ctx, const struct gr_grid &grid,
              const struct gr_terrain_analysis_params &p, vtkDataArray *heights,
              const std::string &name, std::vector<vtkSmartPointer<vtkDataArray>> &arrays);

  vtkTerrainAnalysisFilter(const vtkTerrainAnalysisFilter &) = delete;
  void operator=(const vtkTerrainAnalysisFilter &) = delete;
};

#endif
