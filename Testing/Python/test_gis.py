"""GIS rasters in, georeferenced maps out (vtkGISRasterReader, vtkGeoTIFFWriter,
graupel/raster_io.h), checked against GDAL itself (osgeo, gdalwarp's library):

  * Data/jacksboro_fault_dem.tif, the DEM in its own geographic CRS (NAD83,
    3 arc-second pixels), is reprojected to UTM zone 16N on reading: the
    valid data's east-west and north-south extents are within 0.5 % of the
    box's true size on the ellipsoid (never degrees taken as metres).
  * The DEM warped by GDAL to UTM at 80 m with no-data corners (-9999): the
    reader gives GDAL's geotransform (pixel centres), heights and NaN exactly
    where GDAL's mask says no data; Rain Runoff runs on it with no other
    filter, the no-data points stay NaN, and its depths equal those of the
    same heights through an EXR to the bit; the CRS reaches Rain Runoff's
    output.
  * The same raster as an ESRI ASCII grid (.asc) gives the same heights.
  * The same raster in a CRS in US feet (Tennessee State Plane, EPSG:2274):
    spacing and origin in metres (the feet times 1200/3937).
  * Flood maps written as GeoTIFF and read back with GDAL: the CRS is the
    input's, the geotransform equal, values and NaN equal, bands named.
  * Bad input, one sentence each and an empty output: a corrupt file, a
    rotated geotransform, a multi-band raster without a band chosen, a band
    it lacks; a raster without a CRS is read with one warning.
  * ParaView's own GDAL Raster Reader (cell data 'Elevation', ghost cells
    for no data, the CRS as a PROJ string): Rain Runoff runs on it with no
    other filter, its points the cells' centres, heights, NaN and depths
    equal to the GIS reader's bit for bit, the CRS carried; the Height Array
    chosen as cells gives the same, one it lacks and a geographic file are
    refused in one sentence; Terrain Surface draws the cells as the GIS
    reader's points. A terrain whose only array is 'dem' runs too.
"""
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args()

from osgeo import gdal, osr  # noqa: E402
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402

import graupel  # noqa: E402

vtkRainRunoffFilter_cls = graupel.vtkRainRunoffFilter

gdal.UseExceptions()
scratch = os.path.join(a.scratch, "gis")
os.makedirs(scratch, exist_ok=True)
DEM = os.path.join(a.data, "jacksboro_fault_dem.tif")


def read(path, band=0):
    r = graupel.vtkGISRasterReader()
    errors = T.ErrorCatcher(r)
    warnings = T.ErrorCatcher(r, event="WarningEvent")
    r.SetFileName(path)
    r.SetBand(band)
    r.Update()
    return r, r.GetOutput(), errors.messages, warnings.messages


def heights(img):
    nx, ny, _ = img.GetDimensions()
    return vtk_to_numpy(img.GetPointData().GetArray("elevation")).reshape(ny, nx)


def gdal_grid(path):
    """GDAL's own view: values row 0 south (float, NaN for no data), pixel
    centre of the south-west pixel, pixel size."""
    ds = gdal.Open(path)
    b = ds.GetRasterBand(1)
    v = b.ReadAsArray().astype(np.float64)
    mask = b.GetMaskBand().ReadAsArray() == 0
    v[mask] = np.nan
    gt = ds.GetGeoTransform()
    h = ds.RasterYSize
    return v[::-1], (gt[0] + 0.5 * gt[1], gt[3] + (h - 0.5) * gt[5]), (gt[1], -gt[5]), ds


# ---- the geographic DEM: reprojected, real sizes -----------------------------
r, geo, errs, warns = read(DEM)
T.check(not errs and geo.GetNumberOfPoints() > 0, "the geographic DEM reads (%s)" % errs)
z = heights(geo)
valid = ~np.isnan(z)
sx, sy, _ = geo.GetSpacing()
area = valid.sum() * sx * sy  # m2 of the valid data: the grid is rotated, its area is not
mid = valid[valid.shape[0] // 2]  # the middle row's run of data, east-west
ew = (np.where(mid)[0][-1] - np.where(mid)[0][0] + 1) * sx
src = gdal.Open(DEM)
gt = src.GetGeoTransform()
lat = gt[3] + 0.5 * src.RasterYSize * gt[5]
phi = math.radians(lat)
# Metres per degree on the WGS84/GRS80 ellipsoid at the box's mean latitude.
m_lat = 111132.954 - 559.822 * math.cos(2 * phi) + 1.175 * math.cos(4 * phi)
m_lon = 111412.84 * math.cos(phi) - 93.5 * math.cos(3 * phi) + 0.118 * math.cos(5 * phi)
true_ew = src.RasterXSize * gt[1] * m_lon
true_ns = src.RasterYSize * -gt[5] * m_lat
print("geographic DEM: %d x %d points of %.2f m; data %.1f km2 (true %.1f), middle row %.0f m "
      "(true %.0f)" % (geo.GetDimensions()[0], geo.GetDimensions()[1], sx, area / 1e6,
                       true_ew * true_ns / 1e6, ew, true_ew))
# UTM's scale 2.75 degrees off its meridian is 1.0003; the grid meets the
# box's edges within a pixel (0.3 %); the middle row crosses the box at the
# meridian convergence, 1.6 degrees (1/cos: 1.0004).
T.check(abs(area / (true_ew * true_ns) - 1) < 0.005 and abs(ew / true_ew - 1) < 0.005,
        "the area and the east-west size are within 0.5 %% of the true ones (%.4f, %.4f)"
        % (area / (true_ew * true_ns), ew / true_ew))
T.check(20.0 < sx < 200.0 and sx == sy, "square pixels in metres, not degrees (%g)" % sx)
T.check(abs(np.nanmin(z) - 236.0) < 15.0 and abs(np.nanmax(z) - 1076.0) < 15.0,
        "heights of the DEM (%.1f..%.1f m)" % (np.nanmin(z), np.nanmax(z)))
crs = geo.GetFieldData().GetAbstractArray("graupel_crs")
utm = osr.SpatialReference()
utm.ImportFromWkt(crs.GetValue(0) if crs else "")
T.check(crs is not None and utm.IsProjected() and utm.GetUTMZone() == 16,
        "the grid's CRS is UTM zone 16 (%s)" % (utm.GetUTMZone() if crs else None))
source = geo.GetFieldData().GetAbstractArray("graupel_source_crs")
T.check(source is not None and source.GetValue(0) == "EPSG:4269", "the source CRS is kept")

# ---- UTM at 80 m with no-data corners ---------------------------------------
utm_tif = os.path.join(scratch, "dem_utm.tif")
gdal.Warp(utm_tif, DEM, dstSRS="EPSG:26916", xRes=80.0, yRes=80.0, resampleAlg="bilinear",
          outputType=gdal.GDT_Float32, dstNodata=-9999.0)
want, origin, pixel, _ = gdal_grid(utm_tif)
_, img, errs, warns = read(utm_tif)
got = heights(img)
T.check(not errs and not warns, "the UTM raster reads quietly (%s %s)" % (errs, warns))
T.check(img.GetSpacing()[:2] == pixel and
        np.allclose(img.GetOrigin()[:2], origin, rtol=0, atol=1e-6),
        "GDAL's geotransform: spacing %s origin %s (GDAL %s %s)"
        % (img.GetSpacing()[:2], img.GetOrigin()[:2], pixel, origin))
nodata = np.isnan(want)
T.check(nodata.sum() > 1000 and np.array_equal(np.isnan(got), nodata),
        "NaN exactly where GDAL's mask has no data (%d points)" % nodata.sum())
T.check(np.array_equal(got[~nodata], want[~nodata].astype(np.float32)), "heights equal GDAL's")

rain = graupel.vtkRainRunoffFilter()
rr_reader = graupel.vtkGISRasterReader()
rr_reader.SetFileName(utm_tif)
rain.SetInputConnection(rr_reader.GetOutputPort())
rain.SetRainRate(50.0)
rain.SetEndTime(600.0)
rain.SetOutputInterval(300.0)
caught = T.ErrorCatcher(rain)
rain.UpdateTimeStep(600.0)
out = rain.GetOutput()
depth = vtk_to_numpy(out.GetPointData().GetArray("water_depth")) if out.GetNumberOfPoints() else None
T.check(not caught.messages and depth is not None, "Rain Runoff runs on the raster as read (%s)"
        % caught.messages)
if depth is not None:
    depth = depth.reshape(got.shape)
    T.check(np.isnan(depth[nodata]).all() and not np.isnan(depth[~nodata]).any()
            and depth[~nodata].max() > 0.0,
            "no-data points stay NaN; the others hold water (max %.3f m)" % np.nanmax(depth))
    T.check(out.GetFieldData().GetAbstractArray("graupel_crs") is not None,
            "the CRS reaches Rain Runoff's output")
    # The same heights through an EXR: the same depths, bit for bit.
    exr = os.path.join(scratch, "dem_utm.exr")
    w = graupel.vtkEXRFieldWriter()
    w.SetInputData(img)
    w.SetFileName(exr)
    w.Write()
    er = graupel.vtkEXRHeightFieldReader()
    er.SetFileName(exr)
    rain2 = graupel.vtkRainRunoffFilter()
    rain2.SetInputConnection(er.GetOutputPort())
    rain2.SetRainRate(50.0)
    rain2.SetEndTime(600.0)
    rain2.SetOutputInterval(300.0)
    rain2.UpdateTimeStep(600.0)
    d2 = vtk_to_numpy(rain2.GetOutput().GetPointData().GetArray("water_depth")).reshape(got.shape)
    T.check(np.array_equal(depth, d2, equal_nan=True), "depths equal the EXR route's to the bit")

    # ---- flood maps back to GeoTIFF, read with GDAL ---------------------------
    maps = os.path.join(scratch, "flood_maps.tif")
    gw = graupel.vtkGeoTIFFWriter()
    gw.SetInputData(out)
    gw.SetFileName(maps)
    for name in ("max_depth", "arrival_time", "hazard_class"):
        gw.AddArrayName(name)
    T.check(gw.Write() == 1 and gw.GetErrorCode() == 0, "the GeoTIFF Writer writes")
    ds = gdal.Open(maps)
    back = osr.SpatialReference(wkt=ds.GetProjection())
    inp = osr.SpatialReference(wkt=gdal.Open(utm_tif).GetProjection())
    T.check(back.IsSame(inp) == 1, "the written CRS is the input's")
    T.check(np.allclose(ds.GetGeoTransform(), gdal.Open(utm_tif).GetGeoTransform(), rtol=0,
                        atol=1e-6), "the geotransform equals the input's (%s)"
            % (ds.GetGeoTransform(),))
    names = [ds.GetRasterBand(k + 1).GetDescription() for k in range(ds.RasterCount)]
    T.check(names == ["max_depth", "arrival_time", "hazard_class"], "bands named (%s)" % names)
    md = ds.GetRasterBand(1).ReadAsArray()[::-1]
    mine = vtk_to_numpy(out.GetPointData().GetArray("max_depth")).reshape(got.shape)
    T.check(np.array_equal(md, mine, equal_nan=True) and np.isnan(md[nodata]).all(),
            "max_depth read back equals the output, NaN kept")
    T.check(math.isnan(ds.GetRasterBand(1).GetNoDataValue()), "NaN is the no-data value")
    left = [f for f in os.listdir(scratch) if ".tmp" in f]
    T.check(not left, "no temporary file left (%s)" % left)

    # A full disk (a file-size limit of 16 KiB): one sentence, the earlier
    # file whole, no temporary file; with room again the write succeeds.
    import resource
    import signal

    before = open(maps, "rb").read()
    old_handler = signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    soft, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
    resource.setrlimit(resource.RLIMIT_FSIZE, (16384, hard))
    full = graupel.vtkGeoTIFFWriter()
    full.SetInputData(out)
    full.SetFileName(maps)
    caught = T.ErrorCatcher(full)
    full.Write()
    resource.setrlimit(resource.RLIMIT_FSIZE, (soft, hard))
    signal.signal(signal.SIGXFSZ, old_handler)
    T.check(len(caught.messages) == 1 and ("GeoTIFF Writer: '%s' was not written" % maps)
            in caught.messages[0], "a full disk: one sentence (%s)" % caught.messages)
    T.check(open(maps, "rb").read() == before, "the earlier file is whole")
    left = [f for f in os.listdir(scratch) if ".tmp" in f]
    T.check(not left, "no temporary file left after the failure (%s)" % left)
    full.Write()
    nbands = sum(out.GetPointData().GetArray(k).GetNumberOfComponents()
                 for k in range(out.GetPointData().GetNumberOfArrays()))
    T.check(full.GetErrorCode() == 0 and gdal.Open(maps).RasterCount == nbands,
            "with room again it writes (every point array, %d bands: %d)"
            % (nbands, gdal.Open(maps).RasterCount))
    missing = graupel.vtkGeoTIFFWriter()
    missing.SetInputData(out)
    missing.SetFileName(os.path.join(scratch, "no", "such", "folder.tif"))
    caught = T.ErrorCatcher(missing)
    missing.Write()
    T.check(len(caught.messages) == 1 and "was not written" in caught.messages[0],
            "a missing folder: one sentence (%s)" % caught.messages)

# ---- the same raster as an ASCII grid -----------------------------------------
asc = os.path.join(scratch, "dem_utm.asc")
gdal.Translate(asc, utm_tif, format="AAIGrid", creationOptions=["SIGNIFICANT_DIGITS=9"])
_, img_asc, errs, _ = read(asc)
za = heights(img_asc)
T.check(not errs and za.shape == got.shape and np.array_equal(np.isnan(za), nodata)
        and np.array_equal(za[~nodata], got[~nodata]), "the .asc gives the GeoTIFF's heights")
T.check(np.allclose(img_asc.GetOrigin()[:2], img.GetOrigin()[:2], rtol=0, atol=1e-6),
        "and its origin")

# ---- a CRS in US survey feet ---------------------------------------------------
feet_tif = os.path.join(scratch, "dem_feet.tif")
gdal.Warp(feet_tif, DEM, dstSRS="EPSG:2274", xRes=250.0, yRes=250.0, outputType=gdal.GDT_Float32,
          dstNodata=-9999.0)
_, img_ft, errs, _ = read(feet_tif)
gt_ft = gdal.Open(feet_tif).GetGeoTransform()
ft = 1200.0 / 3937.0
T.check(not errs and abs(img_ft.GetSpacing()[0] - 250.0 * ft) < 1e-9
        and abs(img_ft.GetOrigin()[0] - (gt_ft[0] + 125.0) * ft) < 1e-6,
        "feet become metres: spacing %.6f m (%.6f)" % (img_ft.GetSpacing()[0], 250.0 * ft))

# ---- bad input -----------------------------------------------------------------
def refused(path, what, band=0, expect=None):
    _, o, errs, _ = read(path, band)
    T.check(o.GetNumberOfPoints() == 0 and len(errs) == 1
            and ("GIS Raster Reader: '%s'" % path) in errs[0]
            and (expect is None or expect in errs[0]), "%s: one sentence, empty (%s)" % (what, errs))


corrupt = os.path.join(scratch, "corrupt.tif")
with open(utm_tif, "rb") as f:
    head = f.read(4000)
with open(corrupt, "wb") as f:
    f.write(head)
refused(corrupt, "a truncated GeoTIFF")
rotated = os.path.join(scratch, "rotated.tif")
ds = gdal.GetDriverByName("GTiff").Create(rotated, 20, 10, 1, gdal.GDT_Float32)
ds.SetGeoTransform([500000.0, 10.0, 2.0, 4000000.0, 2.0, -10.0])
ds.SetProjection(inp.ExportToWkt())
ds.GetRasterBand(1).Fill(100.0)
ds = None
refused(rotated, "a rotated geotransform", expect="rotated")
multi = os.path.join(scratch, "multi.tif")
ds = gdal.GetDriverByName("GTiff").Create(multi, 20, 10, 3, gdal.GDT_Float32)
ds.SetGeoTransform([500000.0, 10.0, 0.0, 4000000.0, 0.0, -10.0])
ds.SetProjection(inp.ExportToWkt())
for k in range(3):
    ds.GetRasterBand(k + 1).Fill(100.0 * (k + 1))
ds = None
refused(multi, "three bands, none chosen", expect="choose the band")
refused(multi, "band 4 of three", band=4, expect="no band 4")
_, o, errs, _ = read(multi, 2)
T.check(not errs and np.all(heights(o) == 200.0), "band 2 chosen: its heights")
bare = os.path.join(scratch, "no_crs.tif")
ds = gdal.GetDriverByName("GTiff").Create(bare, 20, 10, 1, gdal.GDT_Float32)
ds.SetGeoTransform([100.0, 5.0, 0.0, 200.0, 0.0, -5.0])
ds.GetRasterBand(1).Fill(7.0)
ds = None
_, o, errs, warns = read(bare)
T.check(not errs and len(warns) == 1 and "no coordinate reference system" in warns[0]
        and o.GetSpacing()[:2] == (5.0, 5.0) and o.GetOrigin()[:2] == (102.5, 152.5),
        "no CRS: one warning, the spacing taken as metres (%s, %s %s)"
        % (warns, o.GetSpacing(), o.GetOrigin()))

# ---- ParaView's own GDAL reader: its cells are the samples -----------------------
try:
    from vtkmodules.vtkIOGDAL import vtkGDALRasterReader
except ImportError:  # the VTK-alone build's VTK 9.1 has no GDAL module
    vtkGDALRasterReader = None


def gdal_rain(path, choose=None):
    """Rain Runoff straight on ParaView's GDAL Raster Reader (cell data
    'Elevation', a vtkGhostType for the no-data cells), nothing between."""
    pv = vtkGDALRasterReader()
    pv.SetFileName(path)
    f = vtkRainRunoffFilter_cls()
    f.SetInputConnection(pv.GetOutputPort())
    if choose:
        f.SetInputArrayToProcess(0, 0, 0, choose[0], choose[1])
    f.SetRainRate(50.0)
    f.SetEndTime(600.0)
    f.SetOutputInterval(300.0)
    caught = T.ErrorCatcher(f)
    f.UpdateTimeStep(600.0)
    return pv, f, f.GetOutput(), caught.messages


if vtkGDALRasterReader is not None and depth is not None:
    keep, cells_rain, o, errs = gdal_rain(utm_tif)
    pv_out = keep.GetOutput()
    T.check(pv_out.GetCellData().GetArray("Elevation") is not None
            and pv_out.GetPointData().GetNumberOfArrays() == 0,
            "ParaView's reader gives cell data only (%s)" % pv_out.GetCellData().GetArrayName(0))
    T.check(not errs and o.GetNumberOfPoints() > 0, "Rain Runoff runs on it untouched (%s)" % errs)
    if o.GetNumberOfPoints():
        T.check(o.GetDimensions()[:2] == img.GetDimensions()[:2]
                and np.allclose(o.GetOrigin()[:2], img.GetOrigin()[:2], rtol=0, atol=1e-6)
                and o.GetSpacing()[:2] == img.GetSpacing()[:2],
                "the cells' centres are the points: %s at %s (Graupel's reader %s at %s)"
                % (o.GetDimensions(), o.GetOrigin(), img.GetDimensions(), img.GetOrigin()))
        ev = vtk_to_numpy(o.GetPointData().GetArray("elevation")).reshape(got.shape)
        T.check(np.array_equal(ev, got, equal_nan=True),
                "heights equal Graupel's reader's, NaN at the %d no-data cells" % nodata.sum())
        dv = vtk_to_numpy(o.GetPointData().GetArray("water_depth")).reshape(got.shape)
        T.check(np.array_equal(dv, depth, equal_nan=True) and np.isnan(dv[nodata]).all(),
                "depths equal the GIS reader's and the EXR route's to the bit; no-data stays NaN")
        crs_pv = o.GetFieldData().GetAbstractArray("graupel_crs")
        T.check(crs_pv is not None and osr.SpatialReference(wkt=crs_pv.GetValue(0)).IsSame(inp),
                "its CRS (MAP_PROJECTION) reaches the output as graupel_crs")
    # The Height Array chosen the ParaView way: the same; one it lacks: one sentence.
    _, _, o2, errs = gdal_rain(utm_tif, (1, "Elevation"))
    T.check(not errs and o2.GetNumberOfPoints() and np.array_equal(
        vtk_to_numpy(o2.GetPointData().GetArray("water_depth")).reshape(got.shape), depth,
        equal_nan=True), "Height Array = cells 'Elevation': the same depths (%s)" % errs)
    # One it lacks (ParaView keeps the Height Array when the Input changes):
    # one warning, and the default heights.
    _, f3, o3, errs = gdal_rain(utm_tif, (1, "Height"))
    T.check(not errs and o3.GetNumberOfPoints() and np.array_equal(
        vtk_to_numpy(o3.GetPointData().GetArray("water_depth")).reshape(got.shape), depth,
        equal_nan=True), "a Height Array it lacks: the default heights (%s)" % errs)
    w3 = T.ErrorCatcher(f3, event="WarningEvent")
    f3.Modified()
    f3.UpdateTimeStep(600.0)
    T.check(len(w3.messages) == 1 and "no array 'Height'" in w3.messages[0]
            and "'Elevation' instead" in w3.messages[0], "and one warning naming both (%s)"
            % w3.messages)
    # Terrain Surface draws the raster's cells at their centres, no-data as holes.
    surf = graupel.vtkTerrainSurfaceFilter()
    surf.SetInputConnection(keep.GetOutputPort())
    surf.SetSkirt(False)
    surf.SetVerticalExaggeration(1.0)
    surf_gis = graupel.vtkTerrainSurfaceFilter()
    surf_gis.SetInputData(img)
    surf_gis.SetSkirt(False)
    surf_gis.SetVerticalExaggeration(1.0)
    caught = T.ErrorCatcher(surf)
    surf.Update()
    surf_gis.Update()
    sa, sb = surf.GetOutput(), surf_gis.GetOutput()
    T.check(not caught.messages and sa.GetNumberOfPolys() > 0
            and sa.GetNumberOfPoints() == sb.GetNumberOfPoints()
            and sa.GetNumberOfPolys() == sb.GetNumberOfPolys()
            and np.array_equal(vtk_to_numpy(sa.GetPoints().GetData()),
                               vtk_to_numpy(sb.GetPoints().GetData())),
            "Terrain Surface on the cells: the GIS reader's surface (%d quads, %s)"
            % (sa.GetNumberOfPolys(), caught.messages))
    # A CRS in US survey feet through ParaView's reader: metres, as the GIS reader's.
    _, _, o5, errs = gdal_rain(feet_tif)
    T.check(not errs and o5.GetNumberOfPoints() == img_ft.GetNumberOfPoints()
            and abs(o5.GetSpacing()[0] - img_ft.GetSpacing()[0]) < 1e-9
            and np.allclose(o5.GetOrigin()[:2], img_ft.GetOrigin()[:2], rtol=0, atol=1e-6),
            "feet through ParaView's reader: spacing %.6f m, origin %s (GIS reader %.6f, %s; %s)"
            % (o5.GetSpacing()[0], o5.GetOrigin()[:2], img_ft.GetSpacing()[0],
               img_ft.GetOrigin()[:2], errs))
    # The geographic file through ParaView's reader: degrees are refused.
    _, _, o4, errs = gdal_rain(DEM)
    T.check(o4.GetNumberOfPoints() == 0 and len(errs) == 1 and "geographic coordinates" in errs[0]
            and "GIS Raster Reader" in errs[0], "degrees as metres refused in one sentence (%s)"
            % errs)

# ---- any point array as the heights --------------------------------------------
lifted = graupel.vtkRainRunoffFilter()
calc_src = graupel.vtkGISRasterReader()
calc_src.SetFileName(utm_tif)
calc_src.Update()
renamed = calc_src.GetOutput().NewInstance()
renamed.DeepCopy(calc_src.GetOutput())
renamed.GetPointData().GetArray("elevation").SetName("dem")
from vtkmodules.vtkCommonExecutionModel import vtkTrivialProducer  # noqa: E402

renamed_src = vtkTrivialProducer()
renamed_src.SetOutput(renamed)
lifted.SetInputConnection(renamed_src.GetOutputPort())
lifted.SetRainRate(50.0)
lifted.SetEndTime(600.0)
lifted.SetOutputInterval(300.0)
caught = T.ErrorCatcher(lifted)
lifted.UpdateTimeStep(600.0)
lo = lifted.GetOutput()
T.check(not caught.messages and lo.GetNumberOfPoints() and depth is not None and np.array_equal(
    vtk_to_numpy(lo.GetPointData().GetArray("water_depth")).reshape(got.shape), depth,
    equal_nan=True), "the only array, named dem, is taken as the heights: the same depths (%s)"
    % caught.messages)
T.finish()
