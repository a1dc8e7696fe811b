/**
 * @class   vtkGISRasterReader
 * @brief   A GIS raster (GeoTIFF, ESRI ASCII grid, SRTM tile, VRT, anything
 *          GDAL reads) as a terrain in metres, ready for every Graupel filter.
 *
 * The raster's pixels are its samples: each becomes a point at the pixel's
 * centre of a 2-D vtkImageData, row 0 the southern row, its value in the
 * point array `elevation` (m), NaN where the raster has no data (its
 * no-data value or mask), so that Rain Runoff takes those cells as outside
 * its domain. Spacing and origin are metres in the raster's projected CRS: a
 * CRS in feet is converted, one in degrees (geographic) is reprojected to
 * the UTM zone of the raster's centre on its own datum, and a raster without
 * a CRS is taken in metres with a warning. The CRS goes with the data as
 * the field-data string `graupel_crs` (WKT), which every Graupel filter
 * passes on to its outputs and vtkGeoTIFFWriter writes back; the file's own
 * CRS is in `graupel_source_crs`.
 *
 * `Band` picks the band of heights (1-based; 0, the default, takes a
 * raster's only band). A file GDAL cannot read, a rotated geotransform, a
 * multi-band raster without a band chosen, or a band it lacks give one error
 * sentence and an empty output. The work is gr_raster_read's
 * (graupel/raster_io.h).
 */
#ifndef vtkGISRasterReader_h
#define vtkGISRasterReader_h

#include "GraupelFiltersModule.h"
#include "vtkImageAlgorithm.h"

#include <memory>

class GRAUPELFILTERS_EXPORT vtkGISRasterReader : public vtkImageAlgorithm {
public:
  static vtkGISRasterReader *New();
  vtkTypeMacro(vtkGISRasterReader, vtkImageAlgorithm);
  void PrintSelf(ostream &os, vtkIndent indent) override;

  ///@{
  /** The raster file to read. */
  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  ///@}

  ///@{
  /** The band of heights, from 1; 0 (default): the raster's only band. */
  vtkSetClampMacro(Band, int, 0, 65535);
  vtkGetMacro(Band, int);
  ///@}

  /** Whether GDAL opens the file as a raster. */
  static int CanReadFile(const char *filename);

protected:
  vtkGISRasterReader();
  ~vtkGISRasterReader() override;

  int RequestInformation(vtkInformation *, vtkInformationVector **,
                         vtkInformationVector *) override;
  int RequestData(vtkInformation *, vtkInformationVector **, vtkInformationVector *) override;

  char *FileName = nullptr;
  int Band = 0;

private:
  struct Cache;
  std::unique_ptr<Cache> Loaded;
  bool Load();

  vtkGISRasterReader(const vtkGISRasterReader &) = delete;
  void operator=(const vtkGISRasterReader &) = delete;
};

#endif
