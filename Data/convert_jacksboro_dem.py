"""Converts the Jacksboro Fault DEM shipped in Debian's python-matplotlib-data
into Data/jacksboro_fault_dem.exr (one FLOAT channel, metres, north up), with
its geometry in the header: spacing 74.5 m east-west and 92.1 m north-south
(3 arc-seconds at the DEM's mean latitude, to 0.1 m) and origin (0, 0, 0) at
the south-west point, so that the EXR Height Field Reader (and File > Open in
ParaView) gives the terrain its real size with no property to set.

    PYTHONPATH=build/lib/python3/site-packages pvpython Data/convert_jacksboro_dem.py

Run once; the result is committed. The test py.wrapped_classes checks that the
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
