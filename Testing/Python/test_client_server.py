"""Graupel on a remote server: `mpiexec -n 2 pvserver` on a free loopback port,
a `pvpython` client that connects to it, loads the plugin on both sides
(LoadPlugin(path, remote=True), then remote=False; the server has no
PV_PLUGIN_PATH), runs Rain Runoff on the DEM in Data/, Snow Deformation (a
sphere ploughing across the ranks' shared edge) and Snow Accumulation (snow
on a box) on the server and saves the results there (parallel .pvti/.pvtp,
each rank its piece, the hydrograph as CSV); then the same pipeline in
`mpiexec -n 2 pvbatch`. The client's fields, ledgers, hydrograph and
objects' ports must equal pvbatch's bit for bit, the objects once (not once
per rank).

Progress and abort: a long Rain Runoff's progress reaches the client, whose
progress observer then calls graupel.remote.abort_update(); the server's
update must end within a second of that, with an empty output and the
warning once on the client, and the same filter must then run another time
to pvbatch's bits; an abort sent while the server idles is dropped (the
pipeline after it gives pvbatch's bits). An error (a RainRunoff on a 3-D image) reaches the
client as one sentence and the pipeline stays usable; when the client
disconnects the server ranks exit, leaving no process behind.

Disconnect in the middle of an update: a client killed (SIGKILL) while the
server runs a long update. The server ends that update at its next progress
report (the socket is closed) and its ranks exit within seconds, not after
the run; a second client then connects on the same port and runs the
pipeline to pvbatch's bits.

    pvpython test_client_server.py --data D --scratch S --plugin P --mpiexec M
        --pvserver PVSERVER --pvbatch PVBATCH --pvpython PVPYTHON"""
import csv
import os
import signal
import socket
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402


def extra(p):
    for name in ("mpiexec", "pvserver", "pvbatch", "pvpython"):
        p.add_argument("--" + name, required=True)


a = T.args(extra)
folder = os.path.join(a.scratch, "client_server")
os.makedirs(folder, exist_ok=True)
for f in os.listdir(folder):
    path = os.path.join(folder, f)
    if os.path.isfile(path):
        os.remove(path)

SPHERE_RES = 24
PIPELINE = r"""
dem = GISRasterReader(FileName=DEM)
rain = RainRunoff(Input=dem, RainRate=50.0, EndTime=600.0, OutputInterval=300.0)
scene = GetAnimationScene()
scene.UpdateAnimationUsingDataTimeSteps()
scene.AnimationTime = 600.0
rain.UpdatePipeline(600.0)
SaveData(OUT + ".pvti", proxy=rain)
SaveData(OUT + "_hydrograph.csv", proxy=OutputPort(rain, 1))
print("LEDGER", repr([rain.FieldData[n].GetRange()[0] for n in
      ("rain_volume", "outflow_volume", "stored_volume", "balance_error")]), flush=True)

# A sphere ploughing along the two ranks' shared edge.
field = ProceduralTerrain(Dimensions=[96, 160], Spacing=0.05, Seed=5, HeightScale=0.3)
ball = Sphere(Center=[1.0, 0.5 * 159 * 0.05, 0.6], Radius=0.4, ThetaResolution=%(res)d,
              PhiResolution=%(res)d)
plough = SnowDeformation(Input=field, Objects=ball, ObjectVelocity=[2.0, 0.0, 0.0],
                         TimeStep=1.0 / 64.0, EndTime=0.5, OutputInterval=0.25)
plough.UpdatePipeline(0.5)
SaveData(OUT + "_plough.pvti", proxy=plough)
SaveData(OUT + "_plough_objects.pvtp", proxy=OutputPort(plough, 1))
print("PLOUGH", repr([plough.FieldData[n].GetRange()[0] for n in
      ("snow_volume", "snow_mass", "displaced_volume", "balance_error")]), flush=True)

# Wind-driven snow on hills and on a box.
hills = ProceduralTerrain(Dimensions=[64, 120], Spacing=0.1, Seed=11, Frequency=300.0,
                          HeightScale=2.5)
box = Box(Center=[3.15, 5.95, 2.2], XLength=1.6, YLength=2.4, ZLength=0.6)
drift = SnowAccumulation(Input=hills, Objects=box, SnowDirection=[0.3, 1.0, -1.0], Flutter=3.0,
                         SnowfallRate=8.0, NoiseScale=0.4, ExposureResolution=128, BlurRadius=2,
                         Dilation=1, MaxDepth=0.3, StabilityFactor=0.01, TimeStep=300.0,
                         EndTime=1800.0, OutputInterval=900.0)
drift.UpdatePipeline(1800.0)
SaveData(OUT + "_drift.pvti", proxy=drift)
SaveData(OUT + "_drift_objects.pvtp", proxy=OutputPort(drift, 1))
print("DRIFT", repr([drift.FieldData[n].GetRange()[0] for n in
      ("stored_volume_terrain", "stored_volume_objects", "shed_volume", "dropped_volume")]),
      flush=True)
""" % {"res": SPHERE_RES}
# Every client: connect to the server (it may still be starting).
REACH = r"""
import os, signal, sys, time
from paraview.simple import *
from paraview import servermanager
port, PLUGIN, DEM, OUT = int(sys.argv[1]), sys.argv[2], sys.argv[3], sys.argv[4]
for k in range(150):
    try:
        Connect("localhost", port)
        break
    except Exception:
        time.sleep(0.2)
"""
CONNECT = REACH + r"""
print("RANKS", servermanager.ActiveConnection.GetNumberOfDataPartitions(), flush=True)
LoadPlugin(PLUGIN, remote=True, ns=globals())
LoadPlugin(PLUGIN, remote=False, ns=globals())
from graupel import remote
handler = servermanager.ActiveConnection.Session.GetProgressHandler()
"""
CLIENT = CONNECT + r"""
# Progress reaches the client; its abort stops the server's update.
source = GISRasterReader(FileName=DEM)
long = RainRunoff(Input=source, RainRate=50.0, EndTime=36000.0, OutputInterval=36000.0)
texts, sent = [], []
def on_progress(h, event):
    text = h.GetLastProgressText() or ""
    if text.startswith("Rain Runoff: t = "):
        texts.append(text)
        if len(texts) == 2 and not sent:
            sent.append((time.time(), remote.abort_update()))
tag = handler.AddObserver("ProgressEvent", on_progress)
long.UpdatePipeline(36000.0)
done = time.time()
handler.RemoveObserver(tag)
print("PROGRESS", len(texts), flush=True)
print("ABORT", "%s %.3f" % (sent[0][1], done - sent[0][0]) if sent else "none", flush=True)
print("ABORTED", long.GetDataInformation().GetNumberOfPoints(), flush=True)
# The same filter runs again, another time: pvbatch's bits.
long.EndTime = 600.0
long.OutputInterval = 300.0
long.UpdatePipeline(600.0)
print("AGAIN", repr([long.FieldData[n].GetRange()[0] for n in
      ("rain_volume", "outflow_volume", "stored_volume", "balance_error")]), flush=True)
Delete(long)
# An abort with nothing running is dropped when the server reads it.
print("IDLE ABORT", remote.abort_update(), flush=True)
""" + PIPELINE + r"""
bad = RainRunoff(Input=Wavelet())
bad.UpdatePipeline(0.0)
info = bad.GetDataInformation()
print("BAD POINTS", info.GetNumberOfPoints(), flush=True)
rain.UpdatePipeline(300.0)
print("AFTER", rain.GetDataInformation().GetNumberOfPoints(), flush=True)
Disconnect()
print("DISCONNECTED", flush=True)
"""
# A client killed in the middle of a long update.
KILLED = CONNECT + r"""
source = GISRasterReader(FileName=DEM)
long = RainRunoff(Input=source, RainRate=50.0, EndTime=36000.0, OutputInterval=36000.0)
print("UPDATING", flush=True)
long.UpdatePipeline(36000.0)
print("NOT KILLED", flush=True)
"""
SECOND = CONNECT + r"""
dem = GISRasterReader(FileName=DEM)
rain = RainRunoff(Input=dem, RainRate=50.0, EndTime=600.0, OutputInterval=300.0)
rain.UpdatePipeline(600.0)
print("LEDGER", repr([rain.FieldData[n].GetRange()[0] for n in
      ("rain_volume", "outflow_volume", "stored_volume", "balance_error")]), flush=True)
Disconnect()
"""
# Loaded at start on both sides from the build's plugin configuration file.
CONFIGURED = REACH + r"""
terrain = ProceduralTerrain(Dimensions=[40, 30])
rain = RainRunoff(Input=terrain, EndTime=60.0, OutputInterval=60.0)
rain.UpdatePipeline(60.0)
print("POINTS", rain.GetDataInformation().GetNumberOfPoints(), flush=True)
Disconnect()
"""
BATCH = r"""
import sys
from paraview.simple import *
PLUGIN, DEM, OUT = sys.argv[1], sys.argv[2], sys.argv[3]
LoadPlugin(PLUGIN, ns=globals())
""" + PIPELINE
scripts = {}
for name, text in (("client", CLIENT), ("killed", KILLED), ("second", SECOND),
                   ("configured", CONFIGURED), ("batch", BATCH)):
    scripts[name] = os.path.join(folder, name + ".py")
    open(scripts[name], "w").write(text)
dem = os.path.join(a.data, "jacksboro_fault_dem.tif")

# pvpython, which runs this test, is an MPI singleton: its OMPI_*/PMIX_*
# variables would make the children's mpiexec think it runs inside a job.
# The server gets no PV_PLUGIN_PATH: the client loads the plugin there.
keep = ("OMPI_ALLOW_RUN_AS_ROOT", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "OMPI_MCA_rmaps_base_oversubscribe")
env = {k: v for k, v in os.environ.items()
       if k in keep or not (k.startswith(("OMPI_", "PMIX_", "OPAL_")) or k == "PV_PLUGIN_PATH")}


def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def start_server(port, *options, environment=None):
    return subprocess.Popen([a.mpiexec, "-n", "2", "--oversubscribe", a.pvserver,
                             "--server-port=%d" % port, "--hostname=localhost"] + list(options),
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            env=environment or env)


def client(name, port, stem, timeout=300, environment=None):
    return subprocess.run([a.pvpython, scripts[name], str(port), a.plugin, dem,
                           os.path.join(folder, stem)], capture_output=True, text=True,
                          timeout=timeout, env=environment or env)


def kill_while_updating(port):
    """Starts the KILLED client and kills it (SIGKILL) 3 s into its long
    update; returns its exit status, whether it had begun, and when it died."""
    p = subprocess.Popen([a.pvpython, scripts["killed"], str(port), a.plugin, dem, "x"],
                         stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, env=env)
    begun = False
    deadline = time.time() + 120
    for line in p.stdout:
        if line.startswith("UPDATING"):
            begun = True
            break
        if time.time() > deadline:
            break
    time.sleep(3.0)
    p.kill()
    p.wait()
    return p.returncode, begun, time.time()


def stop(server, wait):
    """The server's output, and whether it exited by itself within `wait` s."""
    try:
        out, _ = server.communicate(timeout=wait)
        return out, True
    except subprocess.TimeoutExpired:
        server.kill()
        out, _ = server.communicate()
        return out, False


def said(run):
    return dict(line.split(" ", 1) for line in run.stdout.splitlines() if " " in line)


def left_behind(port):
    ps = subprocess.run(["ps", "-eo", "args"], capture_output=True, text=True).stdout
    return [line for line in ps.splitlines() if "--server-port=%d" % port in line]


# --- The client's session: abort, pipeline, error, disconnect. ---
port = free_port()
server = start_server(port)
try:
    run = client("client", port, "cs")
finally:
    server_out, exited = stop(server, 30)
print(run.stdout[-3000:])
print(run.stderr[-3000:])
print("server:", server_out[-1500:])
got = said(run)
T.check(run.returncode == 0, "the client ran (exit %d)" % run.returncode)
T.check(got.get("RANKS") == "2", "the client sees 2 server ranks (%s)" % got.get("RANKS"))
T.check(int(got.get("PROGRESS", "0")) >= 2,
        "the server's progress reached the client (%s reports)" % got.get("PROGRESS"))
abort = got.get("ABORT", "none").split()
print("abort: update ended %s s after the client sent it; progress reports: %s"
      % (abort[1:] or abort, got.get("PROGRESS")))
T.check(len(abort) == 2 and abort[0] == "True" and float(abort[1]) < 1.0,
        "the client's abort ended the server's update within a second (%s s after it was sent)"
        % (abort[1] if len(abort) == 2 else abort))
T.check(got.get("ABORTED") == "0", "the aborted update's output is empty (%s points)"
        % got.get("ABORTED"))
T.check(run.stderr.count("the update was aborted") == 1,
        "the client hears of the abort once (%d)" % run.stderr.count("the update was aborted"))
T.check(got.get("BAD") == "POINTS 0" and run.stderr.count("needs a 2-D terrain") == 1,
        "an error reaches the client once, with an empty output (%r, %d)"
        % (got.get("BAD"), run.stderr.count("needs a 2-D terrain")))
T.check(got.get("AFTER", "0") != "0", "and the pipeline stays usable (%s)" % got.get("AFTER"))
T.check(exited and server.returncode is not None,
        "the server ranks exit when the client disconnects (%s)" % server.returncode)

ref = subprocess.run([a.mpiexec, "-n", "2", "--oversubscribe", a.pvbatch, scripts["batch"],
                      a.plugin, dem, os.path.join(folder, "batch")], capture_output=True,
                     text=True, timeout=300, env=env)
T.check(ref.returncode == 0, "the pvbatch run (exit %d: %s)" % (ref.returncode, ref.stderr[-500:]))
expected = {}
for line in ref.stdout.splitlines():
    if " " in line:
        key, value = line.split(" ", 1)
        expected.setdefault(key, value)
for key in ("LEDGER", "PLOUGH", "DRIFT"):
    T.check(got.get(key) is not None and got.get(key) == expected.get(key),
            "the %s ledger is pvbatch's to the bit (%s | %s)" % (key.lower(), got.get(key),
                                                                  expected.get(key)))
T.check(got.get("IDLE") == "ABORT True",
        "an abort sent while the server idles is dropped: the pipeline after it runs to "
        "pvbatch's bits (%s)" % got.get("IDLE"))
T.check(got.get("AGAIN") is not None and got.get("AGAIN") == expected.get("LEDGER"),
        "the aborted filter runs again to pvbatch's bits (%s)" % got.get("AGAIN"))

from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402
from vtkmodules.vtkFiltersSources import vtkCubeSource, vtkSphereSource  # noqa: E402
from vtkmodules.vtkIOXML import vtkXMLPImageDataReader, vtkXMLPPolyDataReader  # noqa: E402
import numpy as np  # noqa: E402


def read(stem, kind):
    path = os.path.join(folder, stem + (".pvti" if kind == "image" else ".pvtp"))
    if not os.path.exists(path):
        return None
    r = vtkXMLPImageDataReader() if kind == "image" else vtkXMLPPolyDataReader()
    r.SetFileName(path)
    r.Update()
    return r.GetOutput()


def same_arrays(x, y, what):
    names = [x.GetPointData().GetArrayName(k) for k in range(x.GetPointData().GetNumberOfArrays())]
    T.check(len(names) >= 1, "%s: arrays %s" % (what, names))
    for name in names:
        u = vtk_to_numpy(x.GetPointData().GetArray(name))
        v = y.GetPointData().GetArray(name)
        T.check(v is not None and np.array_equal(u, vtk_to_numpy(v), equal_nan=True),
                "%s: '%s' is pvbatch's bit for bit" % (what, name))


for suffix, points in (("", 375 * 395), ("_plough", 96 * 160), ("_drift", 64 * 120)):
    cs, pb = read("cs" + suffix, "image"), read("batch" + suffix, "image")
    T.check(cs is not None and pb is not None and cs.GetNumberOfPoints() == points
            and pb.GetNumberOfPoints() == points,
            "%s: both saved the whole grid from 2 ranks" % (suffix[1:] or "rain"))
    if cs is not None and pb is not None:
        same_arrays(cs, pb, suffix[1:] or "rain")
sphere = vtkSphereSource()
sphere.SetThetaResolution(SPHERE_RES)
sphere.SetPhiResolution(SPHERE_RES)
sphere.Update()
cube = vtkCubeSource()
cube.Update()
for suffix, single in (("_plough_objects", sphere.GetOutput().GetNumberOfPoints()),
                       ("_drift_objects", cube.GetOutput().GetNumberOfPoints())):
    cs, pb = read("cs" + suffix, "poly"), read("batch" + suffix, "poly")
    T.check(cs is not None and pb is not None and cs.GetNumberOfPoints() == single
            and pb.GetNumberOfPoints() == single,
            "%s: the objects once, not once a rank (%s and %s points, one object has %d)"
            % (suffix[1:], cs and cs.GetNumberOfPoints(), pb and pb.GetNumberOfPoints(), single))
    if cs is not None and pb is not None:
        same_arrays(cs, pb, suffix[1:])
rows = []
for stem in ("cs", "batch"):
    path = os.path.join(folder, stem + "_hydrograph.csv")
    rows.append(list(csv.reader(open(path))) if os.path.exists(path) else None)
T.check(rows[0] is not None and rows[0] == rows[1] and len(rows[0]) == 4
        and [r[rows[0][0].index("time")] for r in rows[0][1:]] == ["0", "300", "600"],
        "the hydrograph is pvbatch's, each output once (%s)" % (rows[0],))

# --- A client killed in the middle of an update. ---
port = free_port()
server = start_server(port)
try:
    status, begun, gone = kill_while_updating(port)
finally:
    server_out, exited = stop(server, 30)
ended = time.time() - gone
print("server:", server_out[-800:])
print("killed client: the server exited %.2f s after it" % ended)
T.check(status == -signal.SIGKILL and begun,
        "the client was killed during the server's update (exit %d)" % status)
T.check(exited and ended < 10.0 and not left_behind(port),
        "the server's update ends and its ranks exit %.1f s after the client died (a full run "
        "takes minutes); no process left: %s" % (ended, left_behind(port)))

# --- A second client, on the same port: the port is free and the run clean. ---
# (ParaView 5.11's --multi-clients server exits too when its first client
# dies during an update, so a second client meets a new server either way.)
server = start_server(port)
try:
    second = client("second", port, "second")
finally:
    server_out, exited = stop(server, 30)
print("second client:", second.stdout[-800:], second.stderr[-800:])
T.check(second.returncode == 0 and said(second).get("LEDGER") == expected.get("LEDGER"),
        "a second client connects on that port and runs to pvbatch's bits (exit %d, %s)"
        % (second.returncode, said(second).get("LEDGER")))
T.check(exited and not left_behind(port), "and no server process is left after it disconnects")

# --- PV_PLUGIN_CONFIG_FILE on both sides: the plugin is there at start. ---
config = os.path.join(os.path.dirname(os.path.dirname(a.plugin)), "graupel.plugins.xml")
T.check(os.path.exists(config), "the build made %s" % config)
configured_env = dict(env, PV_PLUGIN_CONFIG_FILE=config)
port = free_port()
server = start_server(port, environment=configured_env)
try:
    configured = client("configured", port, "configured", environment=configured_env)
finally:
    server_out, exited = stop(server, 30)
T.check(configured.returncode == 0 and int(said(configured).get("POINTS", "0")) >= 40 * 30,
        "with PV_PLUGIN_CONFIG_FILE on both sides a client runs Rain Runoff on the server without "
        "loading anything (exit %d, %s points: %s)" % (configured.returncode,
                                                       said(configured).get("POINTS"),
                                                       configured.stderr[-300:]))
T.finish()
