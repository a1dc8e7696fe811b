"""mpiexec -n 1, -n 2 and -n 4 pvbatch: Snow Accumulation split over the ranks. With
2 ranks each rank simulates its strip along y with the core's ring of BlurRadius + 2
rows (field data piece_cells at most 55% of the grid), exchanging rings through
ParaView's MPI controller. Tilted, fluttering snow over steep ridges draws the
terrain into the exposure view, so the ranks combine their views every step; a box
stands across the strips' shared edge, so both ranks see it and its snow. Each
rank's piece (fields), its ledger and the box's snow must equal, bit for bit, what
one process computes on the whole grid (computed in that rank by the wrapped
classes): the -n 1, -n 2 and -n 4 runs thus give the same bits."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a, ranks = T.mpi_setup(globals())

NX, NY, DX = 64, 120, 0.1
END = 1800.0
STEP = 300.0
BLUR = 2
# The scenario, built by the proxies below and, the same, by the wrapped classes.
SCENARIO = """
def scenario(terrain_cls, box_cls, snow_cls, with_box=True):
    t = terrain_cls()
    t.SetDimensions(%(nx)d, %(ny)d)
    t.SetSpacing(%(dx)r)
    t.SetSeed(11)
    t.SetFrequency(300.0)
    t.SetHeightScale(2.5)
    b = box_cls()
    b.SetCenter(0.5 * (%(nx)d - 1) * %(dx)r, 0.5 * (%(ny)d - 1) * %(dx)r, 2.2)
    b.SetXLength(1.6)
    b.SetYLength(2.4)
    b.SetZLength(0.6)
    f = snow_cls()
    f.SetInputConnection(t.GetOutputPort())
    if with_box:
        f.SetObjectsConnection(b.GetOutputPort())
    f.SetSnowDirection(0.3, 1.0, -1.0)
    f.SetFlutter(3.0)
    f.SetSnowfallRate(8.0)
    f.SetNoiseScale(0.4)
    f.SetExposureResolution(128)
    f.SetBlurRadius(%(blur)d)
    f.SetDilation(1)
    f.SetMaxDepth(0.3)
    f.SetStabilityFactor(0.01)
    f.SetTimeStep(%(dt)r)
    f.SetEndTime(%(end)r)
    f.SetOutputInterval(900.0)
    return t, b, f
""" % {"nx": NX, "ny": NY, "dx": DX, "end": END, "dt": STEP, "blur": BLUR}

LEDGER = ["time", "steps", "initial_volume", "snowfall_volume", "stored_volume",
          "stored_volume_terrain", "stored_volume_objects", "shed_volume", "dropped_volume",
          "balance_error"]
FIELDS = ["snow_depth", "snow_surface", "snow_density", "exposure", "elevation"]

# Each rank compares its piece with the whole grid computed there
# (gr_check.piece_compare); the per-point mismatch counts are then reduced
# over the ranks by ParaView's data information.
COMPARE = SCENARIO + T.IMPORT + """
import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkFiltersSources import vtkCubeSource
from graupel import vtkProceduralTerrainSource, vtkSnowAccumulationFilter
_, _, whole = scenario(vtkProceduralTerrainSource, vtkCubeSource, vtkSnowAccumulationFilter)
whole.UpdateTimeStep(%(end)r)
ref = whole.GetOutput()
# The bare ridges alone: tilted snow hides some of their points (the
# terrain is drawn into the view, so the ranks' views are combined).
_, _, bare = scenario(vtkProceduralTerrainSource, vtkCubeSource, vtkSnowAccumulationFilter,
                      with_box=False)
bare.UpdateTimeStep(%(dt)r)
hidden = np.count_nonzero(vtk_to_numpy(bare.GetOutput().GetPointData().GetArray("exposure")) == 0.0)
gr_check.piece_compare(self, ref, %(fields)r, %(ledger)r, %(nx)d, %(ny)d,
                       [("ridge_hidden", hidden),
                        ("ref_objects",
                         ref.GetFieldData().GetArray("stored_volume_objects").GetTuple1(0))])
""" % {"end": END, "dt": STEP, "fields": FIELDS, "ledger": LEDGER, "nx": NX, "ny": NY}

# The box's output (on the rank that carries it): its snow per point against the whole grid's.
BOX = SCENARIO + """
import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy, numpy_to_vtk
from vtkmodules.vtkFiltersSources import vtkCubeSource
from graupel import vtkProceduralTerrainSource, vtkSnowAccumulationFilter
pd = self.GetInputDataObject(0, 0)
out = self.GetOutputDataObject(0)
out.ShallowCopy(pd)
if pd.GetNumberOfPoints() > 0:
    _, _, whole = scenario(vtkProceduralTerrainSource, vtkCubeSource, vtkSnowAccumulationFilter)
    whole.UpdateTimeStep(%(end)r)
    ref = vtk_to_numpy(whole.GetOutputDataObject(1).GetPointData().GetArray("snow_depth"))
    mine = vtk_to_numpy(pd.GetPointData().GetArray("snow_depth"))
    bad = float(np.count_nonzero(mine.view(np.uint32) != ref.view(np.uint32))) \\
        if mine.shape == ref.shape else -1.0
    for name, v in (("box_mismatch", bad), ("box_snow", float(ref.max()))):
        arr = numpy_to_vtk(np.full(pd.GetNumberOfPoints(), v, np.float32), deep=1)
        arr.SetName(name)
        out.GetPointData().AddArray(arr)
""" % {"end": END}

terrain = ProceduralTerrain(Dimensions=[NX, NY], Spacing=DX, Seed=11, Frequency=300.0,
                            HeightScale=2.5)
box = Box(Center=[0.5 * (NX - 1) * DX, 0.5 * (NY - 1) * DX, 2.2], XLength=1.6, YLength=2.4,
          ZLength=0.6)
snow = SnowAccumulation(Input=terrain, Objects=box, SnowDirection=[0.3, 1.0, -1.0], Flutter=3.0,
                        SnowfallRate=8.0, NoiseScale=0.4, ExposureResolution=128,
                        BlurRadius=BLUR, Dilation=1, MaxDepth=0.3, StabilityFactor=0.01,
                        TimeStep=STEP, EndTime=END, OutputInterval=900.0)

pid = ProcessIdScalars(Input=snow)
cmp = ProgrammableFilter(Input=pid)
cmp.Script = COMPARE
cmp.UpdatePipeline(END)
T.check(cmp.PointData["ProcessId"].GetRange() == (0.0, ranks - 1.0),
        "every rank computed a piece")
T.check(cmp.GetDataInformation().GetNumberOfPoints() >= NX * NY, "the pieces cover the grid")
T.check(cmp.PointData["mismatch"].GetRange() == (0.0, 0.0),
        "every rank's fields equal that part of the whole grid's, bit for bit")
T.check(cmp.PointData["ledger_mismatch"].GetRange() == (0.0, 0.0),
        "every rank's ledger (%d values) equals the whole grid's, bit for bit" % len(LEDGER))
T.check(cmp.PointData["ridge_hidden"].GetRange()[0] > 0,
        "tilted snow hides points of the bare ridges (%g): the terrain is in the view"
        % cmp.PointData["ridge_hidden"].GetRange()[0])
T.check(cmp.PointData["ref_objects"].GetRange()[0] > 0.0, "snow lies on the box")
share = cmp.PointData["piece_share"].GetRange()
T.piece_share(share, ranks)

boxes = ProgrammableFilter(Input=OutputPort(snow, 1))
boxes.Script = BOX
boxes.UpdatePipeline(END)
T.check(boxes.PointData["box_mismatch"].GetRange() == (0.0, 0.0),
        "the box's snow per point equals the whole grid's, bit for bit")
T.check(boxes.PointData["box_snow"].GetRange()[0] > 0.0, "snow lies on the box's top")
print("piece_cells share of the grid per rank: %.4f to %.4f" % share)
T.finish()
