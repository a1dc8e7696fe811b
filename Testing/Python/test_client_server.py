"""Graupel on a remote server: `mpiexec -n 2 pvserver` on a free loopback port,
a `pvpython` client that connects to it, loads the plugin on both sides
(LoadPlugin(path, remote=True), then remote=False; the server has no
PV_PLUGIN_PATH), runs Rain Runoff on the DEM in Data/ on the server and
saves the result there (a parallel .pvti, each rank its piece, and the
hydrograph as CSV); then the same pipeline in `mpiexec -n 2 pvbatch`. The
client's fields, ledger and hydrograph must equal pvbatch's bit for bit;
an error (a RainRunoff on a 3-D image) reaches the client as one sentence
and the pipeline stays usable; and when the client disconnects the server
ranks exit, leaving no process behind.

    pvpython test_client_server.py --data D --scratch S --plugin P --mpiexec M
        --pvserver PVSERVER --pvbatch PVBATCH --pvpython PVPYTHON"""
import csv
import os
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

PIPELINE = r'''
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
'''
CLIENT = r'''
import sys, time
from paraview.simple import *
from paraview import servermanager
port, PLUGIN, DEM, OUT = int(sys.argv[1]), sys.argv[2], sys.argv[3], sys.argv[4]
for k in range(150):
    try:
        Connect("localhost", port)
        break
    except Exception:
        time.sleep(0.2)
print("RANKS", servermanager.ActiveConnection.GetNumberOfDataPartitions(), flush=True)
LoadPlugin(PLUGIN, remote=True, ns=globals())
LoadPlugin(PLUGIN, remote=False, ns=globals())
''' + PIPELINE + r'''
bad = RainRunoff(Input=Wavelet())
bad.UpdatePipeline(0.0)
info = bad.GetDataInformation()
print("BAD POINTS", info.GetNumberOfPoints(), flush=True)
rain.UpdatePipeline(300.0)
print("AFTER", rain.GetDataInformation().GetNumberOfPoints(), flush=True)
Disconnect()
print("DISCONNECTED", flush=True)
'''
BATCH = r'''
import sys
from paraview.simple import *
PLUGIN, DEM, OUT = sys.argv[1], sys.argv[2], sys.argv[3]
LoadPlugin(PLUGIN, ns=globals())
''' + PIPELINE
client = os.path.join(folder, "client.py")
batch = os.path.join(folder, "batch.py")
open(client, "w").write(CLIENT)
open(batch, "w").write(BATCH)
dem = os.path.join(a.data, "jacksboro_fault_dem.tif")

s = socket.socket()
s.bind(("127.0.0.1", 0))
port = s.getsockname()[1]
s.close()
# pvpython, which runs this test, is an MPI singleton: its OMPI_*/PMIX_*
# variables would make the children's mpiexec think it runs inside a job.
# The server gets no PV_PLUGIN_PATH: the client loads the plugin there.
keep = ("OMPI_ALLOW_RUN_AS_ROOT", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "OMPI_MCA_rmaps_base_oversubscribe")
env = {k: v for k, v in os.environ.items()
       if k in keep or not (k.startswith(("OMPI_", "PMIX_", "OPAL_")) or k == "PV_PLUGIN_PATH")}
server = subprocess.Popen([a.mpiexec, "-n", "2", "--oversubscribe", a.pvserver,
                           "--server-port=%d" % port, "--hostname=localhost"],
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env)
try:
    run = subprocess.run([a.pvpython, client, str(port), a.plugin, dem,
                          os.path.join(folder, "cs")], capture_output=True, text=True,
                         timeout=240, env=env)
finally:
    try:
        server_out, _ = server.communicate(timeout=30)
        exited = True
    except subprocess.TimeoutExpired:
        server.kill()
        server_out, _ = server.communicate()
        exited = False
print(run.stdout[-2000:])
print(run.stderr[-3000:])
print("server:", server_out[-1500:])
said = dict(line.split(" ", 1) for line in run.stdout.splitlines() if " " in line)
T.check(run.returncode == 0, "the client ran (exit %d)" % run.returncode)
T.check(said.get("RANKS") == "2", "the client sees 2 server ranks (%s)" % said.get("RANKS"))
T.check(said.get("BAD") == "POINTS 0" and run.stderr.count("needs a 2-D terrain") == 1,
        "an error reaches the client once, with an empty output (%r, %d)"
        % (said.get("BAD"), run.stderr.count("needs a 2-D terrain")))
T.check(said.get("AFTER", "0") != "0", "and the pipeline stays usable (%s)" % said.get("AFTER"))
T.check(exited and server.returncode is not None,
        "the server ranks exit when the client disconnects (%s)" % server.returncode)

ref = subprocess.run([a.mpiexec, "-n", "2", "--oversubscribe", a.pvbatch, batch, a.plugin, dem,
                      os.path.join(folder, "batch")], capture_output=True, text=True,
                     timeout=240, env=env)
T.check(ref.returncode == 0, "the pvbatch run (exit %d: %s)" % (ref.returncode, ref.stderr[-500:]))
ref_ledger = [line for line in ref.stdout.splitlines() if line.startswith("LEDGER")]
T.check(said.get("LEDGER") is not None and ref_ledger and
        said["LEDGER"] == ref_ledger[0].split(" ", 1)[1],
        "the ledger is pvbatch's to the bit (%s | %s)" % (said.get("LEDGER"), ref_ledger))

from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402
from vtkmodules.vtkIOXML import vtkXMLPImageDataReader  # noqa: E402
import numpy as np  # noqa: E402


def read(stem):
    path = os.path.join(folder, stem + ".pvti")
    if not os.path.exists(path):
        return None
    r = vtkXMLPImageDataReader()
    r.SetFileName(path)
    r.Update()
    return r.GetOutput()


cs, pb = read("cs"), read("batch")
T.check(cs is not None and pb is not None and cs.GetNumberOfPoints() == 375 * 395
        and pb.GetNumberOfPoints() == 375 * 395, "both saved the whole grid from 2 ranks")
if cs is not None and pb is not None:
    names = [cs.GetPointData().GetArrayName(k) for k in range(cs.GetPointData().GetNumberOfArrays())]
    T.check(len(names) >= 8, "arrays %s" % names)
    for name in names:
        x = vtk_to_numpy(cs.GetPointData().GetArray(name))
        y = vtk_to_numpy(pb.GetPointData().GetArray(name)) if pb.GetPointData().GetArray(name) else None
        T.check(y is not None and np.array_equal(x, y, equal_nan=True),
                "'%s' is pvbatch's bit for bit" % name)
rows = []
for stem in ("cs", "batch"):
    path = os.path.join(folder, stem + "_hydrograph.csv")
    rows.append(list(csv.reader(open(path))) if os.path.exists(path) else None)
T.check(rows[0] is not None and rows[0] == rows[1] and len(rows[0]) == 4
        and [r[rows[0][0].index("time")] for r in rows[0][1:]] == ["0", "300", "600"],
        "the hydrograph is pvbatch's, each output once (%s)" % (rows[0],))
T.finish()
