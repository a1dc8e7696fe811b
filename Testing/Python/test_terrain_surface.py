"""Terrain Surface: the drawn grid, its heights and normals, and the stride
that keeps a large grid within MaximumPoints.

A tilted plane z = 0.3 x - 0.2 y + 5 on 37 x 23 points (spacing 2 x 3 m)
drawn with exaggeration 2: every point at z0 + 2 h, every normal the
plane's (-0.6, 0.4, 1)/|.|, (nx-1)(ny-1) top quads plus 2(nx+ny-2) wall
quads. With MaximumPoints 100 the smallest stride k whose grid fits is taken
(k = 4: 10 x 7 = 70 points; k = 3 would give 13 x 9 = 117), the last row and
column are kept (the bounds are the full grid's), each drawn point is the
input point k times its index (or the last), the field data says k, and
the normals are still the plane's. MaximumPoints 0 draws every point."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args()

from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData  # noqa: E402
from vtkmodules.vtkCommonExecutionModel import vtkTrivialProducer  # noqa: E402

from graupel import vtkTerrainSurfaceFilter  # noqa: E402

nx, ny, dx, dy = 37, 23, 2.0, 3.0
img = vtkImageData()
img.SetDimensions(nx, ny, 1)
img.SetSpacing(dx, dy, 1.0)
img.SetOrigin(10.0, 20.0, 1.0)
x = 10.0 + dx * np.arange(nx)[None, :]
y = 20.0 + dy * np.arange(ny)[:, None]
h = (0.3 * x - 0.2 * y + 5.0) * np.ones((ny, nx))
e = numpy_to_vtk(h.ravel(), deep=1)
e.SetName("elevation")
img.GetPointData().SetScalars(e)
prod = vtkTrivialProducer()
prod.SetOutput(img)
plane_normal = np.array([-0.6, 0.4, 1.0]) / np.linalg.norm([-0.6, 0.4, 1.0])


def surface(most):
    f = vtkTerrainSurfaceFilter()
    f.SetInputConnection(prod.GetOutputPort())
    f.SetVerticalExaggeration(2.0)
    f.SetMaximumPoints(most)
    f.Update()
    return f.GetOutput()


def check_top(out, label, xs, ys):
    mx, my = len(xs), len(ys)
    top = mx * my
    pts = vtk_to_numpy(out.GetPoints().GetData())
    T.check(out.GetNumberOfPoints() == top + 4 * (mx + my),
            "%s: %d points (%d drawn + walls)" % (label, out.GetNumberOfPoints(), top))
    T.check(out.GetNumberOfPolys() == (mx - 1) * (my - 1) + 2 * (mx + my - 2),
            "%s: %d quads" % (label, out.GetNumberOfPolys()))
    ii, jj = np.meshgrid(xs, ys)
    want = np.stack([10.0 + dx * ii, 20.0 + dy * jj, 1.0 + 2.0 * h[jj, ii]], axis=-1).reshape(-1, 3)
    T.check(np.abs(pts[:top] - want).max() < 1e-9,
            "%s: drawn points at the input's, z0 + 2 h (%g)" % (label, np.abs(pts[:top] - want).max()))
    nrm = vtk_to_numpy(out.GetPointData().GetArray("Normals"))[:top]
    # The normal of the exaggerated plane: (-2*0.3, 2*0.2, 1).
    T.check(np.abs(nrm - plane_normal).max() < 1e-6,
            "%s: normals the plane's (%g)" % (label, np.abs(nrm - plane_normal).max()))
    el = vtk_to_numpy(out.GetPointData().GetArray("elevation"))[:top]
    T.check(np.array_equal(el, h[jj, ii].ravel()), "%s: the input's point arrays at the drawn points" % label)
    b = out.GetBounds()
    T.check(abs(b[0] - 10.0) < 1e-12 and abs(b[1] - (10.0 + dx * (nx - 1))) < 1e-9
            and abs(b[2] - 20.0) < 1e-12 and abs(b[3] - (20.0 + dy * (ny - 1))) < 1e-9,
            "%s: the full extent %s" % (label, b))
    return out.GetFieldData().GetArray("surface_stride").GetValue(0)


full = surface(0)
T.check(check_top(full, "every point", list(range(nx)), list(range(ny))) == 1, "MaximumPoints 0: stride 1")
same = surface(nx * ny)
T.check(same.GetNumberOfPoints() == full.GetNumberOfPoints(), "MaximumPoints = the grid: every point")
k = check_top(surface(100), "at most 100", list(range(0, nx - 1, 4)) + [nx - 1],
              list(range(0, ny - 1, 4)) + [ny - 1])
T.check(k == 4, "at most 100: stride %d (4: 10 x 7; 3 gives 13 x 9 = 117)" % k)

# No-data points: a NaN block of 3 x 2 points inside and a NaN corner point
# on the edge. Every point stays (at its place, z0 + 2 lowest for the
# holes); no quad touches a NaN point; the walls skip the corner's two
# wall quads; the bounds are the data's.
hn = h.copy()
hn[10:12, 5:8] = np.nan
hn[0, 0] = np.nan
holey = numpy_to_vtk(hn.ravel(), deep=1)
holey.SetName("elevation")
img.GetPointData().SetScalars(holey)
img.Modified()
out = surface(0)
top = nx * ny
touching = set()
for j in range(ny - 1):
    for i in range(nx - 1):
        if np.isnan(hn[j:j + 2, i:i + 2]).any():
            touching.add((i, j))
walls = 2 * (nx + ny - 2) - 2  # the corner point is on two edges
T.check(out.GetNumberOfPoints() == top + 4 * (nx + ny), "no-data: every point kept")
T.check(out.GetNumberOfPolys() == (nx - 1) * (ny - 1) - len(touching) + walls,
        "no-data: %d quads (%d top quads touch a NaN point, %d walls)"
        % (out.GetNumberOfPolys(), len(touching), walls))
pts = vtk_to_numpy(out.GetPoints().GetData())
conn = vtk_to_numpy(out.GetPolys().GetConnectivityArray())
holes = np.flatnonzero(np.isnan(hn.ravel()))
T.check(not np.isin(conn, holes).any(), "no quad uses a no-data point")
T.check(np.isfinite(pts).all() and abs(out.GetBounds()[5] - (1.0 + 2.0 * np.nanmax(hn))) < 1e-9,
        "finite points, the data's bounds")
T.finish()
