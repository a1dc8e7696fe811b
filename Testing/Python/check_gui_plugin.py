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
env = dict(os.environ, GRAUPEL_GUI_RESULT=result, PV_PLUGIN_PATH=plugin_dir)
cmd = ["paraview", "--dr",
       "--script=" + os.path.join(here, "gui_plugin_script.py"), "--exit"]
proc = subprocess.run(cmd, env=env, timeout=240)
text = open(result).read().strip() if os.path.exists(result) else ""
expected = "found=ProceduralTerrain,EXRHeightFieldReader points=768"
print("paraview exit code %d; recorded: %r" % (proc.returncode, text))
ok = proc.returncode == 0 and text == expected
print("%d passed, %d failed" % (int(ok), int(not ok)))
sys.exit(0 if ok else 1)
