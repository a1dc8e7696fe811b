"""The camera follows a reader's geometry in the GUI (Plugin/pqGraupelApplyLook.h):
File > Open of the DEM in Data/ (its spacing, 74.5 x 92.1 m, from the file),
Apply; then GeometryFromFile off (1 m spacing: the same heights on a 402 x 343 m
block), Apply. The saved states show the camera looking at the terrain each
time: its focal point within a tenth of the surface's size of the terrain's
centre, and its distance a few sizes. Before, the camera stayed where the
first Apply put it, 30 km away from the new 400 m block."""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gr_gui import APPLY, PANEL, State, paraview, write_events  # noqa: E402

scratch = sys.argv[sys.argv.index("--scratch") + 1]
plugin_dir = sys.argv[sys.argv.index("--plugin-dir") + 1]
data = sys.argv[sys.argv.index("--data") + 1]
states = [os.path.join(scratch, "gui_camera_%d.pvsm" % k) for k in (1, 2)]
script = os.path.join(scratch, "gui_camera.xml")
for s in states:
    if os.path.exists(s):
        os.remove(s)


def save(path):
    return [("pqClientMainWindow/menubar/menu_File", "activate", "actionFileSaveServerState"),
            ("pqClientMainWindow/FileSaveServerStateDialog", "filesSelected", path)]


write_events(script, [
    ("pqClientMainWindow/menubar/menu_File", "activate", "actionFileOpen"),
    ("pqClientMainWindow/FileOpenDialog", "filesSelected",
     os.path.join(os.path.abspath(data), "jacksboro_fault_dem.exr")),
    (APPLY, "activate", ""),
    ("pqClientMainWindow", "process_events", "1000"),
] + save(states[0]) + [
    (PANEL + "GeometryFromFile/CheckBox", "set_boolean", "false"),
    (APPLY, "activate", ""),
    ("pqClientMainWindow", "process_events", "1500"),
] + save(states[1]))
proc = paraview(script, plugin_dir)
print("paraview exit code %d" % proc.returncode)
checks = []
for k, (path, span) in enumerate(zip(states, ((402 * 74.5, 343 * 92.1), (402.0, 343.0)))):
    if not os.path.exists(path):
        print("no state %s: the GUI script did not get through" % path)
        sys.exit(1)
    S = State(path)
    views = [p for p in S.proxies.values() if p.get("type") == "RenderView"]
    focal = [float(v) for v in S.prop(views[0], "CameraFocalPoint")[0]]
    position = [float(v) for v in S.prop(views[0], "CameraPosition")[0]]
    centre = (0.5 * span[0], 0.5 * span[1])
    # The surface's size: its span, or its height (the heights drawn x2,
    # about twice the focal point's z) where that is larger (1 m cells).
    size = max(max(span), 2.0 * focal[2])
    off = math.hypot(focal[0] - centre[0], focal[1] - centre[1])
    distance = math.dist(focal, position)
    print("state %d: focal %s, %.0f m from the terrain's centre; camera %.0f m away; span %.0f m"
          % (k + 1, [round(v) for v in focal], off, distance, size))
    checks.append(off < 0.1 * size and 0.3 * size < distance < 5.0 * size)
print("%d passed, %d failed" % (sum(checks), len(checks) - sum(checks)))
sys.exit(0 if all(checks) else 1)
