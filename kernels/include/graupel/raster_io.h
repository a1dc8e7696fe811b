/**
 * @file raster_io.h
 * @brief GIS rasters (GeoTIFF, ESRI ASCII grids, anything GDAL reads) in and
 *        georeferenced GeoTIFF out, in metres always.
 *
 * A raster's pixels are its samples: pixel (i, j) becomes grid point (i, j)
 * at the pixel's centre, row 0 the southern row (the gr_grid convention),
 * its value a float, NaN where the raster has no data (its no-data value or
 * its mask). Spacing and origin are in metres:
 *  - a projected CRS in metres is taken as it is; one in another linear
 *    unit (feet) has its coordinates converted, and heights too when the band
 *    says its unit is that foot;
 *  - a geographic CRS (degrees) is reprojected on reading to the UTM zone of
 *    the raster's centre on the same datum (bilinear; GDAL's suggested pixel
 *    size), so that no degree is ever taken for a metre;
 *  - a raster without a CRS is taken in metres as it stands (reported in
 *    gr_raster.notes, for the caller to warn).
 * A rotated or sheared geotransform, a multi-band raster without a chosen
 * band, a band beyond the raster's, a file GDAL cannot open or read, and a
 * raster of more than GR_RASTER_MAX_POINTS points give GR_ERR_FORMAT (or
 * GR_ERR_IO, GR_ERR_TOO_LARGE) with one sentence naming the file.
 *
 * This part of the core needs GDAL (Debian's libgdal-dev); it is the library
 * graupel_raster, built beside graupel_core when GDAL is found.
 */
#ifndef GRAUPEL_RASTER_IO_H
#define GRAUPEL_RASTER_IO_H

#include "graupel/graupel.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Largest number of points (width x height) the reader allocates. */
#define GR_RASTER_MAX_POINTS ((long long)1 << 31)

/** A raster read as a grid of samples in metres. */
typedef struct gr_raster {
  int width, height;  /**< points along x (east) and y (north) */
  double spacing[2];  /**< m between points along x and y */
  double origin[2];   /**< m: the south-west point (a pixel's centre) in crs_wkt */
  float *data;        /**< width*height values, row 0 = south; NaN = no data */
  char *crs_wkt;      /**< the grid's CRS as WKT (projected, metres); NULL without one */
  char *source_crs;   /**< the file's CRS as it was (a short name or WKT); NULL without */
  int reprojected;    /**< 1: the file's CRS was geographic and the grid is its UTM zone */
  double unit_factor; /**< metres per unit of the file's coordinates (1 unless feet, ...) */
  long long no_data;  /**< points without data (NaN) */
  char notes[256];    /**< what the caller should say, e.g. "no CRS: ..."; "" if nothing */
} gr_raster;

/**
 * Reads band `band` (1-based; 0: the raster's only band) of the raster at
 * path as described above. On failure *out is untouched and err (if given)
 * holds a sentence naming the file and the fault.
 */
GR_API gr_status gr_raster_read(const char *path, int band, gr_raster *out, char *err,
                                size_t err_len);

/** 1 if GDAL opens path as a raster with at least one band (nothing is read), else 0. */
GR_API int gr_raster_can_read(const char *path);

/** Frees what gr_raster_read allocated and zeroes the struct. NULL is fine. */
GR_API void gr_raster_free(gr_raster *r);

/**
 * Writes nbands fields of width*height floats (row 0 = south) as one GeoTIFF
 * of Float32 bands, each band described by its name, NaN its no-data value,
 * with the geotransform of spacing and origin (the south-west point, a
 * pixel's centre, in metres) and crs_wkt (NULL or "": none). The file is
 * written under a temporary name in the same folder and renamed over path
 * only once complete, so a failed write leaves an earlier file whole.
 */
GR_API gr_status gr_raster_write(const char *path, int width, int height, int nbands,
                                 const char *const *names, const float *const *data,
                                 const double spacing[2], const double origin[2],
                                 const char *crs_wkt, char *err, size_t err_len);

/** What a CRS definition (WKT, PROJ string, "EPSG:n") says about units. */
typedef struct gr_raster_crs {
  char *wkt;              /**< the CRS as WKT (free with gr_raster_crs_free) */
  int geographic;         /**< 1: coordinates in degrees */
  double metres_per_unit; /**< a projected CRS's linear unit in metres (1 otherwise) */
} gr_raster_crs;

/**
 * Reads a CRS definition as GDAL does (ParaView's GDAL Raster Reader keeps
 * one as a PROJ string in the field data MAP_PROJECTION). GR_ERR_FORMAT and
 * a sentence in err when GDAL cannot read it.
 */
GR_API gr_status gr_raster_crs_describe(const char *definition, gr_raster_crs *out, char *err,
                                        size_t err_len);

/** Frees what gr_raster_crs_describe allocated and zeroes the struct. NULL is fine. */
GR_API void gr_raster_crs_free(gr_raster_crs *c);

#ifdef __cplusplus
}
#endif

#endif
