/* GIS rasters through GDAL's C API: read as a grid of samples in metres,
 * written as a georeferenced GeoTIFF (see graupel/raster_io.h). */
#include "graupel/raster_io.h"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_string.h>
#include <gdal.h>
#include <gdal_utils.h>
#include <ogr_srs_api.h>

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static void gr_raster_say(char *err, size_t len, const char *fmt, ...) {
  if (!err || len == 0)
    return;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(err, len, fmt, ap);
  va_end(ap);
}

/* Ends the sentence in err with a period (GDAL's messages often have none). */
static void gr_raster_end_sentence(char *err, size_t len) {
  if (!err || len < 2)
    return;
  size_t n = strlen(err);
  while (n > 0 && (err[n - 1] == ' ' || err[n - 1] == '\n'))
    err[--n] = '\0';
  if (n > 0 && err[n - 1] != '.' && n + 1 < len) {
    err[n] = '.';
    err[n + 1] = '\0';
  }
}

/* GDAL's last message, or a fallback; never NULL. */
static const char *gr_raster_gdal_message(const char *fallback) {
  const char *m = CPLGetLastErrorMsg();
  return (m && m[0]) ? m : fallback;
}

static char *gr_raster_strdup(const char *s) {
  if (!s)
    return NULL;
  size_t n = strlen(s) + 1;
  char *c = malloc(n);
  if (c)
    memcpy(c, s, n);
  return c;
}

/* Metres per unit of a band's heights: its unit type when it names a foot. */
static double gr_raster_height_factor(GDALRasterBandH band) {
  const char *u = GDALGetRasterUnitType(band);
  if (!u)
    return 1.0;
  if (EQUAL(u, "US survey foot") || EQUAL(u, "US survey feet") || EQUAL(u, "ftUS"))
    return 1200.0 / 3937.0;
  if (EQUAL(u, "ft") || EQUAL(u, "foot") || EQUAL(u, "feet"))
    return 0.3048;
  return 1.0;
}

/* The raster reprojected to the UTM zone of its centre, on its own datum,
 * as an in-memory dataset of Float32 bands with NaN where there is no data. */
static GDALDatasetH gr_raster_to_utm(GDALDatasetH ds, OGRSpatialReferenceH geo, const double gt[6],
                                     char **utm_wkt) {
  const int w = GDALGetRasterXSize(ds), h = GDALGetRasterYSize(ds);
  const double lon = gt[0] + 0.5 * w * gt[1], lat = gt[3] + 0.5 * h * gt[5];
  int zone = (int)floor((lon + 180.0) / 6.0) + 1;
  zone = zone < 1 ? 1 : (zone > 60 ? 60 : zone);
  OGRSpatialReferenceH utm = OSRNewSpatialReference(NULL);
  GDALDatasetH out = NULL;
  char name[160];
  const char *datum = OSRGetAttrValue(geo, "GEOGCS", 0);
  snprintf(name, sizeof name, "%s / UTM zone %d%c", datum ? datum : "unknown datum", zone,
           lat >= 0.0 ? 'N' : 'S');
  if (utm && OSRCopyGeogCSFrom(utm, geo) == OGRERR_NONE && OSRSetProjCS(utm, name) == OGRERR_NONE &&
      OSRSetUTM(utm, zone, lat >= 0.0) == OGRERR_NONE &&
      OSRExportToWkt(utm, utm_wkt) == OGRERR_NONE) {
    char *argv[] = {"-of", "MEM",     "-t_srs",     *utm_wkt, "-r", "bilinear",
                    "-ot", "Float32", "-dstnodata", "nan",    NULL};
    GDALWarpAppOptions *opts = GDALWarpAppOptionsNew(argv, NULL);
    if (opts) {
      out = GDALWarp("", NULL, 1, &ds, opts, NULL);
      GDALWarpAppOptionsFree(opts);
    }
  }
  if (utm)
    OSRDestroySpatialReference(utm);
  return out;
}

/* Reads the band into data (row 0 south), NaN where no data; returns the
 * count of such points, or -1 on a read error. */
static long long gr_raster_read_band(GDALRasterBandH band, int w, int h, int south_up,
                                     double height_factor, float *data) {
  if (GDALRasterIO(band, GF_Read, 0, 0, w, h, data, w, h, GDT_Float32, 0, 0) != CE_None)
    return -1;
  int has = 0;
  const double nodata = GDALGetRasterNoDataValue(band, &has);
  const int flags = GDALGetMaskFlags(band);
  unsigned char *mask = NULL;
  if (!(flags & (GMF_ALL_VALID | GMF_NODATA))) {
    mask = malloc((size_t)w * (size_t)h);
    if (!mask || GDALRasterIO(GDALGetMaskBand(band), GF_Read, 0, 0, w, h, mask, w, h, GDT_Byte, 0,
                              0) != CE_None) {
      free(mask);
      return -1;
    }
  }
  const float nd = (float)nodata;
  long long missing = 0;
  for (size_t k = 0; k < (size_t)w * (size_t)h; ++k) {
    float v = data[k];
    if ((has && (v == nd || (isnan(nd) && isnan(v)))) || (mask && mask[k] == 0) || !isfinite(v)) {
      data[k] = NAN;
      ++missing;
    } else if (height_factor != 1.0) {
      data[k] = (float)(v * height_factor);
    }
  }
  free(mask);
  if (!south_up) { /* the file's row 0 is north: flip to row 0 south */
    float *tmp = malloc(sizeof(float) * (size_t)w);
    if (!tmp)
      return -1;
    for (int j = 0; j < h / 2; ++j) {
      float *a = data + (size_t)j * w, *b = data + (size_t)(h - 1 - j) * w;
      memcpy(tmp, a, sizeof(float) * (size_t)w);
      memcpy(a, b, sizeof(float) * (size_t)w);
      memcpy(b, tmp, sizeof(float) * (size_t)w);
    }
    free(tmp);
  }
  return missing;
}

/* The grid of dataset ds (maybe reprojected): geometry and values into out. */
static gr_status gr_raster_fill(const char *path, GDALDatasetH ds, int band_index, double unit,
                                int has_gt, gr_raster *out, char *err, size_t err_len) {
  const int w = GDALGetRasterXSize(ds), h = GDALGetRasterYSize(ds);
  double gt[6] = {0.0, 1.0, 0.0, (double)h, 0.0, -1.0};
  if (has_gt && GDALGetGeoTransform(ds, gt) != CE_None) {
    gr_raster_say(err, err_len, "'%s' has no usable geotransform.", path);
    return GR_ERR_FORMAT;
  }
  if (gt[2] != 0.0 || gt[4] != 0.0) {
    gr_raster_say(err, err_len,
                  "'%s' has a rotated or sheared geotransform (%g, %g); Graupel needs a grid "
                  "aligned with its axes: warp it first (gdalwarp).",
                  path, gt[2], gt[4]);
    return GR_ERR_FORMAT;
  }
  if (!(gt[1] > 0.0) || gt[5] == 0.0 || !isfinite(gt[0]) || !isfinite(gt[3])) {
    gr_raster_say(err, err_len, "'%s' has a pixel size of %g x %g; it must be finite and above 0.",
                  path, gt[1], fabs(gt[5]));
    return GR_ERR_FORMAT;
  }
  if ((long long)w * (long long)h > GR_RASTER_MAX_POINTS) {
    gr_raster_say(err, err_len, "'%s' is %d x %d points, more than the %lld a raster may have.",
                  path, w, h, (long long)GR_RASTER_MAX_POINTS);
    return GR_ERR_TOO_LARGE;
  }
  GDALRasterBandH band = GDALGetRasterBand(ds, band_index);
  float *data = malloc(sizeof(float) * (size_t)w * (size_t)h);
  if (!data) {
    gr_raster_say(err, err_len, "'%s' (%d x %d points) does not fit in memory.", path, w, h);
    return GR_ERR_OUT_OF_MEMORY;
  }
  const int south_up = gt[5] > 0.0;
  const long long missing =
      gr_raster_read_band(band, w, h, south_up, gr_raster_height_factor(band), data);
  if (missing < 0) {
    free(data);
    gr_raster_say(err, err_len, "'%s' could not be read: %s", path,
                  gr_raster_gdal_message("a read failed."));
    return GR_ERR_IO;
  }
  out->width = w;
  out->height = h;
  out->spacing[0] = gt[1] * unit;
  out->spacing[1] = fabs(gt[5]) * unit;
  out->origin[0] = (gt[0] + 0.5 * gt[1]) * unit;
  out->origin[1] = (south_up ? gt[3] + 0.5 * gt[5] : gt[3] + (h - 0.5) * gt[5]) * unit;
  out->data = data;
  out->no_data = missing;
  out->unit_factor = unit;
  return GR_OK;
}

gr_status gr_raster_read(const char *path, int band, gr_raster *out, char *err, size_t err_len) {
  if (!path || !path[0] || !out) {
    gr_raster_say(err, err_len, "gr_raster_read needs a file name and a place for the raster.");
    return GR_ERR_INVALID_ARGUMENT;
  }
  GDALAllRegister();
  CPLPushErrorHandler(CPLQuietErrorHandler);
  CPLErrorReset();
  gr_raster r;
  memset(&r, 0, sizeof r);
  gr_status st = GR_OK;
  GDALDatasetH ds = GDALOpenEx(path, GDAL_OF_RASTER | GDAL_OF_READONLY, NULL, NULL, NULL);
  GDALDatasetH warped = NULL;
  char *utm_wkt = NULL;
  if (!ds) {
    gr_raster_say(err, err_len, "'%s' could not be opened as a raster: %s", path,
                  gr_raster_gdal_message("no GDAL driver reads it."));
    gr_raster_end_sentence(err, err_len);
    CPLPopErrorHandler();
    return GR_ERR_IO;
  }
  const int bands = GDALGetRasterCount(ds);
  if (bands < 1) {
    gr_raster_say(err, err_len, "'%s' has no raster band.", path);
    st = GR_ERR_FORMAT;
  } else if (band == 0 && bands > 1) {
    gr_raster_say(err, err_len, "'%s' has %d bands; choose the band of heights (Band 1 to %d).",
                  path, bands, bands);
    st = GR_ERR_FORMAT;
  } else if (band < 0 || band > bands) {
    gr_raster_say(err, err_len, "'%s' has %d band%s; there is no band %d.", path, bands,
                  bands == 1 ? "" : "s", band);
    st = GR_ERR_FORMAT;
  }
  double gt[6];
  const int has_gt = GDALGetGeoTransform(ds, gt) == CE_None;
  OGRSpatialReferenceH srs = GDALGetSpatialRef(ds);
  double unit = 1.0;
  if (st == GR_OK && srs && OSRIsGeographic(srs)) {
    if (!has_gt || gt[2] != 0.0 || gt[4] != 0.0) {
      st = gr_raster_fill(path, ds, band ? band : 1, 1.0, has_gt, &r, err, err_len);
    } else if (!(warped = gr_raster_to_utm(ds, srs, gt, &utm_wkt))) {
      gr_raster_say(err, err_len,
                    "'%s' is in geographic coordinates and could not be "
                    "reprojected to metres: %s",
                    path, gr_raster_gdal_message("GDALWarp failed."));
      st = GR_ERR_FORMAT;
    } else {
      st = gr_raster_fill(path, warped, band ? band : 1, 1.0, 1, &r, err, err_len);
      r.reprojected = 1;
      r.crs_wkt = gr_raster_strdup(utm_wkt);
    }
  } else if (st == GR_OK) {
    if (srs && OSRIsProjected(srs))
      unit = OSRGetLinearUnits(srs, NULL);
    if (!(unit > 0.0) || !isfinite(unit))
      unit = 1.0;
    st = gr_raster_fill(path, ds, band ? band : 1, unit, has_gt, &r, err, err_len);
    if (st == GR_OK && srs) {
      char *wkt = NULL;
      if (OSRExportToWkt(srs, &wkt) == OGRERR_NONE)
        r.crs_wkt = gr_raster_strdup(wkt);
      CPLFree(wkt);
    }
    if (st == GR_OK && !srs)
      snprintf(r.notes, sizeof r.notes,
               "'%s' has no coordinate reference system: its %s taken as metres", path,
               has_gt ? "pixel size and origin are" : "pixels are 1 m apart, and");
  }
  if (st == GR_OK && srs) {
    const char *auth = OSRGetAuthorityName(srs, NULL), *code = OSRGetAuthorityCode(srs, NULL);
    char name[64];
    if (auth && code) {
      snprintf(name, sizeof name, "%s:%s", auth, code);
      r.source_crs = gr_raster_strdup(name);
    } else {
      char *wkt = NULL;
      if (OSRExportToWkt(srs, &wkt) == OGRERR_NONE)
        r.source_crs = gr_raster_strdup(wkt);
      CPLFree(wkt);
    }
  }
  if (warped)
    GDALClose(warped);
  GDALClose(ds);
  CPLFree(utm_wkt);
  CPLPopErrorHandler();
  if (st != GR_OK) {
    gr_raster_free(&r);
    gr_raster_end_sentence(err, err_len);
    return st;
  }
  *out = r;
  return GR_OK;
}

int gr_raster_can_read(const char *path) {
  if (!path || !path[0])
    return 0;
  GDALAllRegister();
  CPLPushErrorHandler(CPLQuietErrorHandler);
  GDALDatasetH ds = GDALOpenEx(path, GDAL_OF_RASTER | GDAL_OF_READONLY, NULL, NULL, NULL);
  const int ok = ds && GDALGetRasterCount(ds) > 0;
  if (ds)
    GDALClose(ds);
  CPLPopErrorHandler();
  return ok;
}

void gr_raster_free(gr_raster *r) {
  if (!r)
    return;
  free(r->data);
  free(r->crs_wkt);
  free(r->source_crs);
  memset(r, 0, sizeof *r);
}

/* Writes the bands into the open dataset: rows flipped to north first. */
static int gr_raster_write_bands(GDALDatasetH ds, int w, int h, int nbands,
                                 const char *const *names, const float *const *data) {
  for (int b = 0; b < nbands; ++b) {
    GDALRasterBandH band = GDALGetRasterBand(ds, b + 1);
    for (int row = 0; row < h; ++row) {
      const float *src = data[b] + (size_t)(h - 1 - row) * (size_t)w;
      if (GDALRasterIO(band, GF_Write, 0, row, w, 1, (void *)src, w, 1, GDT_Float32, 0, 0) !=
          CE_None)
        return 0;
    }
    GDALSetDescription(band, names[b]);
    if (GDALSetRasterNoDataValue(band, NAN) != CE_None)
      return 0;
  }
  return 1;
}

gr_status gr_raster_write(const char *path, int width, int height, int nbands,
                          const char *const *names, const float *const *data,
                          const double spacing[2], const double origin[2], const char *crs_wkt,
                          char *err, size_t err_len) {
  if (!path || !path[0] || width < 1 || height < 1 || nbands < 1 || !names || !data || !spacing ||
      !origin || !(spacing[0] > 0.0) || !(spacing[1] > 0.0) || !isfinite(origin[0]) ||
      !isfinite(origin[1])) {
    gr_raster_say(err, err_len,
                  "gr_raster_write needs a file name, at least one band of at least "
                  "1 x 1 points, a spacing above 0 and a finite origin.");
    return GR_ERR_INVALID_ARGUMENT;
  }
  for (int b = 0; b < nbands; ++b) {
    if (!names[b] || !data[b]) {
      gr_raster_say(err, err_len, "gr_raster_write: band %d has no name or no values.", b + 1);
      return GR_ERR_INVALID_ARGUMENT;
    }
  }
  GDALAllRegister();
  CPLPushErrorHandler(CPLQuietErrorHandler);
  CPLErrorReset();
  double unit = 1.0; /* metres per unit of the CRS: the geotransform is in its units */
  OGRSpatialReferenceH srs = NULL;
  if (crs_wkt && crs_wkt[0]) {
    srs = OSRNewSpatialReference(NULL);
    if (!srs || OSRImportFromWkt(srs, (char **)&crs_wkt) != OGRERR_NONE) {
      gr_raster_say(err, err_len, "'%s' was not written: its CRS could not be read (%s).", path,
                    gr_raster_gdal_message("not WKT"));
      if (srs)
        OSRDestroySpatialReference(srs);
      CPLPopErrorHandler();
      return GR_ERR_INVALID_ARGUMENT;
    }
    if (OSRIsProjected(srs))
      unit = OSRGetLinearUnits(srs, NULL);
    if (!(unit > 0.0) || !isfinite(unit))
      unit = 1.0;
  }
  char tmp[4096];
  snprintf(tmp, sizeof tmp, "%s.tmp%ld", path, (long)getpid());
  GDALDriverH drv = GDALGetDriverByName("GTiff");
  char **opts = NULL;
  opts = CSLSetNameValue(opts, "COMPRESS", "DEFLATE");
  opts = CSLSetNameValue(opts, "PREDICTOR", "3");
  opts = CSLSetNameValue(opts, "BIGTIFF", "IF_SAFER");
  GDALDatasetH ds = drv ? GDALCreate(drv, tmp, width, height, nbands, GDT_Float32, opts) : NULL;
  CSLDestroy(opts);
  int ok = ds != NULL;
  if (ok) {
    double gt[6] = {(origin[0] - 0.5 * spacing[0]) / unit,
                    spacing[0] / unit,
                    0.0,
                    (origin[1] + (height - 0.5) * spacing[1]) / unit,
                    0.0,
                    -spacing[1] / unit};
    ok = GDALSetGeoTransform(ds, gt) == CE_None;
    if (ok && srs)
      ok = GDALSetSpatialRef(ds, srs) == CE_None;
    if (ok)
      ok = gr_raster_write_bands(ds, width, height, nbands, names, data);
    GDALClose(ds);
    ok = ok && CPLGetLastErrorType() < CE_Failure;
  }
  if (srs)
    OSRDestroySpatialReference(srs);
  gr_status st = GR_OK;
  if (!ok) {
    gr_raster_say(err, err_len, "'%s' was not written: %s", path,
                  gr_raster_gdal_message("GDAL could not create a GeoTIFF there."));
    st = GR_ERR_IO;
  } else if (rename(tmp, path) != 0) {
    gr_raster_say(err, err_len, "'%s' was not written: the finished file could not replace it.",
                  path);
    st = GR_ERR_IO;
  }
  if (st != GR_OK) {
    VSIUnlink(tmp);
    gr_raster_end_sentence(err, err_len);
  }
  CPLPopErrorHandler();
  return st;
}

gr_status gr_raster_crs_describe(const char *definition, gr_raster_crs *out, char *err,
                                 size_t err_len) {
  if (!out || !definition || !definition[0]) {
    gr_raster_say(err, err_len, "No coordinate reference system was given.");
    return GR_ERR_INVALID_ARGUMENT;
  }
  memset(out, 0, sizeof *out);
  CPLPushErrorHandler(CPLQuietErrorHandler);
  OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
  gr_status st = GR_OK;
  char *wkt = NULL;
  if (!srs || OSRSetFromUserInput(srs, definition) != OGRERR_NONE ||
      OSRExportToWkt(srs, &wkt) != OGRERR_NONE) {
    gr_raster_say(err, err_len, "The coordinate reference system '%.80s' could not be read: %s",
                  definition, gr_raster_gdal_message("GDAL does not know it."));
    gr_raster_end_sentence(err, err_len);
    st = GR_ERR_FORMAT;
  } else {
    out->wkt = gr_raster_strdup(wkt);
    out->geographic = OSRIsGeographic(srs) ? 1 : 0;
    double unit = OSRIsProjected(srs) ? OSRGetLinearUnits(srs, NULL) : 1.0;
    out->metres_per_unit = (unit > 0.0 && isfinite(unit)) ? unit : 1.0;
    if (!out->wkt)
      st = GR_ERR_OUT_OF_MEMORY;
  }
  CPLFree(wkt);
  if (srs)
    OSRDestroySpatialReference(srs);
  CPLPopErrorHandler();
  return st;
}

void gr_raster_crs_free(gr_raster_crs *c) {
  if (!c)
    return;
  free(c->wkt);
  memset(c, 0, sizeof *c);
}
