"""Converts the Jacksboro Fault DEM shipped in Debian's python-matplotlib-data
into Data/jacksboro_fault_dem.tif (a GeoTIFF of the source's int16 metres in
its own geographic coordinates: NAD83, EPSG:4269, 3 arc-second pixels whose
edges are the source's bounds) and Data/jacksboro_fault_dem.exr (one FLOAT
channel, metres, north up), with
its geometry in the header: spacing 74.5 m east-west and 92.1 m north-south
(3 arc-seconds at the DEM's mean latitude, to 0.1 m) and origin (0, 0, 0) at
the south-west point, so that the EXR Height Field Reader (and File > Open in
ParaView) gives the terrain its real size with no property to set.

    PYTHONPATH=build/lib/python3/site-packages pvpython Data/convert_jacksboro_dem.py

Run once (the GeoTIFF needs Debian's python3-gdal); the results are committed. The test py.wrapped_classes checks that the
EXR equals the source value for value and that the reader gives this spacing
and origin."""
import os
import sys

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk
from vtkmodules.vtkCommonDataModel import vtkImageData

from graupel import vtkEXRFieldWriter

SRC = "/usr/share/matplotlib/mpl-data/sample_data/jacksboro_fault_dem.npz"
SPACING = (74.5, 92.1)  # m: the figures Data/README.md gives
ORIGIN = (0.0, 0.0, 0.0)  # m: the south-west point
dst = os.path.join(os.path.dirname(os.path.abspath(__file__)), "jacksboro_fault_dem.exr")
dem = np.load(SRC)
z = dem["elevation"].astype(np.float32)  # int16 metres, first row = north
ny, nx = z.shape
lat = 0.5 * (float(dem["ymin"]) + float(dem["ymax"]))
exact = (float(dem["dx"]) * 111320.0 * np.cos(np.radians(lat)), float(dem["dy"]) * 110574.0)
if any(abs(s - e) > 0.05 for s, e in zip(SPACING, exact)):
    sys.exit("the source's spacing %.2f x %.2f m is not %s to 0.1 m" % (exact + (SPACING,)))
img = vtkImageData()
img.SetDimensions(nx, ny, 1)
img.SetSpacing(SPACING[0], SPACING[1], 1.0)
img.SetOrigin(*ORIGIN)
arr = numpy_to_vtk(z[::-1].reshape(-1).copy(), deep=1)  # row 0 = south
arr.SetName("elevation")
img.GetPointData().SetScalars(arr)
w = vtkEXRFieldWriter()
w.SetInputData(img)
w.SetFileName(dst)
if w.Write() != 1 or w.GetErrorCode():
    sys.exit("conversion failed")
print("wrote %s: %d x %d, %.0f..%.0f m; spacing %.1f m (x) %.1f m (y) (%.2f x %.2f at latitude "
      "%.2f), origin %s" % (dst, nx, ny, z.min(), z.max(), SPACING[0], SPACING[1], exact[0],
                            exact[1], lat, ORIGIN))

# The GeoTIFF: the source's values and its own georeference. The npz's
# bounds are pixel edges (403 x 344 pixels of 1/1200 degree fill them
# exactly); its "ymin" is the northern edge.
from osgeo import gdal, osr  # noqa: E402

west, north = float(dem["xmin"]), max(float(dem["ymin"]), float(dem["ymax"]))
if abs((float(dem["xmax"]) - west) / float(dem["dx"]) - nx) > 1e-6 or \
        abs((north - min(float(dem["ymin"]), float(dem["ymax"]))) / float(dem["dy"]) - ny) > 1e-6:
    sys.exit("the source's bounds are not the edges of its pixels")
tif = os.path.join(os.path.dirname(os.path.abspath(__file__)), "jacksboro_fault_dem.tif")
ds = gdal.GetDriverByName("GTiff").Create(tif, nx, ny, 1, gdal.GDT_Int16,
                                          ["COMPRESS=DEFLATE", "PREDICTOR=2"])
ds.SetGeoTransform([west, float(dem["dx"]), 0.0, north, 0.0, -float(dem["dy"])])
srs = osr.SpatialReference()
srs.ImportFromEPSG(4269)
ds.SetSpatialRef(srs)
band = ds.GetRasterBand(1)
band.WriteArray(dem["elevation"])  # first row = north, as in the source
band.SetUnitType("m")
band.SetDescription("elevation")
ds = None
print("wrote %s: %d x %d int16, EPSG:4269, west %.8f north %.8f, %.8f degree pixels"
      % (tif, nx, ny, west, north, float(dem["dx"])))
