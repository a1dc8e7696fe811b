"""mpiexec -n 1, -n 2 and -n 4 pvbatch: Snow Melt split over the ranks. Each rank
simulates its strip along y with the core's ring of 1 row (the slopes); stepping is
point-local, the cast shadows come from the whole terrain that every rank is given, and
the ledger is reduced over the ranks in fixed point. Rolling ground with shadows, a
Forcing table of three rows (warm, rain, warm again) and a checkpoint replay. Each
rank's piece (every output array) and its ledger must equal, bit for bit, what one
process computes on the whole grid (computed in that rank by the wrapped classes): the
-n 1, -n 2 and -n 4 runs thus give the same bits."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a, ranks = T.mpi_setup(globals())

NX, NY, DX = 48, 80, 20.0
END, STEP = 172800.0, 21600.0
ROWS = {"time": [0.0, 43200.0, 108000.0], "air_temperature": [4.0, 1.0, 6.0],
        "precipitation": [0.0, 2.0, 0.5]}

SCENARIO = """
def scenario(terrain_cls, melt_cls):
    from vtkmodules.vtkCommonCore import vtkDoubleArray
    from vtkmodules.vtkCommonDataModel import vtkTable
    from vtkmodules.vtkCommonExecutionModel import vtkTrivialProducer
    t = terrain_cls()
    t.SetDimensions(%(nx)d, %(ny)d)
    t.SetSpacing(%(dx)r)
    t.SetSeed(7)
    t.SetHeightScale(300.0)
    table = vtkTable()
    for name, values in %(rows)r.items():
        c = vtkDoubleArray()
        c.SetName(name)
        for v in values:
            c.InsertNextValue(v)
        table.AddColumn(c)
    p = vtkTrivialProducer()
    p.SetOutput(table)
    f = melt_cls()
    f.SetInputConnection(t.GetOutputPort())
    f.SetInputConnection(1, p.GetOutputPort())
    f.SetInitialSnowDepth(1.5)
    f.SetInitialDensity(250.0)
    f.SetStartDayOfYear(130)
    f.SetStartHour(16.0)
    f.SetEndTime(%(end)r)
    f.SetOutputInterval(%(step)r)
    return t, f, p
""" % {"nx": NX, "ny": NY, "dx": DX, "end": END, "step": STEP, "rows": ROWS}

LEDGER = ["time", "steps", "snowfall_in", "snowfall_volume", "rain_volume", "melt_volume",
          "refrozen_volume", "released_volume", "released_interval_volume", "stored_swe_volume",
          "stored_liquid_volume", "balance_error"]
FIELDS = ["snow_depth", "snow_density", "swe", "liquid_water", "melt_rate", "water_release",
          "radiation", "elevation", "rain_rate"]

COMPARE = SCENARIO + T.IMPORT + """
import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from graupel import vtkProceduralTerrainSource, vtkSnowMeltFilter
_, whole, _keep = scenario(vtkProceduralTerrainSource, vtkSnowMeltFilter)
whole.UpdateTimeStep(%(end)r)
ref = whole.GetOutput()
rad = vtk_to_numpy(ref.GetPointData().GetArray("radiation"))
gr_check.piece_compare(self, ref, %(fields)r, %(ledger)r, %(nx)d, %(ny)d,
                       [("ref_melt", ref.GetFieldData().GetArray("melt_volume").GetTuple1(0)),
                        ("ref_shaded", np.count_nonzero(rad == 0.0))])
""" % {"end": END, "fields": FIELDS, "ledger": LEDGER, "nx": NX, "ny": NY}

terrain = ProceduralTerrain(Dimensions=[NX, NY], Spacing=DX, Seed=7, HeightScale=300.0)
forcing = ProgrammableSource(OutputDataSetType="vtkTable")
forcing.Script = """
from vtkmodules.vtkCommonCore import vtkDoubleArray
out = self.GetOutput()
for name, values in %r.items():
    c = vtkDoubleArray()
    c.SetName(name)
    for v in values:
        c.InsertNextValue(v)
    out.AddColumn(c)
""" % (ROWS,)
melt = SnowMelt(Input=terrain, Forcing=forcing, InitialSnowDepth=1.5, InitialDensity=250.0,
                StartDayOfYear=130, StartHour=16.0, EndTime=END, OutputInterval=STEP,
                CheckpointInterval=2)
# A replay: forward to the end, back to an earlier output, then the end again.
melt.UpdatePipeline(END)
melt.UpdatePipeline(STEP * 3)

pid = ProcessIdScalars(Input=melt)
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
T.check(cmp.PointData["ref_melt"].GetRange()[0] > 0.0,
        "the snow melted (%g m3)" % cmp.PointData["ref_melt"].GetRange()[0])
share = cmp.PointData["piece_share"].GetRange()
T.piece_share(share, ranks)
print("melt %g m3; points without direct sun in the last step (16:00) %g; piece_cells share per rank: "
      "%.4f to %.4f" % (cmp.PointData["ref_melt"].GetRange()[0],
                        cmp.PointData["ref_shaded"].GetRange()[0], share[0], share[1]))
T.finish()
