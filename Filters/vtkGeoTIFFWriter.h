/**
 * @class   vtkGeoTIFFWriter
 * @brief   Writes point arrays of a 2-D image as one georeferenced GeoTIFF,
 *          to open in QGIS or any GIS on the terrain it came from.
 *
 * Each chosen point array (none chosen: all) becomes a Float32 band named
 * after it (three components: NAME.x/.y/.z), NaN the no-data value, rows
 * north first. The geotransform comes from the image's spacing and origin
 * (metres; each point is a pixel's centre) and the CRS from the field-data
 * string `graupel_crs` that vtkGISRasterReader stored and every Graupel
 * filter passes on; without it the file has no CRS. The file is written
 * under a temporary name beside it and renamed when complete, so a failed
 * write (a full disk) leaves an earlier file whole. Errors are one sentence
 * (vtkEXRFieldWriter's, whose array choice this shares) and no file.
 */
#ifndef vtkGeoTIFFWriter_h
#define vtkGeoTIFFWriter_h

#include "GraupelFiltersModule.h"
#include "vtkEXRFieldWriter.h"

class GRAUPELFILTERS_EXPORT vtkGeoTIFFWriter : public vtkEXRFieldWriter {
public:
  static vtkGeoTIFFWriter *New();
  vtkTypeMacro(vtkGeoTIFFWriter, vtkEXRFieldWriter);

protected:
  vtkGeoTIFFWriter() = default;
  ~vtkGeoTIFFWriter() override = default;

  void WriteData() override;
  const char *Label() const override;

private:
  vtkGeoTIFFWriter(const vtkGeoTIFFWriter &) = delete;
  void operator=(const vtkGeoTIFFWriter &) = delete;
};

#endif
