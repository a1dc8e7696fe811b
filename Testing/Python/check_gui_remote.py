"""The GUI's abort button with a remote server: starts `mpiexec -n 2 pvserver`
on a free loopback port and `paraview` connected to it (both on the test
session's Xvfb: a server without a display makes the GUI stop at a modal
warning), loading the plugin on both sides. The GUI's script shows a long
Rain Runoff on the DEM and moves to its end time; GraupelGui clicks the
abort button 1.5 s into that update (GRAUPEL_GUI_TEST_ABORT_MS), which sends
Graupel's abort message to the server. The Render must return within 3 s of
the click with an empty output, the button enabled when clicked, each
server rank aborted once (not run again for the second port or the
representation), the pipeline usable after (an earlier time renders its
points), and the server gone after the GUI exits.

    python3 check_gui_remote.py --plugin P --data D --scratch S --mpiexec M --pvserver PVSERVER"""
import os
import socket
import subprocess
import sys
import time

here = os.path.dirname(os.path.abspath(__file__))


def arg(name):
    return sys.argv[sys.argv.index("--" + name) + 1]


scratch = os.path.join(arg("scratch"), "gui_remote")
os.makedirs(scratch, exist_ok=True)
result = os.path.join(scratch, "result.txt")
click_log = os.path.join(scratch, "click.txt")
script = os.path.join(scratch, "script.py")
for f in (result, click_log):
    if os.path.exists(f):
        os.remove(f)
plugin = arg("plugin")
dem = os.path.join(arg("data"), "jacksboro_fault_dem.tif")
open(script, "w").write(r'''
import time
from paraview.simple import *
LoadPlugin(%(plugin)r, remote=True, ns=globals())
LoadPlugin(%(plugin)r, remote=False, ns=globals())
dem = GISRasterReader(FileName=%(dem)r)
rain = RainRunoff(Input=dem, RainRate=50.0, EndTime=36000.0, OutputInterval=1800.0)
Show(rain)
Render()
scene = GetAnimationScene()
scene.UpdateAnimationUsingDataTimeSteps()
start = time.time()
scene.AnimationTime = 36000.0
Render()
end = time.time()
aborted = rain.GetDataInformation().GetNumberOfPoints()
scene.AnimationTime = 1800.0
Render()
after = rain.GetDataInformation().GetNumberOfPoints()
open(%(result)r, "w").write("start=%%.3f end=%%.3f points=%%d after=%%d\n"
                            %% (start, end, aborted, after))
''' % {"plugin": plugin, "dem": dem, "result": result})

s = socket.socket()
s.bind(("127.0.0.1", 0))
port = s.getsockname()[1]
s.close()
keep = ("OMPI_ALLOW_RUN_AS_ROOT", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM",
        "OMPI_MCA_rmaps_base_oversubscribe")
env = {k: v for k, v in os.environ.items()
       if k in keep or not (k.startswith(("OMPI_", "PMIX_", "OPAL_")) or k == "PV_PLUGIN_PATH")}
server = subprocess.Popen([arg("mpiexec"), "-n", "2", "--oversubscribe", arg("pvserver"),
                           "--server-port=%d" % port, "--hostname=localhost"],
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env)
gui_env = dict(env, GRAUPEL_GUI_TEST_ABORT_MS="1500", GRAUPEL_GUI_TEST_ABORT_LOG=click_log)
try:
    gui = subprocess.run(["paraview", "--dr", "--server-url=cs://localhost:%d" % port,
                          "--script=" + script, "--exit"], env=gui_env, timeout=300,
                         capture_output=True, text=True)
finally:
    try:
        server_out, _ = server.communicate(timeout=30)
        server_exited = True
    except subprocess.TimeoutExpired:
        server.kill()
        server_out, _ = server.communicate()
        server_exited = False
print("paraview exit code %d" % gui.returncode)
print(gui.stderr[-1500:])
print("server:", server_out[-1500:])
got = dict(kv.split("=") for kv in open(result).read().split()) if os.path.exists(result) else {}
click = open(click_log).read().split() if os.path.exists(click_log) else []
print("recorded %r; click %r" % (got, click))
checks = []


def check(cond, what):
    checks.append(cond)
    print(("ok: " if cond else "CHECK failed: ") + what)


check(gui.returncode == 0 and got != {}, "the GUI ran its script and exited")
check(len(click) == 2 and click[1] == "enabled", "the abort button was enabled when clicked")
if got and len(click) == 2:
    back = float(got["end"]) - float(click[0])
    print("click to return %.2f s (the update ran %.2f s before the click)"
          % (back, float(click[0]) - float(got["start"])))
    check(0.0 <= back < 3.0, "the Render returned %.2f s after the click" % back)
check(got.get("points") == "0", "the aborted output is empty (%s points)" % got.get("points"))
check(int(got.get("after", "0")) > 0, "an earlier time renders after it (%s points)"
      % got.get("after"))
aborts = server_out.count("the update was aborted")
check(aborts == 2, "each of the 2 server ranks aborted once (%d)" % aborts)
check(server_exited, "the server exited with the GUI")
print("%d passed, %d failed" % (checks.count(True), checks.count(False)))
sys.exit(0 if all(checks) else 1)
