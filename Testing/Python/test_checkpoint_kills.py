"""Checkpoints that survive SIGKILL. A pvpython child runs Rain Runoff on a
256 x 256 Procedural Terrain with CheckpointFile, writing a checkpoint at
every output (10 s); it is killed with SIGKILL at a random moment, again and
again, always into the same folder (so the torn and stale files of earlier
kills lie there too). After each kill a fresh child restarts from the
manifest and steps one output further: every restart must be taken (no
torn piece, no refusal) and its water depth, discharge and ledger must be
those of an uninterrupted run at that output, bit for bit. The folder must
never hold more than the pieces of one checkpoint beside temporary files.

    pvpython test_checkpoint_kills.py --data D --scratch S [--kills N] [--seed K]

The test form kills 6 times; `./graupel.sh soak` 24. Before the pieces
were written under names of their own, then renamed, a kill during a
write tore the piece the manifest named (restart refused: "holds no state")
or left a manifest beside the next output's piece."""
import hashlib
import json
import os
import random
import signal
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

CHILD = r'''
import hashlib, json, sys
import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
import graupel
mode, folder, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
terrain = graupel.vtkProceduralTerrainSource()
terrain.SetDimensions(256, 256)
terrain.SetSpacing(2.0)
rain = graupel.vtkRainRunoffFilter()
rain.SetInputConnection(terrain.GetOutputPort())
rain.SetRainRate(100.0)
rain.SetEndTime(10.0 * n)
rain.SetOutputInterval(10.0)
def digest():
    out = rain.GetOutput()
    pd, fd = out.GetPointData(), out.GetFieldData()
    h = hashlib.sha256()
    for name in ("water_depth", "discharge", "max_depth"):
        h.update(vtk_to_numpy(pd.GetArray(name)).tobytes())
    for name in ("stored_volume", "outflow_volume", "rain_volume", "steps"):
        h.update(np.float64(fd.GetArray(name).GetValue(0)).tobytes())
    return h.hexdigest()
if mode == "reference":
    hashes = {}
    for k in range(1, n + 1):
        rain.UpdateTimeStep(10.0 * k)
        hashes[k] = digest()
    print("HASHES " + json.dumps(hashes), flush=True)
elif mode == "write":
    rain.SetCheckpointFile(folder + "/run.json")
    for k in range(1, n + 1):
        rain.UpdateTimeStep(10.0 * k)
        print("wrote %d" % k, flush=True)
else:
    manifest = json.load(open(folder + "/run.json"))
    index = manifest["output_index"]
    rain.SetRestartFile(folder + "/run.json")
    errors = []
    rain.AddObserver("ErrorEvent", lambda o, e: errors.append(e))
    rain.UpdateTimeStep(10.0 * (index + 1))
    ok = rain.GetOutput().GetNumberOfPoints() > 0 and not errors
    print("RESTART %s %d %s" % ("ok" if ok else "refused", index + 1, digest() if ok else "-"),
          flush=True)
'''


def extra(p):
    p.add_argument("--kills", type=int, default=6)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--python", default=sys.executable)


a = T.args(extra)
rng = random.Random(a.seed)
folder = os.path.join(a.scratch, "checkpoint_kills")
os.makedirs(folder, exist_ok=True)
for f in os.listdir(folder):
    os.remove(os.path.join(folder, f))
child = os.path.join(folder, "..", "checkpoint_kills_child.py")
with open(child, "w") as f:
    f.write(CHILD)
N = 24  # outputs of a writer's run


def run(*args, **kw):
    return subprocess.run([a.python, child] + list(args), capture_output=True, text=True,
                          timeout=600, **kw)


t0 = time.time()
ref = run("reference", folder, str(N))
lines = [line for line in ref.stdout.splitlines() if line.startswith("HASHES ")]
T.check(ref.returncode == 0 and lines, "the uninterrupted run (%s)" % ref.stderr[-500:])
if not lines:
    T.finish()
reference = {int(k): v for k, v in json.loads(lines[0][7:]).items()}
full_run = time.time() - t0  # what a writer's run takes, about (it also writes)
print("uninterrupted run of %d outputs: %.1f s" % (N, full_run))

restarts = refused = wrong = 0
for kill in range(a.kills):
    writer = subprocess.Popen([a.python, child, "write", folder, str(N)],
                              stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    # A moment within the run, after the first outputs have been written.
    time.sleep(rng.uniform(0.35, 0.95) * full_run + 1.0)
    writer.send_signal(signal.SIGKILL)
    out, _ = writer.communicate()
    written = out.count("wrote")
    if not os.path.exists(os.path.join(folder, "run.json")):
        print("kill %d: after %d outputs, no manifest yet" % (kill + 1, written))
        continue
    r = run("restart", folder, str(N))
    said = [line for line in r.stdout.splitlines() if line.startswith("RESTART ")]
    files = sorted(os.listdir(folder))
    pieces = [f for f in files if f.endswith(".vti")]
    print("kill %d: after %d outputs; %s; files %s"
          % (kill + 1, written, said[0] if said else r.stderr[-300:], files))
    T.check(len(pieces) <= 2, "at most the pieces of two checkpoints lie there (%s)" % pieces)
    if not said:
        refused += 1
        continue
    _, verdict, k, digest = said[0].split()
    restarts += 1
    if verdict != "ok":
        refused += 1
    elif digest != reference.get(min(int(k), N)):  # a writer done before its kill: EndTime
        wrong += 1
print("%d kills: %d restarts, %d refused, %d with other bits" % (a.kills, restarts, refused, wrong))
T.check(restarts >= a.kills // 2, "most kills left a checkpoint (%d of %d)" % (restarts, a.kills))
T.check(refused == 0, "no restart refused (%d)" % refused)
T.check(wrong == 0, "every restart goes on with the uninterrupted run's bits (%d differ)" % wrong)
T.finish()
