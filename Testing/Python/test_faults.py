"""Faults in one process, through the VTK layer:

  * A full disk while checkpoints are written (a file-size limit of 64 KiB,
    SIGXFSZ ignored, as `ulimit -f` would): the update that cannot write its
    checkpoint fails with one sentence naming the file; the previous
    checkpoint (manifest and piece) is intact and restarts; the simulation's
    state in memory is unharmed (the next output equals an uninterrupted
    run's); with room again the next checkpoint is written and restarts.
  * Two simulations in one process on one device, updated in interleaved
    order (Rain Runoff on two terrains, Snow Deformation beside them), give
    the same bits as each alone.
"""
import os
import resource
import signal
import sys


sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args()

from vtkmodules.vtkFiltersSources import vtkSphereSource  # noqa: E402

from graupel import (  # noqa: E402
    vtkProceduralTerrainSource,
    vtkRainRunoffFilter,
    vtkSnowDeformationFilter,
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

# ---- two simulations interleaved on one device ------------------------------
alone_a = rain_runoff(terrain(5), FlowModel=0)
alone_b = rain_runoff(terrain(6, 80), FlowModel=1)
sphere = vtkSphereSource()
sphere.SetRadius(2.0)
sphere.SetCenter(40.0, 40.0, 0.0)


def snow(t):
    s = vtkSnowDeformationFilter()
    s.SetInputConnection(t.GetOutputPort())
    s.SetObjectsConnection(sphere.GetOutputPort())
    s.SetInitialSnowDepth(0.3)
    s.SetEndTime(1.0)
    s.SetOutputInterval(0.25)
    return s


alone_s = snow(terrain(7, 64))
times = [20.0, 60.0, 40.0, 100.0, 200.0]
snow_times = [0.25, 0.75, 0.5, 1.0, 0.25]
want_a = [digest(alone_a, t) for t in times]
want_b = [digest(alone_b, t) for t in times]
want_s = [digest(alone_s, t, ("snow_depth", "snow_density")) for t in snow_times]
ia, ib, isn = rain_runoff(terrain(5), FlowModel=0), rain_runoff(terrain(6, 80), FlowModel=1), \
    snow(terrain(7, 64))
got_a, got_b, got_s = [], [], []
for k in range(len(times)):
    got_b.append(digest(ib, times[k]))
    got_s.append(digest(isn, snow_times[k], ("snow_depth", "snow_density")))
    got_a.append(digest(ia, times[k]))
T.check(got_a == want_a and got_b == want_b and got_s == want_s,
        "interleaved updates give each simulation's own bits (%s %s %s)"
        % (got_a == want_a, got_b == want_b, got_s == want_s))
T.check(len(set(want_a)) == len(set(times)), "the times differ (the check can fail)")
T.finish()
