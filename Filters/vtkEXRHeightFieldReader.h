/**
 * @class   vtkEXRHeightFieldReader
 * @brief   Reads an OpenEXR image as a 2-D height field.
 *
 * Every HALF or FLOAT channel becomes a float32 point array of a 2-D
 * vtkImageData (width x height x 1) whose row 0 is the image's bottom
 * (southern) row. A single-channel file yields the array `elevation`
 * whatever its channel is called (unless the channel already has one of
 * Graupel's field names, such as `snow_depth`, which is kept); channels `NAME.x`, `NAME.y`,
 * `NAME.z` (as vtkEXRFieldWriter writes vectors) become one 3-component array NAME. `HeightScale`
 * multiplies `elevation` only (height maps are often stored normalised to 0..1). A broken or
 * hostile file gives one error sentence and an empty output.
 *
 * Geometry and field data: a file written by vtkEXRFieldWriter keeps the
 * image's spacing, origin and field data in its header (`graupel.spacing`,
 * `graupel.origin`, `graupel.field.NAME`; see exr_io.h). With
 * GeometryFromFile on (the default) the file's spacing and origin are used
 * where the file holds them, and the Spacing and Origin properties apply
 * only to files without them (other tools' EXR files: Spacing defaults to
 * 1 1). With GeometryFromFile off, Spacing and Origin always apply. Each
 * `graupel.field.NAME` becomes a field-data array NAME (vtkDoubleArray or
 * vtkStringArray). A header attribute with a bad value (a spacing that is
 * NaN, 0 or negative, too many values) is an error even when the
 * properties would override it: the file is damaged.
 */
#ifndef vtkEXRHeightFieldReader_h
#define vtkEXRHeightFieldReader_h

#include "GraupelFiltersModule.h"
#include "vtkImageAlgorithm.h"

#include <memory>

class GRAUPELFILTERS_EXPORT vtkEXRHeightFieldReader : public vtkImageAlgorithm {
public:
  static vtkEXRHeightFieldReader *New();
  vtkTypeMacro(vtkEXRHeightFieldReader, vtkImageAlgorithm);
  void PrintSelf(ostream &os, vtkIndent indent) override;

  ///@{
  /** The .exr file to read. */
  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  ///@}

  ///@{
  /**
   * 1 (default): the file's graupel.spacing and graupel.origin, where it
   * holds them, win over Spacing and Origin. 0: Spacing and Origin always.
   */
  vtkSetClampMacro(GeometryFromFile, int, 0, 1);
  vtkGetMacro(GeometryFromFile, int);
  vtkBooleanMacro(GeometryFromFile, int);
  ///@}

  ///@{
  /**
   * Point spacing in metres, x and y (default 1 1), for files without
   * graupel.spacing or with GeometryFromFile off.
   */
  vtkSetVector2Macro(Spacing, double);
  vtkGetVector2Macro(Spacing, double);
  ///@}

  ///@{
  /**
   * Position of the south-west point, metres (default 0 0 0), for files
   * without graupel.origin or with GeometryFromFile off.
   */
  vtkSetVector3Macro(Origin, double);
  vtkGetVector3Macro(Origin, double);
  ///@}

  ///@{
  /** Factor applied to `elevation` (default 1). */
  vtkSetMacro(HeightScale, double);
  vtkGetMacro(HeightScale, double);
  ///@}

  /** 1 when the file starts with the OpenEXR magic number. */
  static int CanReadFile(const char *filename);

protected:
  vtkEXRHeightFieldReader();
  ~vtkEXRHeightFieldReader() override;

  int RequestInformation(vtkInformation *, vtkInformationVector **,
                         vtkInformationVector *) override;
  int RequestData(vtkInformation *, vtkInformationVector **, vtkInformationVector *) override;

  char *FileName = nullptr;
  double Spacing[2] = {1.0, 1.0};
  double Origin[3] = {0.0, 0.0, 0.0};
  double HeightScale = 1.0;
  int GeometryFromFile = 1;

private:
  vtkEXRHeightFieldReader(const vtkEXRHeightFieldReader &) = delete;
  void operator=(const vtkEXRHeightFieldReader &) = delete;

  bool Load();
  // The spacing and origin the output gets (file or properties).
  void Geometry(double spacing[3], double origin[3]) const;
  struct Cache;
  std::unique_ptr<Cache> Loaded;
};

#endif
