/**
 * @class   vtkEXRFieldWriter
 * @brief   Writes point arrays of a 2-D image as one multi-channel EXR.
 *
 * Each chosen point array becomes a channel of the same name (a 3-component
 * array NAME becomes NAME.x, NAME.y, NAME.z; other multi-component arrays
 * NAME.0, NAME.1, ...). Values are stored as 32-bit float (default) or half.
 * Row 0 of the image (south) is the last scanline of the file, so other
 * EXR tools show north up. The input must be a vtkImageData with one point
 * in z.
 *
 * The header also keeps the image's geometry and field data (see exr_io.h):
 * `graupel.spacing` (v2d, x and y), `graupel.origin` (v3d) and, for each
 * named numeric or string field-data array of 1 to 65536 values (a ledger's
 * `rain_volume`, `time`, ..., `graupel_device`), `graupel.field.NAME`
 * (double for one value, graupelDoubles for more, string or stringvector).
 * vtkEXRHeightFieldReader restores them.
 */
#ifndef vtkEXRFieldWriter_h
#define vtkEXRFieldWriter_h

#include "GraupelFiltersModule.h"
#include "vtkWriter.h"

#include <string>
#include <vector>

class vtkImageData;

class GRAUPELFILTERS_EXPORT vtkEXRFieldWriter : public vtkWriter {
public:
  static vtkEXRFieldWriter *New();
  vtkTypeMacro(vtkEXRFieldWriter, vtkWriter);
  void PrintSelf(ostream &os, vtkIndent indent) override;

  enum PixelTypes { HALF = 1, FLOAT = 2 };

  ///@{
  /** The .exr file to write. */
  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  ///@}

  ///@{
  /** Storage of every channel: 1 half, 2 float (default). */
  vtkSetClampMacro(PixelType, int, 1, 2);
  vtkGetMacro(PixelType, int);
  ///@}

  ///@{
  /**
   * Point arrays to write. With none chosen, every point array is written.
   */
  void AddArrayName(const char *name);
  void ClearArrayNames();
  int GetNumberOfArrayNames() const;
  const char *GetArrayName(int i) const;
  ///@}

  vtkImageData *GetInput();

protected:
  vtkEXRFieldWriter();
  ~vtkEXRFieldWriter() override;

  void WriteData() override;
  int FillInputPortInformation(int port, vtkInformation *info) override;
  /** The writer's name in its error sentences. */
  virtual const char *Label() const;
  /** The chosen point arrays as float planes, with the C views the core's writers take. */
  struct Planes {
    std::vector<std::string> names;
    std::vector<std::vector<float>> data;
    std::vector<const char *> namePtrs;
    std::vector<const float *> dataPtrs;
    int dims[3] = {0, 0, 0};
  };
  /**
   * The chosen point arrays of a 2-D input as float planes, one per
   * component (NAME.x/.y/.z for three, NAME.0, NAME.1, ... for others).
   * False, with one error sentence and the error code set, when there is no
   * FileName, the input is not 2-D, or an array asked for is missing.
   */
  bool ChoosePlanes(vtkImageData *input, Planes &out);

  char *FileName = nullptr;
  int PixelType = FLOAT;
  std::vector<std::string> ArrayNames;

private:
  vtkEXRFieldWriter(const vtkEXRFieldWriter &) = delete;
  void operator=(const vtkEXRFieldWriter &) = delete;
};

#endif
