"""Output arrays carry their ranges, worked out once by Graupel, where
vtkDataArray::GetRange and GetFiniteRange look first (ParaView asks for both
of every array; VTK's own loops froze the GUI for 13 s on a 20000 x 20000
terrain). Each cached range must be what VTK itself computes on a copy of
the values: Rain Runoff on a terrain with a no-data (NaN) corner, for every
float array and every component and the magnitude of the vectors; Procedural
Terrain; and the EXR reader on a file with NaN (cached) and one with an
infinity (left to VTK, which includes it in the range)."""
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args()

from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy  # noqa: E402
from vtkmodules.vtkCommonCore import vtkDataArray  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData  # noqa: E402
from vtkmodules.vtkCommonExecutionModel import vtkTrivialProducer  # noqa: E402

from graupel import (  # noqa: E402
    vtkEXRFieldWriter,
    vtkEXRHeightFieldReader,
    vtkProceduralTerrainSource,
    vtkRainRunoffFilter,
)


def cached(arr):
    info = arr.GetInformation()
    return info.Has(vtkDataArray.PER_COMPONENT()) and info.Has(vtkDataArray.PER_FINITE_COMPONENT())


def vtk_own(arr):
    """VTK's ranges of a fresh copy of the values (nothing cached on it)."""
    copy = numpy_to_vtk(vtk_to_numpy(arr).copy(), deep=1)
    nc = arr.GetNumberOfComponents()
    comps = [-1] if nc > 1 else []
    return {c: (copy.GetRange(c), copy.GetFiniteRange(c)) for c in list(range(nc)) + comps}


def same_ranges(label, arr, rel=0.0):
    mine = {c: (arr.GetRange(c), arr.GetFiniteRange(c)) for c in vtk_own(arr)}
    theirs = vtk_own(arr)
    for c in theirs:
        for kind, m, t in (("range", mine[c][0], theirs[c][0]), ("finite", mine[c][1], theirs[c][1])):
            ok = all(x == y or abs(x - y) <= rel * max(abs(y), 1e-30) for x, y in zip(m, t))
            T.check(ok, "%s %s component %d: cached %r, VTK %r" % (label, kind, c, m, t))


def all_float_arrays(data, label, expect_cached=True):
    pd = data.GetPointData()
    n = 0
    for i in range(pd.GetNumberOfArrays()):
        arr = pd.GetArray(i)
        if arr is None or arr.GetDataType() not in (10, 11):  # VTK_FLOAT, VTK_DOUBLE
            continue
        n += 1
        name = "%s '%s'" % (label, arr.GetName())
        T.check(cached(arr) == expect_cached, "%s: cached %s" % (name, cached(arr)))
        # The magnitude: VTK sums the squares in double in component order
        # as the cache does; allow for a different rounding of the root.
        same_ranges(name, arr, rel=1e-15 if arr.GetNumberOfComponents() > 1 else 0.0)
    return n


# A terrain with a no-data corner: Rain Runoff's outputs hold NaN there.
nx, ny = 48, 40
x, y = np.meshgrid(np.arange(nx), np.arange(ny))
z = (0.05 * x + 0.5 * np.sin(0.3 * y) + 0.02 * (x - 20.0) ** 2 / 10.0).astype(np.float32)
z[:8, :6] = np.nan
img = vtkImageData()
img.SetDimensions(nx, ny, 1)
img.SetSpacing(2.0, 2.0, 1.0)
e = numpy_to_vtk(z.ravel(), deep=1)
e.SetName("elevation")
img.GetPointData().SetScalars(e)
prod = vtkTrivialProducer()
prod.SetOutput(img)
rr = vtkRainRunoffFilter()
rr.SetInputConnection(prod.GetOutputPort())
rr.SetRainRate(200.0)
rr.SetEndTime(120.0)
rr.SetOutputInterval(60.0)
rr.UpdateTimeStep(120.0)
out = rr.GetOutput()
T.check(out.GetNumberOfPoints() == nx * ny, "Rain Runoff ran (%d points)" % out.GetNumberOfPoints())
depth = vtk_to_numpy(out.GetPointData().GetArray("water_depth"))
T.check(np.isnan(depth).sum() > 0 and np.nanmax(depth) > 0.0,
        "the depth has NaN (%d) and water (%g)" % (np.isnan(depth).sum(), np.nanmax(depth)))
n = all_float_arrays(out, "Rain Runoff")
T.check(n >= 8, "Rain Runoff: %d float arrays checked" % n)
vel = out.GetPointData().GetArray("velocity")
T.check(vel is not None and vel.GetNumberOfComponents() == 3 and vel.GetRange(-1)[1] > 0.0,
        "velocity's magnitude range %r" % (vel.GetRange(-1) if vel else None,))

t = vtkProceduralTerrainSource()
t.SetDimensions(64, 48)
t.Update()
T.check(all_float_arrays(t.GetOutput(), "Procedural Terrain") >= 1, "Procedural Terrain's arrays")


def exr_with(value, name):
    im = vtkImageData()
    im.SetDimensions(5, 4, 1)
    v = np.linspace(-3.0, 7.0, 20)
    v[7] = value
    arr = numpy_to_vtk(v, deep=1)
    arr.SetName("elevation")
    im.GetPointData().SetScalars(arr)
    path = os.path.join(a.scratch, "ranges_%s.exr" % name)
    w = vtkEXRFieldWriter()
    w.SetInputData(im)
    w.SetFileName(path)
    w.Write()
    r = vtkEXRHeightFieldReader()
    r.SetFileName(path)
    r.Update()
    return r.GetOutput()


nan_out = exr_with(math.nan, "nan")
T.check(all_float_arrays(nan_out, "EXR with NaN") == 1, "EXR with NaN: one array")
T.check(nan_out.GetPointData().GetArray("elevation").GetRange(0) == (-3.0, 7.0),
        "EXR with NaN: range %r" % (nan_out.GetPointData().GetArray("elevation").GetRange(0),))
inf_out = exr_with(math.inf, "inf")
T.check(all_float_arrays(inf_out, "EXR with an infinity", expect_cached=False) == 1,
        "EXR with an infinity: one array, left to VTK")
T.check(inf_out.GetPointData().GetArray("elevation").GetRange(0)[1] == math.inf,
        "EXR with an infinity: VTK's range has it (%r)"
        % (inf_out.GetPointData().GetArray("elevation").GetRange(0),))
T.finish()
