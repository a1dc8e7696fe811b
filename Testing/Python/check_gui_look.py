"""The look on Apply in the ParaView GUI with objects, a failed first Apply and
the hydrograph (Plugin/pqGraupelApplyLook.h), played through the menus and
the panel by QtTesting as a user does:

  Sphere (a 0.5 m ball at 2, 2, 0.9), Apply; Wavelet, Apply; Procedural
  Terrain (81 x 81 points of 5 cm, heights up to 0.3 m), Apply;
  Filters > Graupel > Snow Deformation, Objects: Sphere1 picked in the
  panel's list, Apply;
  Wavelet1 selected, Filters > Graupel > Rain Runoff, Apply (refused: the
  Wavelet has no elevation); Edit > Change Input: ProceduralTerrain1, Rain
  Rate -5 mm/h (out of range), Apply;
  the Hydrograph shown in a new line chart from the Python shell;
  File > Save State.

Then checks the saved state:
  * the objects were attached from the panel (Snow Deformation's Objects is
    Sphere1), the ball is shown at its pose (output port Objects, visible, in
    a colour that is not the snow's white) and the Sphere source is hidden;
    the snow's surface has no vertical exaggeration;
  * Rain Runoff, refused on its first Apply, got the look on the first update
    that worked: a Terrain Surface coloured by water depth with a legend that
    states the exaggeration ("heights x2"), range labels as plain numbers, the
    hidden image's representation named as what is drawn (Surface), and one
    time annotation in the view (Snow Deformation added it; not a second);
  * the rain rate out of range was said once, in one sentence, and the panel
    shows the value used (0);
  * the Hydrograph shown in a line chart (made in the Python shell) has the
    discharge series shown, the volumes hidden and on the right axis, and the
    axes titled in units."""
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gr_gui import APPLY, PANEL, play_to_state, setup, write_events  # noqa: E402

scratch, plugin_dir, state, script = setup("gui_look")

chart_script = os.path.join(scratch, "gui_look_chart.py")
with open(chart_script, "w") as f:
    f.write("from paraview.simple import *\n"
            "rain = FindSource('RainRunoff1')\n"
            "chart = CreateView('XYChartView')\n"
            "AssignViewToLayout(chart)\n"
            "Show(OutputPort(rain, 1), chart)\n"
            "Render(chart)\n")

apply_button, panel = APPLY, PANEL
browser = "pqClientMainWindow/pipelineBrowserDock/pipelineBrowser"
change = "pqClientMainWindow/ChangeInputDialog/pipelineView"
events = [
    ("pqClientMainWindow/menubar/menuSources/Alphabetical", "activate", "SphereSource"),
    (panel + "Center/DoubleLineEdit0", "set_string", "2"),
    (panel + "Center/DoubleLineEdit1", "set_string", "2"),
    (panel + "Center/DoubleLineEdit2", "set_string", "0.9"),
    (panel + "Radius/DoubleLineEdit0", "set_string", "0.5"),
    (apply_button, "activate", ""),
    ("pqClientMainWindow/menubar/menuSources/Alphabetical", "activate", "RTAnalyticSource"),
    (apply_button, "activate", ""),
    ("pqClientMainWindow/menubar/menuSources/Graupel", "activate", "ProceduralTerrain"),
    (panel + "Dimensions/LineEdit0", "set_string", "81"),
    (panel + "Dimensions/LineEdit1", "set_string", "81"),
    (panel + "Spacing/DoubleLineEdit0", "set_string", "0.05"),
    (panel + "HeightScale/DoubleRangeWidget/DoubleLineEdit", "set_string", "0.3"),
    (apply_button, "activate", ""),
    ("pqClientMainWindow", "process_events", "1000"),
    ("pqClientMainWindow/menubar/menuFilters/Graupel", "activate", "SnowDeformation"),
    (panel + "Objects/1QComboBox0", "activated", "Sphere1"),
    (apply_button, "activate", ""),
    ("pqClientMainWindow", "process_events", "1000"),
    # The top-level rows: Sphere1, Wavelet1, ProceduralTerrain1.
    (browser, "mousePress", "1,1,0,40,8,/0:0/1:0"),
    (browser, "mouseRelease", "1,0,0,40,8,/0:0/1:0"),
    ("pqClientMainWindow/menubar/menuFilters/Graupel", "activate", "RainRunoff"),
    (apply_button, "activate", ""),
    ("pqClientMainWindow", "process_events", "1000"),
    ("pqClientMainWindow/menubar/menu_Edit", "activate", "actionChangeInput"),
    (change, "mousePress", "1,1,0,40,8,/0:0/2:0"),
    (change, "mouseRelease", "1,0,0,40,8,/0:0/2:0"),
    ("pqClientMainWindow/ChangeInputDialog/buttonBox/1QPushButton0", "activate", ""),
    # Out of range (0-3600 mm/h): the filter warns once and uses 0.
    (panel + "RainRate/DoubleRangeWidget/DoubleLineEdit", "set_string", "-5"),
    (apply_button, "activate", ""),
    ("pqClientMainWindow", "process_events", "2000"),
    # A line chart of the Hydrograph, made as the Python shell makes it.
    ("pqClientMainWindow/menubar", "activate", "menu_View"),
    ("pqClientMainWindow/menubar/menu_View", "activate", "Python Shell"),
    ("pqClientMainWindow/pythonShellDock/pythonShell/runScriptButton", "activate", ""),
    ("pqClientMainWindow/pythonShellDock/pythonShell/PythonShellRunScriptDialog", "filesSelected",
     chart_script),
    ("pqClientMainWindow", "process_events", "1000"),
    ("pqClientMainWindow/menubar/menu_File", "activate", "actionFileSaveServerState"),
    ("pqClientMainWindow/FileSaveServerStateDialog", "filesSelected", state),
]
write_events(script, events)
proc, S = play_to_state(script, plugin_dir, state, stdout=subprocess.PIPE,
                        stderr=subprocess.STDOUT, text=True)
names, proxies, prop, by_type, bar_for = S.names, S.proxies, S.prop, S.by_type, S.bar_for


def reprs(source_id, port="0"):
    """The representations of `source_id`'s port (render view or chart)."""
    return [p for p in proxies.values()
            if p.get("group") == "representations" and prop(p, "Input")[1] == [(source_id, port)]
            and (prop(p, "Representation")[0] or p.get("type") == "XYChartRepresentation")]


def pairs(values):
    return dict(zip(values[0::2], values[1::2]))


checks = []


def check(ok, what):
    print("%s: %s" % ("ok" if ok else "FAILED", what))
    checks.append(bool(ok))


sphere, snow, rain = by_type("SphereSource"), by_type("SnowDeformation"), by_type("RainRunoff")
terrain = by_type("ProceduralTerrain")
surfaces = by_type("TerrainSurface")
print("sources: %s" % sorted(names.values()))
check(len(sphere) == 1 and len(snow) == 1 and len(rain) == 1 and len(terrain) == 1,
      "one each of Sphere, Snow Deformation, Rain Runoff, Procedural Terrain")
if not all(checks):
    sys.exit(1)
sphere, snow, rain, terrain = sphere[0], snow[0], rain[0], terrain[0]

# 3: the objects attached from the panel.
check(prop(proxies[snow], "Objects")[1] == [(sphere, "0")], "Snow Deformation's Objects is Sphere1")
# 4: the ball at its pose, the source hidden, heights drawn true.
balls = reprs(snow, "1")
sphere_shown = [prop(r, "Visibility")[0] for r in reprs(sphere)]
check(len(balls) == 1 and prop(balls[0], "Visibility")[0] == ["1"],
      "the objects' port shown (%s)" % [prop(r, "Visibility")[0] for r in balls])
color = [float(v) for v in prop(balls[0], "DiffuseColor")[0]] if balls else []
check(len(color) == 3 and min(color) < 0.5, "the objects drawn in a colour, not white: %s" % color)
check(sphere_shown and all(v == ["0"] for v in sphere_shown), "the Sphere source hidden: %s"
      % sphere_shown)
below = {s: prop(proxies[s], "Input")[1][0][0] for s in surfaces}
snow_surface = [s for s, src in below.items() if src == snow]
rain_surface = [s for s, src in below.items() if src == rain]
check(len(snow_surface) == 1 and
      prop(proxies[snow_surface[0]], "VerticalExaggeration")[0] == ["1"],
      "the snow's surface drawn without exaggeration")


# 8: Rain Runoff refused first, then the look on the first update that worked.
check(prop(proxies[rain], "Input")[1] == [(terrain, "0")], "Rain Runoff's input changed to the terrain")
shown = reprs(rain_surface[0]) if len(rain_surface) == 1 else []
check(len(shown) == 1 and prop(shown[0], "Visibility")[0] == ["1"]
      and prop(shown[0], "ColorArrayName")[0][-1:] == ["water_depth_display"],
      "Rain Runoff's surface shown, coloured by water depth")
bar = bar_for(shown[0]) if shown else None
title = prop(bar, "Title")[0] if bar is not None else []
check(title == ["water depth (m), heights \u00d72"], "its legend %r states the exaggeration" % title)
check(bar is not None and prop(bar, "RangeLabelFormat")[0] == ["%.4g"], "plain range labels")
check(bar is not None and prop(bar, "Visibility")[0] == ["1"], "its legend visible")
image = reprs(rain)
check(len(image) == 1 and prop(image[0], "Representation")[0] == ["Surface"],
      "the hidden image's representation says Surface, not Slice")
# The simulated time in the view, once.
clocks = by_type("TimeToTextConvertorSource")
shown_clock = [p for p in proxies.values() if p.get("group") == "representations"
               and clocks and prop(p, "Input")[1] == [(clocks[0], "0")]
               and prop(p, "Visibility")[0] == ["1"]]
check(len(clocks) == 1 and len(shown_clock) >= 1,
      "one time annotation shown (%d)" % len(clocks))

# 5: a value out of range said once, and the panel shows the value used.
warning = ("Rain Runoff: RainRate must be from 0 to 3600 mm/h; it was set to -5 mm/h, so 0 mm/h "
           "is used.")
check(proc.stdout.count(warning) == 1, "the warning said once (%d times)" % proc.stdout.count(warning))
check(prop(proxies[rain], "RainRate")[0] == ["0"],
      "the panel's RainRate is the value used: %s" % prop(proxies[rain], "RainRate")[0])

# 9: the hydrograph in a line chart, discharge only, volumes on the right.
charts = [r for r in reprs(rain, "1") if r.get("type") == "XYChartRepresentation"]
check(len(charts) == 1, "the Hydrograph in a line chart")
if charts:
    vis = pairs(prop(charts[0], "SeriesVisibility")[0])
    corner = pairs(prop(charts[0], "SeriesPlotCorner")[0])
    print("  series shown: %s" % vis)
    check(all(vis.get(c) == "1" for c in ("rain_volume_rate", "inflow_rate", "infiltration_rate",
                                          "outflow_rate")), "the discharge series shown")
    check(all(vis.get(c) == "0" for c in ("stored_volume", "outflow_volume", "balance_error",
                                          "time")), "the volumes and time hidden")
    check(all(corner.get(c) == "1" for c in ("stored_volume", "outflow_volume")),
          "the volumes on the right axis")
    view = [p for p in proxies.values() if p.get("type") == "XYChartView"
            and charts[0].get("id") in [d[0] for d in prop(p, "Representations")[1]]]
    titles = [prop(view[0], t)[0] for t in ("LeftAxisTitle", "BottomAxisTitle")] if view else []
    check(titles == [["discharge (m\u00b3/s)"], ["time (s)"]], "axis titles %s" % titles)
ok = all(checks)
print("%d passed, %d failed" % (sum(checks), len(checks) - sum(checks)))
sys.exit(0 if ok else 1)
