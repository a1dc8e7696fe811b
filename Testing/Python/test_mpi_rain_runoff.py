"""mpiexec -n 1, -n 2 and -n 4 pvbatch: Rain Runoff split over the ranks, in
both flow models. With 2 ranks each rank simulates its strip along y with the
core's ring (3 rows local inertial, 4 shallow water; field data piece_cells
at most 55% of the grid), exchanging rings through ParaView's MPI controller.
The scenario crosses the strips' edges everywhere: initial water and a point
inflow on the middle rows, a wall on the west edge and a level (a lake at a
set height) on the north one, open edges south and east, and every input
array (water_depth, velocity, rain_rate, permeability, manning_n) varying
over the grid; three gauges, one on each side of the middle. Each rank's
piece (fields and flood maps) and its gauges must equal, bit for bit, what
one process computes on the whole grid (computed in that rank by the wrapped
classes), so the -n 1, -n 2 and -n 4 runs give the same fields; so must every
entry of the ledger and every row of the hydrograph, bit for bit (the core
sums the volumes in fixed point, as integers that no split can change: see
kernels/include/graupel/reduce.h), the same bits on every rank."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a, ranks = T.mpi_setup(globals())

NX, NY, DX = 40, 104, 5.0
END, EVERY = 60.0, 20.0

# What both pipelines share: the input arrays added to the terrain, the
# inflow and the gauges (point sets), and the whole-grid reference built
# from the wrapped classes.
COMMON = """
import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkPolyData

NX, NY, DX = %(nx)d, %(ny)d, %(dx)r


def decorate(img):
    nx, ny, _ = img.GetDimensions()
    j, i = np.mgrid[0:ny, 0:nx]
    blob = (i - nx / 2) ** 2 + (j - ny / 2) ** 2 < 49
    vel = np.zeros((ny, nx, 3), np.float32)
    vel[blob] = (0.2, -0.3, 0.0)
    for name, v in (("water_depth", np.where(blob, 0.4, 0.0)),
                    ("rain_rate", 2e-5 * (1.0 + i / nx)),
                    ("permeability", 1e-6 * (1.0 + (j %% 7))),
                    ("manning_n", np.where(j > ny / 2 + 1, 0.05, 0.03)),
                    ("velocity", vel)):
        v = np.ascontiguousarray(np.asarray(v, np.float32).reshape(nx * ny, -1))
        arr = numpy_to_vtk(v if v.shape[1] > 1 else v.reshape(-1), deep=1)
        arr.SetName(name)
        img.GetPointData().AddArray(arr)


def points(xy, discharge=None):
    pd = vtkPolyData()
    p = vtkPoints()
    for x, y in xy:
        p.InsertNextPoint(x, y, 0.0)
    pd.SetPoints(p)
    if discharge is not None:
        q = numpy_to_vtk(np.array(discharge, np.float64), deep=1)
        q.SetName("discharge")
        pd.GetPointData().AddArray(q)
    return pd


def inflows():
    # On the last row of the southern strip with 2 ranks, near the blob.
    return points([(DX * (NX // 2 + 3), DX * (NY // 2 - 1))], [3.0])


def gauges():
    return points([(DX * (NX // 2), DX * (NY // 2 - 1)), (DX * (NX // 2), DX * (NY // 2)),
                   (DX * 4, DX * (NY - 3))])
""" % {"nx": NX, "ny": NY, "dx": DX}

REFERENCE = COMMON + """

def reference(model, level):
    from graupel import vtkProceduralTerrainSource, vtkRainRunoffFilter
    t = vtkProceduralTerrainSource()
    t.SetDimensions(NX, NY)
    t.SetSpacing(DX)
    t.SetSeed(7)
    t.SetHeightScale(20.0)
    t.Update()
    img = vtkImageData()
    img.DeepCopy(t.GetOutput())
    decorate(img)
    f = vtkRainRunoffFilter()
    f.SetInputDataObject(0, img)
    f.SetInputDataObject(1, img)
    f.SetInputDataObject(2, gauges())
    f.SetInputDataObject(3, inflows())
    f.SetFlowModel(model)
    f.SetRainRate(10.0)
    f.SetBoundaryWest(1)
    f.SetBoundaryNorth(3)
    f.SetLevelNorth(level)
    f.SetEndTime(%(end)r)
    f.SetOutputInterval(%(every)r)
    f.UpdateTimeStep(%(end)r)
    return f, img
""" % {"end": END, "every": EVERY}

LEDGER = ["time", "steps", "initial_volume", "rain_volume", "infiltrated_volume",
          "outflow_volume", "inflow_volume", "stored_volume", "balance_error", "max_depth"]

# Each rank compares its piece and its hydrograph with the whole grid
# computed there; the per-point mismatch counts are then reduced over the
# ranks by ParaView's data information (Fetch brings only rank 0's piece in
# pvbatch).
COMPARE = """
img = self.GetInputDataObject(0, 0)
table = self.GetInputDataObject(0, 1)
out = self.GetOutputDataObject(0)
out.ShallowCopy(img)
f, _ = reference(%(model)d, %(level)r)
ref = f.GetOutput()
e0, e1, f0, f1, _, _ = img.GetExtent()
bad = np.zeros((f1 - f0 + 1) * (e1 - e0 + 1), dtype=np.float32)
names = [ref.GetPointData().GetArrayName(k) for k in range(ref.GetPointData().GetNumberOfArrays())]
missing = 0
for name in names:
    if img.GetPointData().GetArray(name) is None:
        missing += 1
        continue
    r = vtk_to_numpy(ref.GetPointData().GetArray(name)).reshape(NY, NX, -1)
    m = vtk_to_numpy(img.GetPointData().GetArray(name)).reshape(f1 - f0 + 1, e1 - e0 + 1, -1)
    bad += (m.view(np.uint32) != r[f0:f1 + 1, e0:e1 + 1].view(np.uint32)).sum(axis=2).reshape(-1)
# The core sums its ledger's volumes in fixed point (integers, exact in any
# order), so every entry equals the whole grid's to the bit, however the
# ranks cut the grid. Every rank's ledger is the same bits (the reduction is
# broadcast): their digests must agree over the ranks.
import zlib
def number(fd, name):
    x = fd.GetArray(name)
    return x.GetTuple1(0) if x is not None else float("nan")
ledger_bad = 0
ledger_off = 0.0
digest = b""
for name in %(ledger)r:
    x, y = number(img.GetFieldData(), name), number(ref.GetFieldData(), name)
    digest += np.float64(x).tobytes()
    ledger_bad += int(np.float64(x).tobytes() != np.float64(y).tobytes() or np.isnan(y))
    if np.isfinite(x) and np.isfinite(y):
        ledger_off = np.nanmax([ledger_off, abs(x - y)])
rt = f.GetOutputDataObject(1)
# The hydrograph is rank 0's: the other ranks give its columns without rows
# (ParaView appends the ranks' tables when it delivers them).
from vtkmodules.vtkParallelCore import vtkMultiProcessController
rank = vtkMultiProcessController.GetGlobalController().GetLocalProcessId()
table_bad = int(table.GetNumberOfColumns() != rt.GetNumberOfColumns() or
                table.GetNumberOfRows() != (rt.GetNumberOfRows() if rank == 0 else 0))
for k in range(rt.GetNumberOfColumns()):
    c = rt.GetColumn(k)
    mine = table.GetColumnByName(c.GetName())
    if mine is None:
        table_bad += 1
        continue
    if rank != 0:
        continue
    x, y = vtk_to_numpy(mine), vtk_to_numpy(c)
    # Every row of every column, volumes and rates too: the same bits.
    table_bad += int(x.dtype != y.dtype or x.shape != y.shape or x.tobytes() != y.tobytes())
gauge_wet = float(np.nanmax([np.nanmax(vtk_to_numpy(rt.GetColumnByName("gauge%%d_depth" %% g)))
                             for g in range(3)]))
cells = img.GetFieldData().GetArray("piece_cells")
share = cells.GetTuple1(0) / (NX * NY) if cells else -1.0
n = bad.size
for arr_name, value in (("mismatch", bad), ("missing", missing), ("ledger_mismatch", ledger_bad),
                        ("ledger_off", ledger_off), ("digest", float(zlib.crc32(digest))),
                        ("table_mismatch", table_bad), ("piece_share", share),
                        ("fields", len(names)), ("table_columns", rt.GetNumberOfColumns()),
                        ("inflow", ref.GetFieldData().GetArray("inflow_volume").GetTuple1(0)),
                        ("outflow", ref.GetFieldData().GetArray("outflow_volume").GetTuple1(0)),
                        ("gauge_wet", gauge_wet)):
    values = value if isinstance(value, np.ndarray) else np.full(n, value, np.float32)
    arr = numpy_to_vtk(np.ascontiguousarray(values), deep=1)
    arr.SetName(arr_name)
    out.GetPointData().AddArray(arr)
"""

INFLOWS = COMMON + """
self.GetOutputDataObject(0).ShallowCopy(inflows())
"""
GAUGES = COMMON + """
self.GetOutputDataObject(0).ShallowCopy(gauges())
"""
DECORATE = COMMON + """
out = self.GetOutputDataObject(0)
out.DeepCopy(self.GetInputDataObject(0, 0))
decorate(out)
"""

# The lake on the north edge: a metre above the lowest bed along that edge.
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402
from graupel import vtkProceduralTerrainSource  # noqa: E402

probe = vtkProceduralTerrainSource()
probe.SetDimensions(NX, NY)
probe.SetSpacing(DX)
probe.SetSeed(7)
probe.SetHeightScale(20.0)
probe.Update()
bed = vtk_to_numpy(probe.GetOutput().GetPointData().GetArray("elevation")).reshape(NY, NX)
LEVEL = float(bed[-1].min()) + 1.0

terrain = ProceduralTerrain(Dimensions=[NX, NY], Spacing=DX, Seed=7, HeightScale=20.0)
deco = ProgrammableFilter(Input=terrain, Script=DECORATE)
flows = ProgrammableSource(OutputDataSetType="vtkPolyData", Script=INFLOWS)
gauge_points = ProgrammableSource(OutputDataSetType="vtkPolyData", Script=GAUGES)

for model, label in ((0, "shallow water"), (1, "local inertial")):
    rain = RainRunoff(Input=deco, PermeabilityMap=deco, Gauges=gauge_points, Inflows=flows,
                      FlowModel=model, RainRate=10.0, BoundaryWest="Closed", BoundaryNorth="Level",
                      LevelNorth=LEVEL, EndTime=END, OutputInterval=EVERY)
    pid = ProcessIdScalars(Input=rain)
    cmp = ProgrammableFilter(Input=[pid, OutputPort(rain, 1)])
    cmp.Script = REFERENCE + COMPARE % {"model": model, "level": LEVEL, "ledger": LEDGER,
                                        "every": EVERY}
    cmp.UpdatePipeline(END)

    def rng(name):
        return cmp.PointData[name].GetRange()

    T.check(rng("ProcessId") == (0.0, ranks - 1.0), "%s: every rank computed a piece" % label)
    T.check(cmp.GetDataInformation().GetNumberOfPoints() >= NX * NY,
            "%s: the pieces cover the grid" % label)
    T.check(rng("fields")[0] >= 12 and rng("missing") == (0.0, 0.0),
            "%s: every rank has the %d fields and flood maps" % (label, rng("fields")[0]))
    T.check(rng("mismatch") == (0.0, 0.0),
            "%s: every rank's fields and flood maps equal that part of the whole grid's, bit for "
            "bit" % label)
    T.check(rng("ledger_mismatch") == (0.0, 0.0),
            "%s: every rank's ledger (%d values) equals the whole grid's, bit for bit (largest "
            "difference %g m^3)" % (label, len(LEDGER), rng("ledger_off")[1]))
    T.check(rng("table_columns")[0] == 17 and rng("table_mismatch") == (0.0, 0.0),
            "%s: rank 0's hydrograph (%d columns, 3 gauges) equals the whole grid's, every "
            "row bit for bit; the other ranks' have its columns and no rows"
            % (label, rng("table_columns")[0]))
    T.check(rng("digest")[0] == rng("digest")[1],
            "%s: every rank's ledger is the same bits" % label)
    T.check(rng("inflow")[0] > 0.0 and rng("outflow")[0] > 0.0,
            "%s: water comes in (%g m^3) and goes out (%g m^3)"
            % (label, rng("inflow")[0], rng("outflow")[0]))
    T.check(rng("gauge_wet")[0] > 0.0, "%s: a gauge sees water" % label)
    share = rng("piece_share")
    T.piece_share(share, ranks, label)
    print("%s: piece_cells share of the grid per rank: %.4f to %.4f" % ((label,) + share))
    Delete(cmp)
    Delete(pid)
    Delete(rain)
T.finish()
