"""Graupel demo (the README's first command runs it with pvbatch):

  * a procedural terrain (seed 001's inverted ridged multifractal) computed on
    OpenCL, rendered, and written as EXR and .vti;
  * the real DEM in Data/ (USGS, Jacksboro Fault, Tennessee) read from EXR and
    rendered the same way;
  * half an hour of violent rain (50 mm/h) on that DEM (Rain Runoff, seed
    004): the water gathering in its valleys, rendered, with the water ledger
    printed.

    pvbatch Examples/demo_terrain.py [--out out] [--size 512] [--plugin .../Graupel.so]
"""
import argparse
import os
import sys

from paraview import servermanager
from paraview.simple import *  # noqa: F401,F403

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, here)
import graupel_scene  # noqa: E402

p = argparse.ArgumentParser()
p.add_argument("--out", default="out")
p.add_argument("--size", type=int, default=512)
p.add_argument("--plugin", default=os.path.join(
    here, "..", "build", "lib", "paraview-5.11", "plugins", "Graupel", "Graupel.so"))
args, _ = p.parse_known_args()
os.makedirs(args.out, exist_ok=True)

if "ProceduralTerrain" not in globals():
    LoadPlugin(os.path.abspath(args.plugin), ns=globals())

# 1. Procedural terrain: 2 m spacing, 120 m relief.
terrain = ProceduralTerrain(Dimensions=[args.size, args.size], Spacing=2.0, Seed=2026)
terrain.UpdatePipeline()
lo, hi = terrain.PointData["elevation"].GetRange()
print("procedural terrain: %d x %d points, elevation %.1f..%.1f m" % (args.size, args.size, lo, hi))
SaveData(os.path.join(args.out, "terrain.exr"), proxy=terrain)
SaveData(os.path.join(args.out, "terrain.vti"), proxy=terrain)
view = graupel_scene.show_terrain(terrain)
SaveScreenshot(os.path.join(args.out, "terrain.png"), view, ImageResolution=[1024, 768])
Delete(view)

# 2. The real DEM: 3 arc-second cells (74.5 m east-west, 92.1 m north-south),
# a spacing the file holds, so the reader needs no property.
dem = OpenDataFile(os.path.join(here, "..", "Data", "jacksboro_fault_dem.exr"))
dem.UpdatePipeline()
lo, hi = dem.PointData["elevation"].GetRange()
print("Jacksboro Fault DEM: elevation %.0f..%.0f m" % (lo, hi))
SetActiveView(None)
view = CreateView("RenderView")
SetActiveView(view)
view = graupel_scene.show_terrain(dem, exaggeration=4.0)
SaveScreenshot(os.path.join(args.out, "jacksboro_dem.png"), view, ImageResolution=[1024, 768])

# 3. Rain on the DEM: 50 mm/h for 30 minutes on sealed ground; the water runs
# into the valleys and leaves through the open edge.
rain = RainRunoff(Input=dem, RainRate=50.0, EndTime=1800.0, OutputInterval=300.0,
                  MaxTimeStep=10.0)
rain.UpdatePipeline(1800.0)
fd = servermanager.Fetch(rain).GetFieldData()
ledger = {k: fd.GetArray(k).GetValue(0) for k in
          ("rain_volume", "outflow_volume", "stored_volume", "balance_error")}
print("rain on the DEM after 30 min: rain %.4g m3, outflow %.4g m3, stored %.4g m3, "
      "balance error %.2g m3; deepest water %.2f m" % (
          ledger["rain_volume"], ledger["outflow_volume"], ledger["stored_volume"],
          ledger["balance_error"], rain.PointData["water_depth"].GetRange()[1]))
SaveData(os.path.join(args.out, "rain_jacksboro.vti"), proxy=rain)
SetActiveView(None)
view = CreateView("RenderView")
SetActiveView(view)
view = graupel_scene.show_water(rain, 1800.0, exaggeration=4.0)
SaveScreenshot(os.path.join(args.out, "rain_jacksboro.png"), view, ImageResolution=[1024, 768])
print("wrote %s" % ", ".join(sorted(os.listdir(args.out))))
