"""Converts the Jacksboro Fault DEM shipped in Debian's python-matplotlib-data
into Data/jacksboro_fault_dem.exr (one FLOAT channel, metres, north up).

    PYTHONPATH=build/lib/python3/site-packages pvpython Data/convert_jacksboro_dem.py

Run once; the result is committed. The test py.wrapped_classes checks that the
EXR equals the source value for value."""
import os
import sys

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk
from vtkmodules.vtkCommonDataModel import vtkImageData

from graupel import vtkEXRFieldWriter

SRC = "/usr/share/matplotlib/mpl-data/sample_data/jacksboro_fault_dem.npz"
dst = os.path.join(os.path.dirname(os.path.abspath(__file__)), "jacksboro_fault_dem.exr")
dem = np.load(SRC)
z = dem["elevation"].astype(np.float32)  # int16 metres, first row = north
ny, nx = z.shape
img = vtkImageData()
img.SetDimensions(nx, ny, 1)
arr = numpy_to_vtk(z[::-1].reshape(-1).copy(), deep=1)  # row 0 = south
arr.SetName("elevation")
img.GetPointData().SetScalars(arr)
w = vtkEXRFieldWriter()
w.SetInputData(img)
w.SetFileName(dst)
if w.Write() != 1 or w.GetErrorCode():
    sys.exit("conversion failed")
lat = 0.5 * (float(dem["ymin"]) + float(dem["ymax"]))
print("wrote %s: %d x %d, %.0f..%.0f m; spacing %.1f m (x) %.1f m (y) at latitude %.2f"
      % (dst, nx, ny, z.min(), z.max(),
         float(dem["dx"]) * 111320.0 * np.cos(np.radians(lat)), float(dem["dy"]) * 110574.0, lat))
