"""pvpython: Snow Deformation's `force` is the mean resistance over the output
interval (the impulse since the last output over its time), the same for a
step and its half, and `peak_force` is the largest step's. Before, `force`
was the last step's: a box ploughing at 1 m/s moves whole cells of snow only
every few steps, so the last step's force was 0 or twice the mean by the
phase of the step (33 N at dt 1/60 s against 67 N at 1/120 s, before the fix).
Also: the force does not depend on the order times are asked in (the
impulse is part of the checkpoint state)."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

T.args()
import numpy as np  # noqa: E402
from vtkmodules.util.numpy_support import numpy_to_vtk  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkPolyData  # noqa: E402
from vtkmodules.vtkCommonExecutionModel import vtkTrivialProducer  # noqa: E402
from vtkmodules.vtkFiltersCore import vtkTriangleFilter  # noqa: E402
from vtkmodules.vtkFiltersSources import vtkCubeSource  # noqa: E402

from graupel import vtkSnowDeformationFilter  # noqa: E402

NX, NY, DX = 96, 48, 0.025  # 2.4 m by 1.2 m of 0.5 m snow
_keep = []


def producer(data):
    p = vtkTrivialProducer()
    p.SetOutput(data)
    _keep.append(p)
    return p.GetOutputPort()


def ground():
    img = vtkImageData()
    img.SetDimensions(NX, NY, 1)
    img.SetSpacing(DX, DX, 1.0)
    arr = numpy_to_vtk(np.zeros(NX * NY, dtype=np.float32), deep=1)
    arr.SetName("elevation")
    img.GetPointData().AddArray(arr)
    return img


def box():
    """0.2 m along x, 0.3 m across, pressed 0.2 m into the snow."""
    c = vtkCubeSource()
    c.SetBounds(0.3, 0.5, 0.45, 0.75, 0.3, 0.7)
    t = vtkTriangleFilter()
    t.SetInputConnection(c.GetOutputPort())
    t.Update()
    out = vtkPolyData()
    out.DeepCopy(t.GetOutput())
    return out


def plough(dt, rho=350.0):
    f = vtkSnowDeformationFilter()
    f.SetInputConnection(producer(ground()))
    f.SetObjectsConnection(producer(box()))
    f.SetInitialSnowDepth(0.5)
    f.SetInitialDensity(rho)
    f.SetObjectVelocity(1.0, 0.0, 0.0)
    f.SetTimeStep(dt)
    f.SetEndTime(1.0)
    f.SetOutputInterval(0.25)
    return f


def force_at(f, t):
    f.UpdateTimeStep(t)
    out = f.GetOutputDataObject(1)
    fd = out.GetFieldData()
    fx = fd.GetArray("force").GetTuple3(0)[0]
    peak = fd.GetArray("peak_force").GetValue(0)
    return fx, peak


# Within 2 % at rho 150 (0.1 % measured); at rho 350 the heap the box pushes
# (its shape depends on the step: the berm of Snow Deformation's slumping)
# leaves a 7 % difference between dt and dt/2, within 10 %.
for rho, tol in ((150.0, 0.02), (350.0, 0.10)):
    coarse, fine = plough(1.0 / 60.0, rho), plough(1.0 / 120.0, rho)
    for t in (0.5, 0.75, 1.0):
        fc, pc = force_at(coarse, t)
        ff, pf = force_at(fine, t)
        print("rho %g, t %.2f s: force %.2f N (dt 1/60) %.2f N (dt 1/120); peaks %.1f %.1f N"
              % (rho, t, fc, ff, pc, pf))
        T.check(fc < 0.0 and ff < 0.0, "rho %g t %g: the force opposes the motion (%g, %g)"
                % (rho, t, fc, ff))
        T.check(abs(fc - ff) <= tol * abs(ff),
                "rho %g t %g: dt and dt/2 agree within %g %% (%.2f vs %.2f N)"
                % (rho, t, 100 * tol, fc, ff))
        T.check(pc >= abs(fc) and pf >= abs(ff), "rho %g t %g: the peak is at least the mean"
                % (rho, t))

# Order independence: t = 1.0 first, then back to 0.5 (a checkpoint or a
# restart), the same force as going forward.
a = plough(1.0 / 60.0)
forward = [force_at(a, t)[0] for t in (0.5, 1.0)]
b = plough(1.0 / 60.0)
backward = [force_at(b, t)[0] for t in (1.0, 0.5)][::-1]
T.check(forward == backward, "the same forces whatever the order: %s vs %s" % (forward, backward))
T.finish()
