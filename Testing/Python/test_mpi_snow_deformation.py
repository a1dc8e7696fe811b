"""mpiexec -n 1, -n 2 and -n 4 pvbatch: Snow Deformation split over the ranks. With
2 ranks each rank simulates its strip along y with the core's ring of 8 rows
(field data piece_cells at most 55% of the grid), exchanging rings through
ParaView's MPI controller; a sphere ploughs along the strips' shared edge, so
both ranks press it and sum its force. Each rank's piece (fields), its
ledger and the sphere's force must equal, bit for bit, what one process
computes on the whole grid (computed in that rank by the wrapped classes):
the -n 1, -n 2 and -n 4 runs thus give the same bits."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a, ranks = T.mpi_setup(globals())

NX, NY, DX = 96, 200, 0.05
END = 0.5
# A step both ways gives the same double (the proxy's default, 0.0166666666666667,
# is not the class's 1/60).
STEP = 1.0 / 64.0
# The scenario, built by the proxies below and, the same, by the wrapped classes.
SCENARIO = """
def scenario(terrain_cls, sphere_cls, snow_cls):
    t = terrain_cls()
    t.SetDimensions(%(nx)d, %(ny)d)
    t.SetSpacing(%(dx)r)
    t.SetSeed(5)
    t.SetHeightScale(0.3)
    s = sphere_cls()
    s.SetCenter(1.0, 0.5 * (%(ny)d - 1) * %(dx)r, 0.6)
    s.SetRadius(0.4)
    s.SetThetaResolution(24)
    s.SetPhiResolution(24)
    f = snow_cls()
    f.SetInputConnection(t.GetOutputPort())
    f.SetObjectsConnection(s.GetOutputPort())
    f.SetObjectVelocity(2.0, 0.0, 0.0)
    f.SetTimeStep(%(dt)r)
    f.SetEndTime(%(end)r)
    f.SetOutputInterval(0.25)
    return t, s, f
""" % {"nx": NX, "ny": NY, "dx": DX, "end": END, "dt": STEP}

LEDGER = ["time", "steps", "initial_volume", "initial_mass", "snow_volume", "snow_mass",
          "compressed_volume", "displaced_volume", "balance_error", "volume_error",
          "relax_iterations"]
FIELDS = ["snow_depth", "snow_surface", "snow_density", "overlap", "contact", "elevation"]

# Each rank compares its piece with the whole grid computed there
# (gr_check.piece_compare); the per-point mismatch counts are then reduced
# over the ranks by ParaView's data information.
COMPARE = SCENARIO + T.IMPORT + """
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkFiltersSources import vtkSphereSource
from graupel import vtkProceduralTerrainSource, vtkSnowDeformationFilter
_, _, whole = scenario(vtkProceduralTerrainSource, vtkSphereSource, vtkSnowDeformationFilter)
whole.UpdateTimeStep(%(end)r)
ref = whole.GetOutput()
gr_check.piece_compare(self, ref, %(fields)r, %(ledger)r, %(nx)d, %(ny)d,
                       [("ref_overlap", vtk_to_numpy(ref.GetPointData().GetArray("overlap")))])
""" % {"end": END, "fields": FIELDS, "ledger": LEDGER, "nx": NX, "ny": NY}

# The sphere's output (on the ranks that carry it): its force against the whole grid's.
FORCE = SCENARIO + """
import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk
from vtkmodules.vtkFiltersSources import vtkSphereSource
from graupel import vtkProceduralTerrainSource, vtkSnowDeformationFilter
pd = self.GetInputDataObject(0, 0)
out = self.GetOutputDataObject(0)
out.ShallowCopy(pd)
if pd.GetNumberOfPoints() > 0:
    _, _, whole = scenario(vtkProceduralTerrainSource, vtkSphereSource, vtkSnowDeformationFilter)
    whole.UpdateTimeStep(%(end)r)
    ref = whole.GetOutputDataObject(1).GetFieldData()
    mine = pd.GetFieldData()
    # (The programmable filter's sum is a parallel one: count by hand.)
    bad = 0
    for k in ("force", "contact_area"):
        bad += int(np.array(mine.GetArray(k).GetTuple(0), np.float64).tobytes() !=
                   np.array(ref.GetArray(k).GetTuple(0), np.float64).tobytes())
    size = abs(ref.GetArray("force").GetTuple(0)[0])
    for name, v in (("force_mismatch", float(bad)), ("force_size", size)):
        arr = numpy_to_vtk(np.full(pd.GetNumberOfPoints(), v, np.float32), deep=1)
        arr.SetName(name)
        out.GetPointData().AddArray(arr)
""" % {"end": END}

terrain = ProceduralTerrain(Dimensions=[NX, NY], Spacing=DX, Seed=5, HeightScale=0.3)
ball = Sphere(Center=[1.0, 0.5 * (NY - 1) * DX, 0.6], Radius=0.4, ThetaResolution=24,
              PhiResolution=24)
snow = SnowDeformation(Input=terrain, Objects=ball, ObjectVelocity=[2.0, 0.0, 0.0], TimeStep=STEP,
                       EndTime=END, OutputInterval=0.25)

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
T.check(cmp.PointData["ref_overlap"].GetRange()[1] > 0.01, "the sphere presses into the snow")
share = cmp.PointData["piece_share"].GetRange()
T.piece_share(share, ranks)

force = ProgrammableFilter(Input=OutputPort(snow, 1))
force.Script = FORCE
force.UpdatePipeline(END)
T.check(force.PointData["force_mismatch"].GetRange() == (0.0, 0.0),
        "the sphere's force and contact area equal the whole grid's, bit for bit")
T.check(force.PointData["force_size"].GetRange()[0] > 0.0, "the sphere meets resistance")
T.check(snow.FieldData["relax_iterations"].GetRange()[0] > 0,
        "the talus moves snow across the strips' edge (so stale rings would show)")
print("piece_cells share of the grid per rank: %.4f to %.4f" % share)
T.finish()
