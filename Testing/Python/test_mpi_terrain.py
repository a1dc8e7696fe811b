"""mpiexec -n 2 pvbatch: each rank computes its own piece of the terrain;
together they make exactly the terrain one process computes. Rain Runoff on
that distributed terrain: every rank reads the whole terrain and simulates
its strip of it (test_mpi_rain_runoff.py checks the split in detail); its
piece equals that part of a one-process run."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args()

import numpy as np  # noqa: E402
from paraview import servermanager  # noqa: E402
from paraview.simple import *  # noqa: E402,F401,F403
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402
from graupel import vtkProceduralTerrainSource  # noqa: E402

LoadPlugin(a.plugin, ns=globals())
pm = servermanager.vtkProcessModule.GetProcessModule()
ranks = pm.GetNumberOfLocalPartitions()
T.check(ranks == 2, "running on 2 ranks (%d)" % ranks)

t = ProceduralTerrain(Dimensions=[160, 120], Spacing=3.0, Seed=11)
t.UpdatePipeline()
info = t.GetDataInformation()

# The same terrain computed whole, in this process, by the wrapped class.
whole = vtkProceduralTerrainSource()
whole.SetDimensions(160, 120)
whole.SetSpacing(3.0)
whole.SetSeed(11)
whole.Update()
ref = vtk_to_numpy(whole.GetOutput().GetPointData().GetArray("elevation")).reshape(120, 160)

T.check(t.PointData["elevation"].GetRange() == (float(ref.min()), float(ref.max())),
        "the pieces' range equals the whole terrain's range")
T.check(tuple(info.GetBounds()) == (0.0, 477.0, 0.0, 357.0, 0.0, 0.0), "bounds of the pieces")

# Each rank compares its own piece with the whole field computed there by the
# wrapped classes; the per-point mismatch array is then reduced over ranks by
# ParaView's data information. (Fetch brings only rank 0's piece in pvbatch.)
COMPARE = """
import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy, numpy_to_vtk
from graupel import vtkProceduralTerrainSource, vtkRainRunoffFilter
img = self.GetInputDataObject(0, 0)
out = self.GetOutputDataObject(0)
out.ShallowCopy(img)
whole = vtkProceduralTerrainSource()
whole.SetDimensions(160, 120)
whole.SetSpacing(3.0)
whole.SetSeed(11)
last = whole
if "%(array)s" == "water_depth":
    rain = vtkRainRunoffFilter()
    rain.SetInputConnection(whole.GetOutputPort())
    rain.SetRainRate(50.0)
    rain.SetEndTime(60.0)
    rain.SetOutputInterval(30.0)
    rain.UpdateTimeStep(60.0)
    last = rain
else:
    whole.Update()
ref = vtk_to_numpy(last.GetOutput().GetPointData().GetArray("%(array)s")).reshape(120, 160)
e0, e1, f0, f1, _, _ = img.GetExtent()
mine = vtk_to_numpy(img.GetPointData().GetArray("%(array)s")).reshape(f1 - f0 + 1, e1 - e0 + 1)
bad = (mine != ref[f0:f1 + 1, e0:e1 + 1]).astype(np.float32).reshape(-1)
arr = numpy_to_vtk(bad, deep=1)
arr.SetName("mismatch")
out.GetPointData().AddArray(arr)
"""


def compare(source, array, time=None):
    pid = ProcessIdScalars(Input=source)
    cmp = ProgrammableFilter(Input=pid)
    cmp.Script = COMPARE % {"array": array}
    cmp.UpdatePipeline(time) if time is not None else cmp.UpdatePipeline()
    T.check(cmp.PointData["ProcessId"].GetRange() == (0.0, 1.0),
            "%s: both ranks computed a piece" % array)
    T.check(cmp.GetDataInformation().GetNumberOfPoints() >= 160 * 120,
            "%s: the pieces cover the grid" % array)
    T.check(cmp.PointData["mismatch"].GetRange() == (0.0, 0.0),
            "%s: every rank's piece equals that part of the whole, bit for bit" % array)


compare(t, "elevation")
rain = RainRunoff(Input=t, RainRate=50.0, EndTime=60.0, OutputInterval=30.0)
compare(rain, "water_depth", 60.0)
T.check(rain.PointData["water_depth"].GetRange()[1] > 0.0, "water on the distributed terrain")
T.finish()
