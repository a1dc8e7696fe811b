"""pvbatch: terrain -> EXR Field Writer -> EXR Height Field Reader keeps every
value (float exactly, half to half precision), names and vectors."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args()

import numpy as np  # noqa: E402
from paraview import servermanager  # noqa: E402
from paraview.simple import *  # noqa: E402,F401,F403
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402

LoadPlugin(a.plugin, ns=globals())

t = ProceduralTerrain(Dimensions=[131, 77], Spacing=5.0, Seed=42, NoiseType="Billow")
calc = Calculator(Input=t, ResultArrayName="velocity", Function="iHat*elevation - jHat*coordsX + 0.25*kHat")
calc.ResultArrayType = "Float"
orig = servermanager.Fetch(calc)
opd = orig.GetPointData()

for pixel, tol in (("Float", 0.0), ("Half", 2.0 ** -11)):
    path = os.path.join(a.scratch, "roundtrip_%s.exr" % pixel)
    SaveData(path, proxy=calc, PixelType=pixel)
    r = OpenDataFile(path)
    r.Spacing = [5.0, 5.0]
    back = servermanager.Fetch(r)
    T.check(back.GetDimensions() == orig.GetDimensions(), "%s: dimensions" % pixel)
    bpd = back.GetPointData()
    names = sorted(bpd.GetArrayName(i) for i in range(bpd.GetNumberOfArrays()))
    T.check(names == ["elevation", "velocity"], "%s: names %s" % (pixel, names))
    for name in ("elevation", "velocity"):
        x = vtk_to_numpy(opd.GetArray(name))
        y = vtk_to_numpy(bpd.GetArray(name))
        T.check(x.shape == y.shape, "%s: %s shape" % (pixel, name))
        err = np.abs(x - y) - tol * np.maximum(np.abs(x), 6.1e-5)
        T.check(x.shape == y.shape and err.max() <= 0.0,
                "%s: %s values (worst excess %g)" % (pixel, name, err.max()))
    Delete(r)

# A writer given a 3-D image reports and writes nothing.
w = Wavelet()
path = os.path.join(a.scratch, "wavelet.exr")
try:
    SaveData(path, proxy=w)
except Exception:
    pass
T.check(not os.path.exists(path), "no EXR written for a 3-D image")

T.finish()
