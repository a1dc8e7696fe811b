"""pvpython: simulations chain end to start (vtkGraupelSimulation::InputTime).
Snow Deformation on Snow Accumulation's output starts from the snow that fell
by the accumulation's EndTime, in a fresh pipeline and whatever time either
was updated to before, not from the bare ground of its time 0; InputTime
picks another input time; the same for Water Surface on Rain Runoff's
water. Before, a fresh pipeline asking Snow Deformation for 0.5 s read the
accumulation at its time 0 (initial_volume 0)."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

T.args()
import graupel  # noqa: E402


def field(data, name):
    arr = data.GetFieldData().GetArray(name) if data else None
    return None if arr is None else arr.GetTuple(0)[0]


def snowfall():
    terrain = graupel.vtkProceduralTerrainSource()
    terrain.SetDimensions(40, 36)
    terrain.SetSpacing(0.1)
    terrain.SetHeightScale(0.5)
    acc = graupel.vtkSnowAccumulationFilter()
    acc.SetInputConnection(terrain.GetOutputPort())
    acc.SetEndTime(7200.0)
    acc.SetOutputInterval(1800.0)
    acc.SetTimeStep(600.0)
    return terrain, acc


def deformation(acc, **kw):
    dfm = graupel.vtkSnowDeformationFilter()
    dfm.SetInputConnection(acc.GetOutputPort(0))
    dfm.SetEndTime(1.0)
    dfm.SetOutputInterval(0.5)
    for k, v in kw.items():
        getattr(dfm, "Set" + k)(v)
    return dfm


# The accumulation's stored snow at each of its output times, for reference.
_, ref = snowfall()
stored = {}
for t in (1800.0, 3600.0, 7200.0):
    ref.UpdateTimeStep(t)
    stored[t] = field(ref.GetOutputDataObject(0), "stored_volume")
T.check(0 < stored[1800.0] < stored[3600.0] < stored[7200.0],
        "the snowfall grows: %s m^3" % stored)

# A fresh pipeline: the deformation asked for 0.5 s starts from the end.
_, acc = snowfall()
dfm = deformation(acc)
dfm.UpdateTimeStep(0.5)
start = field(dfm.GetOutputDataObject(0), "initial_volume")
T.check(start is not None and abs(start - stored[7200.0]) <= 1e-6 * stored[7200.0],
        "fresh pipeline: the deformation starts from the snow at 7200 s (%s vs %g m^3)"
        % (start, stored[7200.0]))

# Whatever was updated before: the accumulation shown at 1800 s first.
_, acc = snowfall()
acc.UpdateTimeStep(1800.0)
dfm = deformation(acc)
dfm.UpdateTimeStep(1.0)
start = field(dfm.GetOutputDataObject(0), "initial_volume")
T.check(start is not None and abs(start - stored[7200.0]) <= 1e-6 * stored[7200.0],
        "after the input was shown at 1800 s: still from 7200 s (%s m^3)" % start)
# No time asked (Update()): the same.
_, acc = snowfall()
dfm = deformation(acc)
dfm.Update()
start = field(dfm.GetOutputDataObject(0), "initial_volume")
T.check(start is not None and abs(start - stored[7200.0]) <= 1e-6 * stored[7200.0],
        "no time asked: from 7200 s (%s m^3)" % start)
# InputTime picks another input time.
_, acc = snowfall()
dfm = deformation(acc, InputTime=3600.0)
dfm.UpdateTimeStep(0.5)
start = field(dfm.GetOutputDataObject(0), "initial_volume")
T.check(start is not None and abs(start - stored[3600.0]) <= 1e-6 * stored[3600.0],
        "InputTime 3600: from the snow at 3600 s (%s vs %g m^3)" % (start, stored[3600.0]))

# Water Surface on Rain Runoff: the water at Rain Runoff's end.
terrain = graupel.vtkProceduralTerrainSource()
terrain.SetDimensions(32, 32)
terrain.SetSpacing(2.0)
terrain.SetHeightScale(4.0)


def storm():
    rain = graupel.vtkRainRunoffFilter()
    rain.SetInputConnection(terrain.GetOutputPort())
    rain.SetRainRate(100.0)
    rain.SetEndTime(600.0)
    rain.SetOutputInterval(300.0)
    return rain


rain = storm()
rain.UpdateTimeStep(600.0)
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402
depth = vtk_to_numpy(rain.GetOutputDataObject(0).GetPointData().GetArray("water_depth"))
rain2 = storm()
ws = graupel.vtkWaterSurfaceFilter()
ws.SetInputConnection(rain2.GetOutputPort(0))
ws.SetEndTime(2.0)
ws.SetOutputInterval(1.0)
ws.UpdateTimeStep(1.0)
wet = field(ws.GetOutputDataObject(0), "wet_points")
expect = int((depth > ws.GetWetDepth()).sum())
T.check(expect > 0 and wet == expect,
        "Water Surface on Rain Runoff: the water at 600 s (%s wet points, %d expected)"
        % (wet, expect))
T.finish()
