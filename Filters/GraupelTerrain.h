/**
 * The heights a terrain filter reads, from any array, point or cell data
 * (private to Graupel::Filters).
 *
 * Every filter that takes a terrain takes its heights from the array chosen
 * as its Height Array (SetInputArrayToProcess(0, ...), ParaView's input-array
 * selection); with none chosen, or "elevation" chosen and absent, the first
 * of: a point array `elevation`, a cell array `elevation`, the active point
 * scalars, the only one-component point array, the active cell scalars, the
 * only one-component cell array. So a Graupel terrain gives `elevation` and
 * ParaView's GDAL Raster Reader gives its cell array `Elevation` untouched.
 *
 * A raster's cells are its samples: when the heights are cell data the
 * filter sees a TerrainView, an image whose points are the cells' centres
 * (extent one point shorter in x and y, origin half a cell on) and whose
 * point data are the cell arrays. Its `elevation` is the chosen array as
 * floats, NaN where the raster has no data (a blanked/hidden ghost cell or
 * point, or the NO_DATA_VALUE ParaView's reader keeps). A CRS ParaView's
 * reader keeps (MAP_PROJECTION) becomes `graupel_crs`; one in degrees is
 * refused with one sentence (Graupel's GIS Raster Reader reprojects it), one
 * in feet has the spacing and origin converted to metres.
 *
 * The output extent of a filter whose heights are cells is decided in
 * RequestInformation (HeightsAreCells), before the data are read: from the
 * association chosen, else from the input's data, and when the input has
 * none yet (a first update), by updating the input once there.
 */
#ifndef GraupelTerrain_h
#define GraupelTerrain_h

#include "vtkSmartPointer.h"
#include "vtkType.h"

#include <string>

class vtkAlgorithm;
class vtkDataArray;
class vtkDataSet;
class vtkImageData;
class vtkInformation;
class vtkInformationVector;

namespace graupel {

/** The heights asked for: a name ("" for the default rule) and an association (-1 any). */
struct HeightsChoice {
  std::string name;
  int association = -1;
};

/**
 * The Height Array of alg (input array 0). A choice of another kind than
 * point or cell data (a table's column, field data: ParaView fills the
 * property from whatever source was active when the filter was made) is no
 * choice: the default rule.
 */
HeightsChoice ChosenHeights(vtkAlgorithm *alg);

/**
 * The choice that holds for data: the chosen array when data have it (or
 * when data have no arrays to tell), else the default rule, *replaced set
 * (ParaView keeps a Height Array when the Input changes; the caller warns).
 */
HeightsChoice EffectiveHeights(vtkDataSet *data, const HeightsChoice &choice, bool *replaced);

/**
 * The heights of data by the choice: the array, and its association in
 * *association (vtkDataObject::FIELD_ASSOCIATION_POINTS or _CELLS); nullptr
 * and a phrase in *why when there is none.
 */
vtkDataArray *FindHeights(vtkDataSet *data, const HeightsChoice &choice, int *association,
                          std::string *why);

/**
 * In RequestInformation: 1 when the heights on input port `port` of alg are
 * cell data. Updates the input first when it holds no data yet and nothing
 * chosen says the association.
 */
bool HeightsAreCells(vtkAlgorithm *alg, int port);

/**
 * In RequestInformation of a filter whose heights are cells: every image
 * output announced with the input's extent gets the cells' centres' extent
 * and origin.
 */
void CellCentreInformation(vtkInformation *inInfo, vtkInformationVector *outInfo);

/** The cached view of one input; see the file comment. */
class TerrainView {
public:
  /**
   * What the filter should read for `input`: input itself when its heights
   * are point data without no-data marks in metres, else the view (whose
   * `elevation` is the heights). nullptr with a sentence in *error (naming label and
   * inputName) when the input's CRS is in degrees. Heights not found: input
   * itself, for the filter to say so (the view cannot help).
   */
  vtkImageData *Get(vtkImageData *input, const HeightsChoice &choice, const std::string &label,
                    const char *inputName, std::string *error);

  /**
   * Another image input of a filter whose terrain's heights are cells: as a
   * view of cell centres when it is that raster's size (cells as points),
   * else input itself.
   */
  vtkImageData *Other(vtkImageData *input, const int terrainDims[3]);

  /** The view last built (nullptr before one). */
  vtkImageData *Current() const { return this->View; }

  /** Forgets the cached view. */
  void Clear();

private:
  vtkSmartPointer<vtkImageData> View;
  vtkImageData *Source = nullptr;
  vtkMTimeType SourceTime = 0;
  std::string Key;
};

/** The error sentence for an input without heights (phrase from FindHeights). */
std::string NoHeightsSentence(const std::string &label, const char *inputName,
                              const std::string &why);

} // namespace graupel

#endif
