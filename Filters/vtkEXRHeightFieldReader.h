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
  /** Point spacing in metres, x and y (default 1 1). */
  vtkSetVector2Macro(Spacing, double);
  vtkGetVector2Macro(Spacing, double);
  ///@}

  ///@{
  /** Position of the south-west point, metres (default 0 0 0). */
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

private:
  vtkEXRHeightFieldReader(const vtkEXRHeightFieldReader &) = delete;
  void operator=(const vtkEXRHeightFieldReader &) = delete;

  bool Load();
  struct Cache;
  std::unique_ptr<Cache> Loaded;
};

#endif
