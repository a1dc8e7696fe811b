"""mpiexec -n 1, -n 2 and -n 4 pvbatch: Water Surface split over the ranks. With 2 ranks
each rank simulates its strip along y with the core's ring of 1 + the raindrops' reach
rows (field data piece_cells at most 55% of the grid), exchanging a row of wave height
every step through ParaView's MPI controller. A lake over rolling ground (shores cross
the strips' edges) takes raindrops everywhere, so ripples cross the cuts. Each rank's
piece (every output array) and its ledger must equal, bit for bit, what one process
computes on the whole grid (computed in that rank by the wrapped classes): the -n 1,
-n 2 and -n 4 runs thus give the same bits."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a, ranks = T.mpi_setup(globals())

NX, NY, DX = 64, 120, 1.0
END = 6.0
terrain = ProceduralTerrain(Dimensions=[NX, NY], Spacing=DX, Seed=5, Frequency=40.0,
                            HeightScale=4.0)
terrain.UpdatePipeline()
low, high = terrain.PointData["elevation"].GetRange()
# A lake over the lower 60% of the ground's range: islands and shores everywhere.
LEVEL = low + 0.6 * (high - low)

# The scenario, built by the proxy below and, the same, by the wrapped classes.
SCENARIO = """
def scenario(terrain_cls, water_cls):
    t = terrain_cls()
    t.SetDimensions(%(nx)d, %(ny)d)
    t.SetSpacing(%(dx)r)
    t.SetSeed(5)
    t.SetFrequency(40.0)
    t.SetHeightScale(4.0)
    f = water_cls()
    f.SetInputConnection(t.GetOutputPort())
    f.SetUseLakeLevel(1)
    f.SetLakeLevel(%(level)r)
    f.SetDropRate(0.05)
    f.SetDropAmplitude(0.01)
    f.SetDropRadius(0.5)
    f.SetSeed(3)
    f.SetEndTime(%(end)r)
    f.SetOutputInterval(3.0)
    return t, f
""" % {"nx": NX, "ny": NY, "dx": DX, "end": END, "level": LEVEL}

LEDGER = ["time", "steps", "wet_points", "wave_volume", "initial_volume", "energy", "max_wave"]
FIELDS = ["wave_height", "water_surface", "normal", "wet", "elevation", "water_depth"]

# Each rank compares its piece with the whole grid computed there
# (gr_check.piece_compare); the per-point mismatch counts are then reduced
# over the ranks by ParaView's data information.
COMPARE = SCENARIO + T.IMPORT + """
import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from graupel import vtkProceduralTerrainSource, vtkWaterSurfaceFilter
_, whole = scenario(vtkProceduralTerrainSource, vtkWaterSurfaceFilter)
whole.UpdateTimeStep(%(end)r)
ref = whole.GetOutput()
dry = np.count_nonzero(vtk_to_numpy(ref.GetPointData().GetArray("wet")) == 0.0)
gr_check.piece_compare(self, ref, %(fields)r, %(ledger)r, %(nx)d, %(ny)d,
                       [("ref_max_wave", ref.GetFieldData().GetArray("max_wave").GetTuple1(0)),
                        ("ref_dry", dry)])
""" % {"end": END, "fields": FIELDS, "ledger": LEDGER, "nx": NX, "ny": NY}

water = WaterSurface(Input=terrain, UseLakeLevel=1, LakeLevel=LEVEL, DropRate=0.05,
                     DropAmplitude=0.01, DropRadius=0.5, Seed=3, EndTime=END, OutputInterval=3.0)

pid = ProcessIdScalars(Input=water)
cmp = ProgrammableFilter(Input=pid)
cmp.Script = COMPARE
cmp.UpdatePipeline(END)
T.check(cmp.PointData["ProcessId"].GetRange() == (0.0, ranks - 1.0),
        "every rank computed a piece")
T.check(cmp.GetDataInformation().GetNumberOfPoints() >= NX * NY, "the pieces cover the grid")
T.check(cmp.PointData["mismatch"].GetRange() == (0.0, 0.0),
        "every rank's fields (%d arrays) equal that part of the whole grid's, bit for bit"
        % len(FIELDS))
T.check(cmp.PointData["ledger_mismatch"].GetRange() == (0.0, 0.0),
        "every rank's ledger (%d values) equals the whole grid's, bit for bit" % len(LEDGER))
T.check(cmp.PointData["ref_max_wave"].GetRange()[0] > 0.001,
        "raindrops made ripples (max |h| %g m)" % cmp.PointData["ref_max_wave"].GetRange()[0])
T.check(cmp.PointData["ref_dry"].GetRange()[0] > 100,
        "the lake has shores (%g dry points)" % cmp.PointData["ref_dry"].GetRange()[0])
share = cmp.PointData["piece_share"].GetRange()
T.piece_share(share, ranks)
print("piece_cells share of the grid per rank: %.4f to %.4f" % share)
T.finish()
