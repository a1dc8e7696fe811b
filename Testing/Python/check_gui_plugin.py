"""The plugin loads in the ParaView GUI: starts `paraview` (on the test
session's Xvfb) with PV_PLUGIN_PATH set, lets it run gui_plugin_script.py and exit, and checks what
the script recorded."""
import os
import subprocess
import sys

here = os.path.dirname(os.path.abspath(__file__))
scratch = sys.argv[sys.argv.index("--scratch") + 1]
result = os.path.join(scratch, "gui_result.txt")
if os.path.exists(result):
    os.remove(result)
plugin_dir = sys.argv[sys.argv.index("--plugin-dir") + 1]
click_log = os.path.join(scratch, "gui_abort_click.txt")
if os.path.exists(click_log):
    os.remove(click_log)
# GraupelGui clicks the abort button 1 s into the long update (see
# gui_plugin_script.py and pqGraupelAbortStarter.cxx).
env = dict(os.environ, GRAUPEL_GUI_RESULT=result, PV_PLUGIN_PATH=plugin_dir,
           GRAUPEL_GUI_TEST_ABORT_MS="1000", GRAUPEL_GUI_TEST_ABORT_LOG=click_log)
cmd = ["paraview", "--dr",
       "--script=" + os.path.join(here, "gui_plugin_script.py"), "--exit"]
proc = subprocess.run(cmd, env=env, timeout=240)
lines = open(result).read().splitlines() if os.path.exists(result) else []
text = lines[0] if lines else ""
expected = "found=ProceduralTerrain,EXRHeightFieldReader points=768"
print("paraview exit code %d; recorded: %r" % (proc.returncode, text))
checks = [proc.returncode == 0 and text == expected]

# The abort: the button was enabled and clicked, the Render returned soon
# after with an empty, ABORTED output, and the simulation was set up once
# (a second run inside the Render would take as long as the whole update).
abort = dict(kv.split("=") for kv in lines[1].split()) if len(lines) > 1 and lines[1] else {}
click = open(click_log).read().split() if os.path.exists(click_log) else []
print("abort: recorded %r; click %r" % (abort, click))
if abort and click:
    click_to_return = float(abort["end"]) - float(click[0])
    print("click to return %.2f s (update started %.2f s before the click)"
          % (click_to_return, float(click[0]) - float(abort["start"])))
    checks.append(click[1] == "enabled")
    checks.append(abort["aborted"] == "1" and abort["points"] == "0")
    checks.append(abort["restarts"] == "1")
    checks.append(0.0 <= click_to_return < 3.0)
else:
    checks.append(False)
ok = all(checks)
print("%d passed, %d failed" % (sum(checks), len(checks) - sum(checks)))
sys.exit(0 if ok else 1)
