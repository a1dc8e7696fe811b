/* GIS raster I/O tests (graupel/raster_io.h): the shipped DEM in its own
 * geographic CRS reprojected to UTM; a GeoTIFF round trip of several bands
 * with NaN, bit for bit, in a metre CRS and in one in US feet (coordinates
 * converted both ways); a raster without a CRS; and every refusal as one
 * sentence naming the file, with the output left untouched. Inputs the
 * reader must refuse are made with GDAL directly.
 *
 * Usage: test_raster --scratch DIR --data DIR [SUBTEST...] */
#include "gr_test.h"
#include "graupel/raster_io.h"

#include <cpl_conv.h>
#include <gdal.h>
#include <ogr_srs_api.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *g_dir = ".";
static const char *g_data = ".";

static void path_in(char *buf, size_t len, const char *dir, const char *name) {
  snprintf(buf, len, "%s/%s", dir, name);
}

/* A sentence naming the file: the file (quoted) or a capital first, a
 * period last. */
static int sentence_naming(const char *s, const char *path) {
  size_t n = strlen(s);
  return n > 10 && ((s[0] >= 'A' && s[0] <= 'Z') || s[0] == '\'') && s[n - 1] == '.' &&
         strstr(s, path) != NULL;
}

static char *wkt_of_epsg(int code) {
  OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
  char *wkt = NULL;
  if (OSRImportFromEPSG(srs, code) != OGRERR_NONE || OSRExportToWkt(srs, &wkt) != OGRERR_NONE)
    wkt = NULL;
  OSRDestroySpatialReference(srs);
  return wkt;
}

/* A GeoTIFF made with GDAL: nb bands of w x h floats (value b*100 + k),
 * the given geotransform and CRS (NULL: none). */
static int make_tiff(const char *path, int w, int h, int nb, const double gt[6], const char *wkt) {
  GDALDriverH drv = GDALGetDriverByName("GTiff");
  GDALDatasetH ds = drv ? GDALCreate(drv, path, w, h, nb, GDT_Float32, NULL) : NULL;
  if (!ds)
    return 0;
  int ok = GDALSetGeoTransform(ds, (double *)gt) == CE_None;
  if (ok && wkt)
    ok = GDALSetProjection(ds, wkt) == CE_None;
  float *v = malloc(sizeof(float) * (size_t)w * (size_t)h);
  for (int b = 0; ok && v && b < nb; ++b) {
    for (int k = 0; k < w * h; ++k)
      v[k] = (float)(100 * (b + 1) + k);
    ok = GDALRasterIO(GDALGetRasterBand(ds, b + 1), GF_Write, 0, 0, w, h, v, w, h, GDT_Float32, 0,
                      0) == CE_None;
  }
  free(v);
  GDALClose(ds);
  return ok && v != NULL;
}

static void test_geographic(void) {
  char path[1024], err[512] = "";
  path_in(path, sizeof path, g_data, "jacksboro_fault_dem.tif");
  gr_raster r;
  memset(&r, 0, sizeof r);
  gr_status st = gr_raster_read(path, 0, &r, err, sizeof err);
  CHECK_MSG(st == GR_OK, "the shipped DEM reads: %s", err);
  if (st != GR_OK)
    return;
  CHECK(r.reprojected == 1);
  CHECK_MSG(r.spacing[0] > 80.0 && r.spacing[0] < 85.0 && r.spacing[0] == r.spacing[1],
            "square pixels of about 82.6 m, not degrees: %g x %g", r.spacing[0], r.spacing[1]);
  CHECK_MSG(r.crs_wkt && strstr(r.crs_wkt, "UTM zone 16N"), "UTM zone 16N: %.80s",
            r.crs_wkt ? r.crs_wkt : "(none)");
  CHECK_MSG(r.source_crs && strcmp(r.source_crs, "EPSG:4269") == 0, "the source CRS: %s",
            r.source_crs ? r.source_crs : "(none)");
  const long long n = (long long)r.width * r.height;
  long long nan = 0;
  float lo = INFINITY, hi = -INFINITY;
  for (long long k = 0; k < n; ++k) {
    if (isnan(r.data[k])) {
      ++nan;
    } else {
      lo = r.data[k] < lo ? r.data[k] : lo;
      hi = r.data[k] > hi ? r.data[k] : hi;
    }
  }
  CHECK_MSG(nan == r.no_data && nan > 0 && nan < n / 10,
            "no data only in the warped corners: %lld of %lld", nan, n);
  CHECK_MSG(lo > 220.0f && hi < 1090.0f && hi - lo > 700.0f, "the DEM's heights: %g..%g", lo, hi);
  /* UTM coordinates of the south-west point: about 731 km east, 4037 km north. */
  CHECK_MSG(fabs(r.origin[0] - 731000.0) < 5000.0 && fabs(r.origin[1] - 4036600.0) < 5000.0,
            "the origin in UTM metres: %.1f %.1f", r.origin[0], r.origin[1]);
  gr_raster_free(&r);
  CHECK(r.data == NULL && r.crs_wkt == NULL);
}

/* Written, read back: bands bit for bit (NaN kept), geometry in metres. */
static void roundtrip(const char *name, int epsg, double unit) {
  char path[1024], err[512] = "";
  path_in(path, sizeof path, g_dir, name);
  const int w = 7, h = 5;
  float a[35], b[35];
  for (int k = 0; k < w * h; ++k) {
    a[k] = (float)(0.1 * k + 250.0);
    b[k] = (float)(k % 3) * 1e-3f;
  }
  a[3] = NAN;
  b[34] = NAN;
  const char *names[2] = {"max_depth", "arrival_time"};
  const float *data[2] = {a, b};
  const double spacing[2] = {12.5, 20.0}, origin[2] = {500012.5, 4000100.0};
  char *wkt = wkt_of_epsg(epsg);
  CHECK(wkt != NULL);
  gr_status st = gr_raster_write(path, w, h, 2, names, data, spacing, origin, wkt, err, sizeof err);
  CHECK_MSG(st == GR_OK, "%s written: %s", name, err);
  for (int band = 1; band <= 2 && st == GR_OK; ++band) {
    gr_raster r;
    memset(&r, 0, sizeof r);
    st = gr_raster_read(path, band, &r, err, sizeof err);
    CHECK_MSG(st == GR_OK, "%s band %d reads: %s", name, band, err);
    if (st != GR_OK)
      break;
    CHECK(r.width == w && r.height == h && r.reprojected == 0);
    CHECK_NEAR(r.unit_factor, unit, 1e-12);
    CHECK_MSG(fabs(r.spacing[0] - spacing[0]) < 1e-9 && fabs(r.spacing[1] - spacing[1]) < 1e-9 &&
                  fabs(r.origin[0] - origin[0]) < 1e-6 && fabs(r.origin[1] - origin[1]) < 1e-6,
              "%s: spacing %.12g %.12g origin %.12g %.12g in metres", name, r.spacing[0],
              r.spacing[1], r.origin[0], r.origin[1]);
    const float *want = band == 1 ? a : b;
    int same = 1;
    for (int k = 0; k < w * h; ++k)
      same &= isnan(want[k]) ? isnan(r.data[k]) : r.data[k] == want[k];
    CHECK_MSG(same, "%s band %d: the values bit for bit, NaN kept", name, band);
    CHECK(r.no_data == 1);
    gr_raster_free(&r);
  }
  CPLFree(wkt);
}

static void test_roundtrip_metres(void) {
  roundtrip("roundtrip_utm.tif", 32616, 1.0);
}

static void test_roundtrip_feet(void) {
  roundtrip("roundtrip_feet.tif", 2274, 1200.0 / 3937.0);
}

static void test_no_crs(void) {
  char path[1024], err[512] = "";
  path_in(path, sizeof path, g_dir, "no_crs.tif");
  const double gt[6] = {100.0, 5.0, 0.0, 200.0, 0.0, -5.0};
  CHECK(make_tiff(path, 4, 3, 1, gt, NULL));
  gr_raster r;
  memset(&r, 0, sizeof r);
  CHECK(gr_raster_read(path, 0, &r, err, sizeof err) == GR_OK);
  CHECK_MSG(strstr(r.notes, "no coordinate reference system") && strstr(r.notes, path),
            "a note for the caller: %s", r.notes);
  CHECK(r.crs_wkt == NULL && r.spacing[0] == 5.0 && r.origin[0] == 102.5 && r.origin[1] == 187.5);
  /* Row 0 is the south: the file's last row. */
  CHECK(r.data && r.data[0] == (float)(100 + 8));
  gr_raster_free(&r);
}

/* A refusal: the status, one sentence naming the file, *out untouched. */
static void refused(const char *path, int band, gr_status want, const char *words) {
  char err[512] = "";
  gr_raster r;
  memset(&r, 0x5a, sizeof r);
  gr_status st = gr_raster_read(path, band, &r, err, sizeof err);
  unsigned char *bytes = (unsigned char *)&r;
  int untouched = 1;
  for (size_t k = 0; k < sizeof r; ++k)
    untouched &= bytes[k] == 0x5a;
  CHECK_MSG(st == want && sentence_naming(err, path) && (!words || strstr(err, words)),
            "%s band %d: %s (%s)", path, band, err, gr_status_string(st));
  CHECK_MSG(untouched, "%s: the output untouched", path);
}

static void test_refusals(void) {
  char path[1024];
  char *wkt = wkt_of_epsg(32616);
  path_in(path, sizeof path, g_dir, "missing.tif");
  remove(path);
  refused(path, 0, GR_ERR_IO, "could not be opened");
  path_in(path, sizeof path, g_dir, "empty.tif");
  FILE *f = fopen(path, "wb");
  if (f)
    fclose(f);
  refused(path, 0, GR_ERR_IO, "could not be opened");
  path_in(path, sizeof path, g_dir, "rotated.tif");
  const double rot[6] = {500000.0, 10.0, 2.0, 4000000.0, 2.0, -10.0};
  CHECK(make_tiff(path, 6, 4, 1, rot, wkt));
  refused(path, 0, GR_ERR_FORMAT, "rotated");
  path_in(path, sizeof path, g_dir, "three_bands.tif");
  const double gt[6] = {500000.0, 10.0, 0.0, 4000000.0, 0.0, -10.0};
  CHECK(make_tiff(path, 6, 4, 3, gt, wkt));
  refused(path, 0, GR_ERR_FORMAT, "choose the band");
  refused(path, 4, GR_ERR_FORMAT, "no band 4");
  refused(path, -1, GR_ERR_FORMAT, "no band -1");
  gr_raster r;
  char err[512];
  memset(&r, 0, sizeof r);
  CHECK(gr_raster_read(path, 3, &r, err, sizeof err) == GR_OK && r.data &&
        r.data[0] == (float)(300 + 18));
  gr_raster_free(&r);
  CHECK(gr_raster_can_read(path) == 1);
  path_in(path, sizeof path, g_dir, "empty.tif");
  CHECK(gr_raster_can_read(path) == 0 && gr_raster_can_read(NULL) == 0);
  CHECK(gr_raster_read(NULL, 0, &r, err, sizeof err) == GR_ERR_INVALID_ARGUMENT);
  /* Writes that cannot be made: one sentence, no file. */
  const float v[4] = {1, 2, 3, 4};
  const float *data[1] = {v};
  const char *names[1] = {"x"};
  const double spacing[2] = {1.0, 1.0}, origin[2] = {0.0, 0.0}, bad[2] = {0.0, 1.0};
  path_in(path, sizeof path, g_dir, "no/such/folder.tif");
  CHECK(gr_raster_write(path, 2, 2, 1, names, data, spacing, origin, wkt, err, sizeof err) ==
            GR_ERR_IO &&
        sentence_naming(err, path));
  path_in(path, sizeof path, g_dir, "bad_spacing.tif");
  CHECK(gr_raster_write(path, 2, 2, 1, names, data, bad, origin, wkt, err, sizeof err) ==
        GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_raster_write(path, 2, 2, 1, names, data, spacing, origin, "not a CRS", err,
                        sizeof err) == GR_ERR_INVALID_ARGUMENT &&
        sentence_naming(err, path));
  CHECK(fopen(path, "rb") == NULL);
  CPLFree(wkt);
}

/* What a CRS definition says (ParaView's GDAL reader keeps a PROJ string). */
static void test_crs_describe(void) {
  gr_raster_crs c;
  char err[512] = "";
  CHECK(gr_raster_crs_describe("+proj=longlat +datum=NAD83 +no_defs", &c, err, sizeof err) ==
        GR_OK);
  CHECK_MSG(c.geographic == 1 && c.metres_per_unit == 1.0 && c.wkt && strstr(c.wkt, "1983"),
            "degrees: %d %g", c.geographic, c.metres_per_unit);
  gr_raster_crs_free(&c);
  CHECK(c.wkt == NULL);
  CHECK(gr_raster_crs_describe("EPSG:2274", &c, err, sizeof err) == GR_OK);
  CHECK_NEAR(c.metres_per_unit, 1200.0 / 3937.0, 1e-12);
  CHECK(c.geographic == 0);
  gr_raster_crs_free(&c);
  CHECK(gr_raster_crs_describe("+proj=utm +zone=16 +datum=NAD83 +units=m +no_defs", &c, err,
                               sizeof err) == GR_OK &&
        c.geographic == 0 && c.metres_per_unit == 1.0);
  gr_raster_crs_free(&c);
  memset(err, 0, sizeof err);
  CHECK(gr_raster_crs_describe("no such CRS", &c, err, sizeof err) == GR_ERR_FORMAT);
  CHECK_MSG(strstr(err, "no such CRS") && err[strlen(err) - 1] == '.', "one sentence: %s", err);
  CHECK(c.wkt == NULL);
  CHECK(gr_raster_crs_describe("", &c, err, sizeof err) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_raster_crs_describe(NULL, &c, err, sizeof err) == GR_ERR_INVALID_ARGUMENT);
  gr_raster_crs_free(NULL);
}

static const gr_subtest tests[] = {
    {"geographic", test_geographic, 0},
    {"roundtrip_metres", test_roundtrip_metres, 0},
    {"roundtrip_feet", test_roundtrip_feet, 0},
    {"no_crs", test_no_crs, 0},
    {"refusals", test_refusals, 0},
    {"crs_describe", test_crs_describe, 0},
};

int main(int argc, char **argv) {
  while (argc > 2 && (strcmp(argv[1], "--scratch") == 0 || strcmp(argv[1], "--data") == 0)) {
    if (strcmp(argv[1], "--scratch") == 0)
      g_dir = argv[2];
    else
      g_data = argv[2];
    argv[2] = argv[0];
    argc -= 2;
    argv += 2;
  }
  GDALAllRegister();
  int rc = gr_test_main(argc, argv, tests, (int)(sizeof tests / sizeof tests[0]), NULL, NULL);
  GDALDestroyDriverManager();
  return rc;
}
