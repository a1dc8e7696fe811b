"""Faults in one process, through the VTK layer:

  * A full disk while checkpoints are written (a file-size limit of 64 KiB,
    SIGXFSZ ignored, as `ulimit -f` would): the update that cannot write its
    checkpoint fails with one sentence naming the file; the previous
    checkpoint (manifest and piece) is intact and restarts; the simulation's
    state in memory is unharmed (the next output equals an uninterrupted
    run's); with room again the next checkpoint is written and restarts.
  * Simulations in one process on one device, updated in interleaved
    order, give the same bits as each alone: every simulation of the module
    (Rain Runoff with FlowModel 0 and 1 on two terrains, Snow Deformation,
    Snow Accumulation, Snow Melt, Water Surface), each output port's every
    array and the ledger compared (gr_check.digest_all), with times that go
    back as well as forward.
"""
import os
import resource
import signal
import sys


sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args()

from vtkmodules.vtkFiltersSources import vtkCubeSource, vtkSphereSource  # noqa: E402

from graupel import (  # noqa: E402
    vtkProceduralTerrainSource,
    vtkRainRunoffFilter,
    vtkSnowAccumulationFilter,
    vtkSnowDeformationFilter,
    vtkSnowMeltFilter,
    vtkWaterSurfaceFilter,
)

folder = os.path.join(a.scratch, "faults")
os.makedirs(folder, exist_ok=True)
for f in os.listdir(folder):
    os.remove(os.path.join(folder, f))


def terrain(seed, n=96):
    t = vtkProceduralTerrainSource()
    t.SetDimensions(n, n)
    t.SetSpacing(2.0)
    t.SetSeed(seed)
    return t


def rain_runoff(t, **props):
    r = vtkRainRunoffFilter()
    r.SetInputConnection(t.GetOutputPort())
    r.SetRainRate(100.0)
    r.SetEndTime(200.0)
    r.SetOutputInterval(20.0)
    for k, v in props.items():
        getattr(r, "Set" + k)(v)
    return r


def digest(alg, time, names=("water_depth", "discharge")):
    return T.digest(alg, time, names)


# ---- a full disk while checkpointing ---------------------------------------
ref = rain_runoff(terrain(3))
reference = {t: digest(ref, t) for t in (20.0, 40.0, 60.0, 80.0)}
manifest = os.path.join(folder, "run.json")
sim = rain_runoff(terrain(3), CheckpointFile=manifest)
T.check(digest(sim, 20.0) == reference[20.0], "checkpointed run at 20 s")
before = {f: open(os.path.join(folder, f), "rb").read() for f in os.listdir(folder)}
T.check("run.json" in before and len(before) == 2, "a manifest and its piece (%s)" % sorted(before))
old_handler = signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
soft, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
resource.setrlimit(resource.RLIMIT_FSIZE, (65536, hard))
caught = T.ErrorCatcher(sim)
sim.UpdateTimeStep(40.0)
resource.setrlimit(resource.RLIMIT_FSIZE, (soft, hard))
signal.signal(signal.SIGXFSZ, old_handler)
T.check(len(caught.messages) == 1 and "could not write its CheckpointFile" in caught.messages[0]
        and manifest in caught.messages[0],
        "a full disk: one sentence naming the file (%s)" % caught.messages)
after = {f: open(os.path.join(folder, f), "rb").read() for f in os.listdir(folder)
         if not f.endswith(".part")}
T.check(after == before, "the previous checkpoint is intact (%s)" % sorted(after))
back = rain_runoff(terrain(3), RestartFile=manifest)
T.check(digest(back, 40.0) == reference[40.0], "and restarts to the uninterrupted run's bits")
# The state in memory is unharmed: the next outputs are the uninterrupted run's.
T.check(digest(sim, 60.0) == reference[60.0], "with room again: t = 60 s as uninterrupted")
files = sorted(f for f in os.listdir(folder) if not f.endswith(".part"))
T.check(files == ["run.3.0.vti", "run.json"], "the new checkpoint replaced the old (%s)" % files)
again = rain_runoff(terrain(3), RestartFile=manifest)
T.check(digest(again, 80.0) == reference[80.0], "and it restarts to the uninterrupted run's bits")

# ---- simulations interleaved on one device ---------------------------------
sphere = vtkSphereSource()
sphere.SetRadius(2.0)
sphere.SetCenter(40.0, 40.0, 0.0)
box = vtkCubeSource()
box.SetBounds(20.0, 30.0, 20.0, 36.0, 0.0, 4.0)


def snow(t):
    s = vtkSnowDeformationFilter()
    s.SetInputConnection(t.GetOutputPort())
    s.SetObjectsConnection(sphere.GetOutputPort())
    s.SetInitialSnowDepth(0.3)
    s.SetEndTime(1.0)
    s.SetOutputInterval(0.25)
    return s


def accumulation(t):
    s = vtkSnowAccumulationFilter()
    s.SetInputConnection(t.GetOutputPort())
    s.SetObjectsConnection(box.GetOutputPort())
    s.SetSnowfallRate(3.0)
    s.SetNoiseAmplitude(0.2)
    s.SetExposureResolution(64)
    s.SetTimeStep(900.0)
    s.SetEndTime(4 * 3600.0)
    s.SetOutputInterval(3600.0)
    return s


def melt(t):
    s = vtkSnowMeltFilter()
    s.SetInputConnection(t.GetOutputPort())
    s.SetInitialSnowDepth(0.5)
    s.SetAirTemperature(3.0)
    s.SetCastShadows(1)
    s.SetEndTime(4 * 86400.0)
    s.SetOutputInterval(86400.0)
    return s


def water(t):
    t.Update()
    low, high = t.GetOutput().GetPointData().GetArray("elevation").GetRange()
    s = vtkWaterSurfaceFilter()
    s.SetInputConnection(t.GetOutputPort())
    s.SetUseLakeLevel(1)
    s.SetLakeLevel(low + 0.4 * (high - low))
    s.SetDropRate(0.2)
    s.SetEndTime(4.0)
    s.SetOutputInterval(1.0)
    return s


# (name, a maker of the simulation on its own terrain, the times asked, in
# an order that goes back as well as forward)
cases = [
    ("Rain Runoff, FlowModel 0", lambda: rain_runoff(terrain(5), FlowModel=0),
     [20.0, 60.0, 40.0, 100.0, 200.0]),
    ("Rain Runoff, FlowModel 1", lambda: rain_runoff(terrain(6, 80), FlowModel=1),
     [20.0, 60.0, 40.0, 100.0, 200.0]),
    ("Snow Deformation", lambda: snow(terrain(7, 64)), [0.25, 0.75, 0.5, 1.0, 0.25]),
    ("Snow Accumulation", lambda: accumulation(terrain(8, 48)),
     [3600.0, 10800.0, 7200.0, 14400.0, 0.0]),
    ("Snow Melt", lambda: melt(terrain(9, 48)), [86400.0, 3 * 86400.0, 172800.0, 345600.0,
                                                 86400.0]),
    ("Water Surface", lambda: water(terrain(10, 48)), [1.0, 3.0, 2.0, 4.0, 1.0]),
]
want = {name: [T.digest_all(make(), t) for t in times] for name, make, times in cases}
# All of them in one process, each request of one followed by one of the
# next, in turn (the last simulation updated before each is another one).
together = [(name, make(), times) for name, make, times in cases]
caught = T.ErrorCatcher(*[sim for _, sim, _ in together])
got = {name: [] for name, _, _ in cases}
for k in range(5):
    for name, sim, times in reversed(together) if k % 2 else together:
        got[name].append(T.digest_all(sim, times[k]))
T.check(not caught.messages, "interleaved: no errors (%s)" % caught.text()[:300])
for name, _, times in cases:
    T.check(got[name] == want[name], "interleaved, %s gives its own bits alone (%s)"
            % (name, [g == w for g, w in zip(got[name], want[name])]))
    T.check(len(set(want[name])) == len(set(times)),
            "%s: the times differ (the check can fail)" % name)
T.finish()
