"""Dragging a dock's separator after Apply in the ParaView GUI keeps the GUI
alive (Plugin/pqGraupelAbortStarter.cxx: events are processed during an
update only inside a Graupel algorithm's own update, never inside a
representation's update that a render on resize or the look starts).

Starts `paraview` on the test's Xvfb with the plugin, plays Sources > Graupel >
Procedural Terrain, Apply (QtTesting), and once the script has finished drags the separator between the
Properties dock and the render view with xdotool, right and back, several
times, as a user does. Checks: the separator moved (the strip right of its
old place turns from the render view's dark background to the panel's light
grey), paraview is still running after every drag, and it exits cleanly on
Ctrl+Q. Before the fix, every run of this test crashed within three drags
(SIGSEGV in QPropertyAnimation::updateState, from QMainWindow's separator
timer)."""
import os
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gr_gui import APPLY, PANEL, paraview, write_events  # noqa: E402

scratch = sys.argv[sys.argv.index("--scratch") + 1]
plugin_dir = sys.argv[sys.argv.index("--plugin-dir") + 1]
script = os.path.join(scratch, "gui_docks.xml")
log = os.path.join(scratch, "gui_docks.log")

apply_button, panel = APPLY, PANEL
# A grid large enough that the surface's representation takes several
# tenths of a second on any machine: progress is reported during it (the
# condition the crash needed; at 512 x 512 only on a loaded machine).
events = [
    ("pqClientMainWindow/menubar/menuSources/Graupel", "activate", "ProceduralTerrain"),
    (panel + "Dimensions/LineEdit0", "set_string", "1536"),
    (panel + "Dimensions/LineEdit1", "set_string", "1536"),
    (apply_button, "activate", ""),
    ("pqClientMainWindow", "process_events", "1000"),
]
write_events(script, events)


def xdotool(*args):
    subprocess.run(["xdotool"] + [str(a) for a in args], check=True)


def row(y):
    """The screen's row y as grey levels 0-255."""
    size = subprocess.run(["xdotool", "getdisplaygeometry"], check=True, capture_output=True,
                          text=True).stdout.split()
    width = int(size[0])
    gray = subprocess.run(["import", "-window", "root", "-depth", "8", "gray:-"], check=True,
                          capture_output=True).stdout
    return list(gray[y * width:(y + 1) * width])


def view_left(line):
    """x of the render view: the first run of 12 pixels of its background
    (ParaView's default, grey 88) right of the docks."""
    for x in range(200, min(len(line), 900) - 12):
        if all(abs(v - 88) <= 3 for v in line[x:x + 12]):
            return x
    return None


with open(log, "w") as out:
    proc = paraview(script, plugin_dir, exit=False, stdout=out, stderr=subprocess.STDOUT)
checks = []
try:
    deadline = time.time() + 180
    finished = False
    while time.time() < deadline and proc.poll() is None:
        if "is finished. Success =  true" in open(log, errors="replace").read():
            finished = True
            break
        time.sleep(0.5)
    print("script finished: %s" % finished)
    checks.append(finished)
    time.sleep(3)  # the look's surface and render
    y = 450
    line = row(y) if finished else []
    before = view_left(line)
    print("the render view's background starts at x = %s" % before)
    checks.append(before is not None)
    alive = []
    moved = None

    def drag(x0, x1):
        xdotool("mousemove", x0, y, "mousedown", 1)
        for i in range(1, 21):
            xdotool("mousemove", x0 + (x1 - x0) * i // 20, y)
            time.sleep(0.05)
        xdotool("mouseup", 1)
        time.sleep(2)
        alive.append(proc.poll() is None)
        return alive[-1]

    def changed(a, b):
        """Pixels of the strip right of the separator that changed."""
        return sum(abs(p - q) > 30 for p, q in zip(a[before:before + 200], b[before:before + 200]))

    if before is not None:
        # The separator lies a few pixels left of the view's frame (the dock's
        # border, then the frame): tried from there leftwards, on the dock's
        # light pixels only (a press inside the view would turn the camera).
        for offset in [d for d in range(5, 12) if line[before - d] > 150]:
            if not drag(before - offset, before - offset + 200):
                break
            after = row(y)
            if changed(line, after) > 30:
                moved = offset
                break
        if moved is not None:
            x0 = before - moved + 200
            for k in range(4):  # back, right, back, right
                step = -200 if k % 2 == 0 else 200
                if not drag(x0, x0 + step):
                    break
                x0 += step
        print("the separator at x = %s moved the view: %s; alive after each of %d drags: %s"
              % (before - moved if moved else None, moved is not None, len(alive), alive))
        checks.append(moved is not None)
        checks.append(len(alive) >= 5 and all(alive))
    if proc.poll() is None:
        xdotool("key", "--clearmodifiers", "ctrl+q")
        try:
            proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            pass
    print("paraview exit code %s" % proc.poll())
    checks.append(proc.poll() == 0)
finally:
    if proc.poll() is None:
        proc.kill()
        proc.wait()
if not all(checks):
    print(open(log, errors="replace").read()[-3000:])
print("%d passed, %d failed" % (sum(checks), len(checks) - sum(checks)))
sys.exit(0 if all(checks) else 1)
