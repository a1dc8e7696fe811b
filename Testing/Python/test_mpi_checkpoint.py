"""mpiexec -n 1 and -n 2 pvbatch: checkpoint files and restarts. For Rain
Runoff (shallow water, a point inflow, a wall and a level edge), Snow
Deformation (a sphere ploughing along the strips' edge), Water Surface (a lake
with raindrops) and Snow Accumulation
(tilted snow over ridges, a box across the strips' edge): a run to output k
with CheckpointFile writes a manifest and one .vti per rank; a fresh pipeline
with RestartFile set to it, asked for output 2k, starts from output k (its
RestartIndex) and gives, on every rank, the fields, the ledger (and Rain
Runoff's hydrograph) of an uninterrupted run to 2k bit for bit. A manifest
that says another number of ranks, one of another simulation, or one whose
piece is gone, manifests tampered with (a NaN time, a piece's file outside
the folder, text cut short, another version, rows beyond the grid), a
piece whose state holds a NaN, and a CheckpointFile that cannot be written,
are refused with one sentence and an empty output."""
import builtins
import json
import os
import sys

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLImageDataReader, vtkXMLImageDataWriter

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a, ranks = T.mpi_setup(globals())
folder = os.path.join(a.scratch, "checkpoint_%d" % ranks)
os.makedirs(folder, exist_ok=True)

# Each rank compares its restarted piece (input 0) with the uninterrupted
# run's (input 1): every point array and every field-data value, bit for
# bit; the mismatch counts are reduced over the ranks by ParaView's data
# information.
COMPARE = """
import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy, numpy_to_vtk
mine = self.GetInputDataObject(0, 0)
ref = self.GetInputDataObject(0, 1)
out = self.GetOutputDataObject(0)
out.ShallowCopy(mine)
bad = 0
arrays = 0
for source, other in ((mine.GetPointData(), ref.GetPointData()),
                      (mine.GetFieldData(), ref.GetFieldData())):
    for k in range(other.GetNumberOfArrays()):
        y = other.GetArray(k)
        if y is None or y.GetName() in ("ProcessId", "graupel_device"):
            continue
        x = source.GetArray(y.GetName())
        arrays += 1
        bad += int(x is None or vtk_to_numpy(x).tobytes() != vtk_to_numpy(y).tobytes())
n = mine.GetNumberOfPoints()
for name, v in (("mismatch", bad), ("arrays", arrays)):
    arr = numpy_to_vtk(np.full(n, v, np.float32), deep=1)
    arr.SetName(name)
    out.GetPointData().AddArray(arr)
"""

# Rain Runoff's hydrograph tables (restarted, uninterrupted): rank 0's rows;
# the other ranks' tables have the columns and no rows, in both runs.
COMPARE_TABLES = """
import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy, numpy_to_vtk
img = self.GetInputDataObject(0, 0)
mine = self.GetInputDataObject(0, 1)
ref = self.GetInputDataObject(0, 2)
out = self.GetOutputDataObject(0)
out.ShallowCopy(img)
bad = int(mine.GetNumberOfColumns() != ref.GetNumberOfColumns() or
          mine.GetNumberOfRows() != ref.GetNumberOfRows())
for k in range(ref.GetNumberOfColumns()):
    x = mine.GetColumnByName(ref.GetColumn(k).GetName())
    bad += int(x is None or vtk_to_numpy(x).tobytes() != vtk_to_numpy(ref.GetColumn(k)).tobytes())
arr = numpy_to_vtk(np.full(img.GetNumberOfPoints(), bad, np.float32), deep=1)
arr.SetName("table_mismatch")
out.GetPointData().AddArray(arr)
arr = numpy_to_vtk(np.full(img.GetNumberOfPoints(), ref.GetNumberOfRows(), np.float32), deep=1)
arr.SetName("table_rows")
out.GetPointData().AddArray(arr)
"""

INFLOW = """
from vtkmodules.vtkCommonCore import vtkPoints, vtkDoubleArray
pd = self.GetOutputDataObject(0)
p = vtkPoints()
p.InsertNextPoint(5.0 * 21, 5.0 * 51, 0.0)
pd.SetPoints(p)
q = vtkDoubleArray()
q.SetName("discharge")
q.InsertNextValue(3.0)
pd.GetPointData().AddArray(q)
"""


def rain_runoff(**extra):
    terrain = ProceduralTerrain(Dimensions=[40, 104], Spacing=5.0, Seed=7, HeightScale=20.0)
    flows = ProgrammableSource(OutputDataSetType="vtkPolyData", Script=INFLOW)
    gauges = ProgrammableSource(OutputDataSetType="vtkPolyData", Script=INFLOW)
    return RainRunoff(Input=terrain, Inflows=flows, Gauges=gauges, RainRate=40.0,
                      BoundaryWest="Closed", BoundaryNorth="Level", LevelNorth=8.0,
                      EndTime=80.0, OutputInterval=10.0, **extra)


def snow_deformation(**extra):
    nx, ny, dx = 48, 104, 0.05
    terrain = ProceduralTerrain(Dimensions=[nx, ny], Spacing=dx, Seed=5, HeightScale=0.3)
    ball = Sphere(Center=[0.6, 0.5 * (ny - 1) * dx, 0.6], Radius=0.4, ThetaResolution=24,
                  PhiResolution=24)
    return SnowDeformation(Input=terrain, Objects=ball, ObjectVelocity=[2.0, 0.0, 0.0],
                           TimeStep=1.0 / 64.0, EndTime=0.5, OutputInterval=0.125, **extra)


def snow_accumulation(**extra):
    nx, ny, dx = 48, 104, 0.1
    terrain = ProceduralTerrain(Dimensions=[nx, ny], Spacing=dx, Seed=11, Frequency=300.0,
                                HeightScale=2.5)
    box = Box(Center=[0.5 * (nx - 1) * dx, 0.5 * (ny - 1) * dx, 2.2], XLength=1.6, YLength=2.4,
              ZLength=0.6)
    return SnowAccumulation(Input=terrain, Objects=box, SnowDirection=[0.3, 1.0, -1.0],
                            Flutter=3.0, SnowfallRate=8.0, ExposureResolution=96, BlurRadius=2,
                            Dilation=1, MaxDepth=0.3, StabilityFactor=0.01, TimeStep=300.0,
                            EndTime=1800.0, OutputInterval=900.0, **extra)


def water_surface(**extra):
    terrain = ProceduralTerrain(Dimensions=[48, 104], Spacing=1.0, Seed=9, HeightScale=4.0)
    return WaterSurface(Input=terrain, UseLakeLevel=1, LakeLevel=2.0, DropRate=0.05,
                        DropAmplitude=0.01, DropRadius=0.5, Seed=3, EndTime=12.0,
                        OutputInterval=3.0, **extra)


def points(source, time):
    source.UpdatePipeline(time)
    return source.GetDataInformation().GetNumberOfPoints()


def check_restart(name, make, k_time, end_time, table):
    manifest = os.path.join(folder, name + ".json")
    first = make(CheckpointFile=manifest)
    first.UpdatePipeline(k_time)
    T.check(os.path.exists(manifest), "%s: the manifest is written" % name)
    with open(manifest) as f:
        m = json.load(f)
    T.check(m["ranks"] == ranks and len(m["pieces"]) == ranks and m["split"] == (ranks > 1),
            "%s: the manifest lists %d piece(s): %r" % (name, ranks, m["pieces"]))
    T.check(builtins.all(os.path.exists(os.path.join(folder, p["file"])) and p["bytes"] > 0
                for p in m["pieces"]), "%s: every piece's file is there" % name)
    T.check(m["time"] == k_time and m["simulation"] == first.GetXMLLabel(),
            "%s: the manifest says t = %r s" % (name, m["time"]))
    rows = sorted((p["rows"][0], p["rows"][1]) for p in m["pieces"])
    T.check(rows[0][0] == 0 and builtins.all(rows[q + 1][0] == rows[q][1] + 1 for q in range(len(rows) - 1)),
            "%s: the pieces' own rows tile the grid: %r" % (name, rows))

    restarted = make(RestartFile=manifest)
    whole = make()
    restarted.UpdatePipeline(end_time)
    k = int(round(k_time / restarted.OutputInterval))
    T.check(restarted.GetClientSideObject().GetRestartIndex() == k,
            "%s: the restart starts at output %d (%d)"
            % (name, k, restarted.GetClientSideObject().GetRestartIndex()))
    pid = ProcessIdScalars(Input=restarted)
    cmp = ProgrammableFilter(Input=[pid, whole], Script=COMPARE)
    cmp.UpdatePipeline(end_time)
    T.check(cmp.PointData["ProcessId"].GetRange() == (0.0, ranks - 1.0),
            "%s: every rank restarted its piece" % name)
    T.check(cmp.GetDataInformation().GetNumberOfPoints() >= m["grid"][0] * m["grid"][1],
            "%s: the pieces cover the grid" % name)
    T.check(cmp.PointData["arrays"].GetRange()[0] >= 10 and
            cmp.PointData["mismatch"].GetRange() == (0.0, 0.0),
            "%s: restarted at t = %g s and run to %g s, every rank's %d arrays and ledger values "
            "equal the uninterrupted run's bit for bit"
            % (name, k_time, end_time, cmp.PointData["arrays"].GetRange()[0]))
    if table:
        tc = ProgrammableFilter(Input=[pid, OutputPort(restarted, 1), OutputPort(whole, 1)],
                                Script=COMPARE_TABLES)
        tc.UpdatePipeline(end_time)
        T.check(tc.PointData["table_mismatch"].GetRange() == (0.0, 0.0) and
                tc.PointData["table_rows"].GetRange()[1] == k * 2 + 1,
                "%s: the hydrograph (%d rows, rows before the restart included) equals the "
                "uninterrupted run's bit for bit" % (name, tc.PointData["table_rows"].GetRange()[1]))
    return manifest, m


def refused(name, make, manifest, time, words):
    f = make(RestartFile=manifest)
    errs = T.ErrorCatcher(f.GetClientSideObject())
    n = points(f, time)
    T.check(n == 0 and builtins.all(w in errs.text() for w in words) and len(errs.messages) == 1,
            "%s: refused with one sentence and an empty output (%d points): %r"
            % (name, n, errs.text()[:300]))


rr_manifest, rr = check_restart("rain_runoff", rain_runoff, 40.0, 80.0, True)
sd_manifest, sd = check_restart("snow_deformation", snow_deformation, 0.25, 0.5, False)
check_restart("snow_accumulation", snow_accumulation, 900.0, 1800.0, False)
check_restart("water_surface", water_surface, 6.0, 12.0, False)

# A manifest of another number of ranks: this run's ranks split (or not) otherwise.
other = dict(rr)
other["ranks"] = 1 if ranks > 1 else 2
other["split"] = other["ranks"] > 1
other["pieces"] = [dict(rr["pieces"][0], rank=r) for r in range(other["ranks"])]
wrong_ranks = os.path.join(folder, "wrong_ranks.json")
with open(wrong_ranks, "w") as f:
    json.dump(other, f)
refused("another number of ranks", rain_runoff, wrong_ranks, 80.0,
        ["RestartFile", "was written", "restart it on"])
refused("another simulation", rain_runoff, sd_manifest, 80.0,
        ["RestartFile", "Snow Deformation", "not Rain Runoff"])
gone = dict(rr)
gone["pieces"] = [dict(p, file="missing_%d.vti" % p["rank"]) for p in rr["pieces"]]
missing = os.path.join(folder, "missing.json")
with open(missing, "w") as f:
    json.dump(gone, f)
refused("a missing piece", rain_runoff, missing, 80.0, ["RestartFile", "could not be opened"])
# A manifest naming a piece whose state is not the size it gives (another
# checkpoint's piece, or a tampered manifest).
tampered = dict(rr)
tampered["pieces"] = [dict(p, bytes=p["bytes"] + 8) for p in rr["pieces"]]
sizes = os.path.join(folder, "sizes.json")
with open(sizes, "w") as f:
    json.dump(tampered, f)
refused("a piece of another size", rain_runoff, sizes, 80.0,
        ["RestartFile", "bytes where the manifest says", "another checkpoint"])
refused("no manifest", rain_runoff, os.path.join(folder, "nothing.json"), 80.0,
        ["RestartFile", "could not be opened"])


# Manifests tampered with, refused by the core's reader (graupel/checkpoint.h)
# with its one sentence under the filter's subject.
def write_manifest(name, text):
    path = os.path.join(folder, name + ".json")
    with open(path, "w") as f:
        f.write(text)
    return path


for name, text, words in (
        ("nan_time", json.dumps(dict(rr, time=float("nan"))), ["gives 'time' as nan"]),
        ("traversal", json.dumps(dict(rr, pieces=[dict(p, file="../" + p["file"])
                                                  for p in rr["pieces"]])),
         ["no file beside the manifest"]),
        ("cut_short", json.dumps(rr)[:150], ["is not a Graupel checkpoint manifest", "cut short"]),
        ("version_2", json.dumps(dict(rr, version=2)), ["is of version 2"]),
        ("rows_beyond", json.dumps(dict(rr, pieces=[dict(p, rows=[p["rows"][0], 104])
                                                    for p in rr["pieces"]])),
         ["the rows", "its grid has the rows 0 to 103"])):
    refused("a manifest tampered with (%s)" % name, rain_runoff, write_manifest(name, text), 80.0,
            ["Rain Runoff's RestartFile", name + ".json"] + words)

# A piece whose state holds a NaN (a float in the core's arrays): the core's
# reader refuses it before loading anything.
poisoned = dict(rr, pieces=[dict(p, file="poisoned_" + p["file"]) for p in rr["pieces"]])
for p, q in zip(rr["pieces"], poisoned["pieces"]):
    reader = vtkXMLImageDataReader()
    reader.SetFileName(os.path.join(folder, p["file"]))
    reader.Update()
    image = reader.GetOutput()
    state = vtk_to_numpy(image.GetFieldData().GetAbstractArray("graupel_state"))
    state[4096:4100] = np.frombuffer(np.float32(np.nan).tobytes(), np.uint8)
    writer = vtkXMLImageDataWriter()
    writer.SetInputData(image)
    writer.SetFileName(os.path.join(folder, q["file"]))
    writer.Write()
refused("a piece whose state holds a NaN", rain_runoff,
        write_manifest("poisoned", json.dumps(poisoned)), 80.0,
        ["RestartFile", "holds a state that this simulation does not take", "damaged"])
# A CheckpointFile in a folder that is not there: one sentence, an empty output.
nowhere = rain_runoff(CheckpointFile=os.path.join(folder, "no_such_folder", "x.json"))
errs = T.ErrorCatcher(nowhere.GetClientSideObject())
n = points(nowhere, 20.0)
T.check(n == 0 and "could not write its CheckpointFile" in errs.text() and
        len(errs.messages) == 1,
        "an unwritable CheckpointFile: one sentence and an empty output (%d points): %r"
        % (n, errs.text()[:300]))
T.finish()
