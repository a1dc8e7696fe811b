"""mpiexec -n 2 pvbatch: each rank computes its own piece of the terrain;
together they make exactly the terrain one process computes."""
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

# Each rank compares its own piece with the whole terrain computed there by
# the wrapped class; the per-point mismatch array is then reduced over ranks
# by ParaView's data information. (Fetch brings only rank 0's piece in pvbatch.)
pid = ProcessIdScalars(Input=t)
cmp = ProgrammableFilter(Input=pid)
cmp.Script = """
import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy, numpy_to_vtk
from graupel import vtkProceduralTerrainSource
img = self.GetInputDataObject(0, 0)
out = self.GetOutputDataObject(0)
out.ShallowCopy(img)
whole = vtkProceduralTerrainSource()
whole.SetDimensions(160, 120)
whole.SetSpacing(3.0)
whole.SetSeed(11)
whole.Update()
ref = vtk_to_numpy(whole.GetOutput().GetPointData().GetArray("elevation")).reshape(120, 160)
e0, e1, f0, f1, _, _ = img.GetExtent()
mine = vtk_to_numpy(img.GetPointData().GetArray("elevation")).reshape(f1 - f0 + 1, e1 - e0 + 1)
bad = (mine != ref[f0:f1 + 1, e0:e1 + 1]).astype(np.float32).reshape(-1)
arr = numpy_to_vtk(bad, deep=1)
arr.SetName("mismatch")
out.GetPointData().AddArray(arr)
"""
cmp.UpdatePipeline()
T.check(cmp.PointData["ProcessId"].GetRange() == (0.0, 1.0), "both ranks computed a piece")
T.check(cmp.GetDataInformation().GetNumberOfPoints() >= 160 * 120, "the pieces cover the grid")
T.check(cmp.PointData["mismatch"].GetRange() == (0.0, 0.0),
        "every rank's piece equals that part of the whole terrain, bit for bit")
T.finish()
