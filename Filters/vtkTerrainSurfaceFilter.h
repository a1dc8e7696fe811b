/**
 * @class   vtkTerrainSurfaceFilter
 * @brief   A height field as a lit 3-D surface: the look every Graupel
 *          terrain output gets in the render view.
 *
 * Input: a 2-D vtkImageData (nx x ny x 1 points, x east, y north) with a
 * one-component point array of heights in metres, as every Graupel terrain
 * output has (Procedural Terrain, the EXR reader, Rain Runoff, the snow
 * filters, Terrain Analysis and Shadow, Water Surface).
 *
 * Output: a vtkPolyData of (nx - 1)(ny - 1) quads whose point z is the
 * image's z plus VerticalExaggeration times the height array, with the
 * input's point arrays, point normals `Normals` of the exaggerated surface
 * (central differences inside, one-sided on the edges, so the edges shade
 * like the inside) and, with Skirt on, walls from the edge down to
 * SkirtDepth below the lowest height, so that a valley cut by the edge reads
 * as a notch in a solid block, not as a sheet hanging in the air. The field
 * data `vertical_exaggeration` holds the factor for captions.
 *
 * HeightArray and ColorArray empty (the defaults) choose by the data: the
 * height is water_surface, else snow_surface, else elevation; the colour
 * (the output's active scalars, which ParaView colours by on Apply) is
 * water_depth, else snow_depth, else cover_class, else shadow, else
 * elevation; water_depth and max_depth are shown through
 * `water_depth_display` (NaN where drier than WettingDepth). The plugin's colour maps
 * (Plugin/GraupelColorMaps.json) are the defaults for those arrays.
 *
 * A grid of more than MaximumPoints points (default 2048 x 2048) is drawn at
 * every k-th row and column, k in the field data `surface_stride`.
 *
 * NaN heights are no-data points (a raster's no-data, the outside of Rain
 * Runoff's domain): no quad or wall touches them, so the surface ends at
 * the data's edge.
 *
 * Bad input (not an image, 3-D, no height array, an infinite height, no
 * height at all) gives
 * one error sentence and an empty output, as does a terrain whose surface
 * would not fit in the memory the process can get (about 84 bytes a point:
 * 34 GB for 20000 x 20000), refused before anything is allocated. A large
 * terrain reports progress and honours an abort every million points.
 */
#ifndef vtkTerrainSurfaceFilter_h
#define vtkTerrainSurfaceFilter_h

#include "GraupelFiltersModule.h"
#include "vtkPolyDataAlgorithm.h"

#include <string>

class vtkCellArray;
class vtkFloatArray;
namespace graupel {
class TerrainView;
}
class vtkImageData;
class vtkPointData;
class vtkPoints;

class GRAUPELFILTERS_EXPORT vtkTerrainSurfaceFilter : public vtkPolyDataAlgorithm {
public:
  static vtkTerrainSurfaceFilter *New();
  vtkTypeMacro(vtkTerrainSurfaceFilter, vtkPolyDataAlgorithm);
  void PrintSelf(ostream &os, vtkIndent indent) override;

  ///@{
  /** The height's scale factor (default 2); 0 gives the flat image. */
  vtkSetClampMacro(VerticalExaggeration, double, 0.0, 1000.0);
  vtkGetMacro(VerticalExaggeration, double);
  ///@}

  ///@{
  /** The point array of heights (m); empty: chosen by the data. */
  virtual void SetHeightArray(const char *name);
  const char *GetHeightArray() const { return this->HeightArray.c_str(); }
  ///@}

  ///@{
  /** The point array made the active scalars; empty: chosen by the data. */
  virtual void SetColorArray(const char *name);
  const char *GetColorArray() const { return this->ColorArray.c_str(); }
  ///@}

  ///@{
  /** Walls along the edges down to the base (default on). */
  vtkSetMacro(Skirt, bool);
  vtkGetMacro(Skirt, bool);
  vtkBooleanMacro(Skirt, bool);
  ///@}

  ///@{
  /** The base of the walls, metres of height below the lowest point (default 0). */
  vtkSetClampMacro(SkirtDepth, double, 0.0, 1.0e6);
  vtkGetMacro(SkirtDepth, double);
  ///@}

  ///@{
  /**
   * Water shallower than this (m, default 0.01) is dry ground: coloured by
   * water_depth or max_depth, the output's active scalars are
   * `water_depth_display`, the depth where at least this, NaN elsewhere.
   */
  vtkSetClampMacro(WettingDepth, double, 0.0, 1.0e3);
  vtkGetMacro(WettingDepth, double);
  ///@}

  ///@{
  /**
   * The most points the surface draws (default 4194304, a 2048 x 2048
   * grid; 0 draws every point). A larger grid is drawn at every k-th row
   * and column (and its last ones, keeping its extent), k the smallest
   * stride that fits; the field data `surface_stride` holds k. A 20000 x
   * 20000 terrain would otherwise take 34 GB and minutes to render.
   */
  vtkSetClampMacro(MaximumPoints, vtkIdType, 0, VTK_ID_MAX);
  vtkGetMacro(MaximumPoints, vtkIdType);
  ///@}

  /** The height array chosen for `input` (HeightArray, or by the data); nullptr if none. */
  static const char *ChooseHeightArray(vtkDataObject *input, const std::string &wanted);
  /** The colour array chosen for `input` (ColorArray, or by the data); nullptr if none. */
  static const char *ChooseColorArray(vtkDataObject *input, const std::string &wanted);

protected:
  vtkTerrainSurfaceFilter();
  ~vtkTerrainSurfaceFilter() override;

  int FillInputPortInformation(int port, vtkInformation *info) override;
  int RequestUpdateExtent(vtkInformation *, vtkInformationVector **,
                          vtkInformationVector *) override;
  int RequestData(vtkInformation *, vtkInformationVector **, vtkInformationVector *) override;
  /** Consumes an abort and marks the output aborted (RequestData returns 1 then). */
  void ConsumeAbort();

  // RequestData's parts: the input checked, the grid drawn and its memory;
  // the lowest height; the top's points and normals; the quads and walls;
  // the colour array. false after one sentence (or, Aborted, an abort).
  struct Surface;
  bool Prepare(vtkImageData *input, Surface &g);
  bool Lowest(Surface &g);
  bool Aborted(vtkPolyData *output, const Surface &g, int row, double share, double done);
  bool TopPoints(const Surface &g, vtkPoints *points, vtkFloatArray *normals, vtkPolyData *output);
  bool Quads(const Surface &g, vtkPoints *points, vtkFloatArray *normals, vtkPolyData *output,
             vtkCellArray *polys);
  void Colour(vtkImageData *input, vtkPointData *outPD);

  double VerticalExaggeration = 2.0;
  std::string HeightArray;
  std::string ColorArray;
  bool Skirt = true;
  double SkirtDepth = 0.0;
  double WettingDepth = 0.01;
  vtkIdType MaximumPoints = 4194304;

private:
  // The view of a raster's cells as points (GraupelTerrain.h), kept between updates.
  graupel::TerrainView *CellView;
  vtkTerrainSurfaceFilter(const vtkTerrainSurfaceFilter &) = delete;
  void operator=(const vtkTerrainSurfaceFilter &) = delete;
};

#endif
