"""Rain Runoff's flood maps on the real DEM in Data/: 1 h of 50 mm/h on the
Jacksboro fault DEM (403 x 344 points, 74.5 x 92.1 m), then the largest depth
and the flood-hazard class (FD2321's h (v + 0.5) + DF) seen from above, and the
hydrograph (output port 1) as a line chart. About 11 s on PoCL on two cores.

    xvfb-run -a pvbatch Examples/flood_maps.py --out out

writes out/flood_max_depth.png, out/flood_hazard_class.png and
out/flood_hydrograph.png (the README shows the first two).
"""
import argparse
import os

from paraview.simple import *  # noqa: F401,F403

here = os.path.dirname(os.path.abspath(__file__))
p = argparse.ArgumentParser()
p.add_argument("--out", default="out")
p.add_argument("--hours", type=float, default=1.0)
p.add_argument("--plugin", default=os.path.join(
    here, "..", "build", "lib", "paraview-5.11", "plugins", "Graupel", "Graupel.so"))
args, _ = p.parse_known_args()
os.makedirs(args.out, exist_ok=True)
if "RainRunoff" not in globals():
    LoadPlugin(os.path.abspath(args.plugin), ns=globals())

end = 3600.0 * args.hours
# The DEM's spacing (74.5 x 92.1 m) and origin are in the file.
dem = OpenDataFile(os.path.join(here, "..", "Data", "jacksboro_fault_dem.exr"))
rain = RainRunoff(Input=dem, RainRate=50.0, EndTime=end, OutputInterval=300.0, MaxTimeStep=10.0)
rain.UpdatePipeline(end)
for m in ("max_depth", "max_speed", "arrival_time", "hazard_class"):
    print(m, rain.PointData[m].GetRange())

# The maps from above: depth on a sequential blue map (dry ground white), the
# hazard classes as categories with their names; legends with units.
for name, arr, title, rng, preset in (
        ("flood_max_depth", "max_depth", "largest depth (m)", [0.0, 2.0], "Blues"),
        ("flood_hazard_class", "hazard_class", "flood hazard (FD2321)", None, None)):
    view = CreateView("RenderView")
    view.ViewTime = end
    view.OrientationAxesVisibility = 0
    view.ViewSize = [900, 1000]
    d = Show(rain, view)
    ColorBy(d, ("POINTS", arr))
    lut = GetColorTransferFunction(arr)
    if preset:
        lut.ApplyPreset(preset, True)
        lut.InvertTransferFunction()  # dry ground near white, deep water dark blue
        lut.RescaleTransferFunction(*rng)
    else:
        lut.InterpretValuesAsCategories = 1
        lut.Annotations = ["0", "low", "1", "moderate", "2", "significant", "3", "extreme"]
        lut.IndexedColors = [0.85, 0.9, 0.85, 1.0, 0.85, 0.2, 1.0, 0.5, 0.0, 0.8, 0.0, 0.0]
    d.SetScalarBarVisibility(view, True)
    bar = GetScalarBar(lut, view)
    bar.Title = title
    bar.ComponentTitle = ""
    view.ResetCamera()
    f = view.CameraFocalPoint
    view.CameraPosition = [f[0], f[1], f[2] + 1e5]
    view.CameraViewUp = [0, 1, 0]
    view.ResetCamera()
    SaveScreenshot(os.path.join(args.out, name + ".png"), view, ImageResolution=[900, 1000])
    Delete(view)

chart = CreateView("XYChartView")
chart.ViewTime = end
c = Show(OutputPort(rain, 1), chart)
c.SeriesVisibility = ["rain_volume_rate", "outflow_rate", "infiltration_rate"]
chart.LeftAxisTitle = "m^3/s"
chart.BottomAxisTitle = "time (s)"
# The chart at the picture's own size, so its fonts are not scaled up, with
# the legend between the rain's line and the outflow's.
chart.ViewSize = [900, 500]
chart.LegendLocation = "Custom"
chart.LegendPosition = [730, 230]
for prop in ("LeftAxisTitleFontSize", "BottomAxisTitleFontSize"):
    setattr(chart, prop, 16)
for prop in ("LeftAxisLabelFontSize", "BottomAxisLabelFontSize", "LegendFontSize"):
    setattr(chart, prop, 13)
SaveScreenshot(os.path.join(args.out, "flood_hydrograph.png"), chart, ImageResolution=[900, 500])
print("wrote", sorted(os.listdir(args.out)))
