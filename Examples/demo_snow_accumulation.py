"""Graupel demo, snow accumulation (the README's first command runs it with
pvbatch after demo_snow_deformation.py): a hut with a porch and four trees
on a 14.35 m patch of procedural terrain under 4 h of 8 cm/h snow driven by
a west wind 30 degrees off vertical (Snow Accumulation, seed 002), then a
sledge pulled across the fresh snow (Snow Deformation on the accumulation's
output as it is). Writes the snowfall (out/snow_accumulation.png: snow depth,
the lee-side shadows, the bare ground under the porch, the snow caps), the
sledge's trail (snow_accumulation_sledge.png), the accumulated snow as .vti,
and prints both ledgers.

    pvbatch Examples/demo_snow_accumulation.py [--out out] [--cells 288] [--plugin .../Graupel.so]
"""
import argparse
import os
import sys
import time

from paraview import servermanager
from paraview.simple import *  # noqa: F401,F403

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, here)

p = argparse.ArgumentParser()
p.add_argument("--out", default="out")
p.add_argument("--cells", type=int, default=288)
p.add_argument("--plugin", default=os.path.join(
    here, "..", "build", "lib", "paraview-5.11", "plugins", "Graupel", "Graupel.so"))
args, _ = p.parse_known_args()
os.makedirs(args.out, exist_ok=True)

if "SnowAccumulation" not in globals():
    LoadPlugin(os.path.abspath(args.plugin), ns=globals())
import snow_scene  # noqa: E402

# The same 14.35 m patch at any --cells: a coarser grid is a quicker check.
spacing = 0.05 * 287 / (args.cells - 1)
start = time.time()
acc, sledge, crossing, _ = snow_scene.build_accumulation(cells=args.cells, spacing=spacing)
fd = servermanager.Fetch(acc).GetFieldData()
value = lambda data, name: data.GetArray(name).GetValue(0)  # noqa: E731
print("snow accumulation: %d x %d cells of %.1f cm, %d steps of %g s in %.1f s" % (
    args.cells, args.cells, 100 * spacing, value(fd, "steps"), acc.TimeStep,
    time.time() - start))
print("after %g h: %.4g m3 fell, %.4g m3 stored (%.4g on the ground, %.4g on the objects), "
      "%.4g m3 shed, balance error %.2g m3" % (
          value(fd, "time") / 3600.0, value(fd, "snowfall_volume"), value(fd, "stored_volume"),
          value(fd, "stored_volume_terrain"), value(fd, "stored_volume_objects"),
          value(fd, "shed_volume"), value(fd, "balance_error")))
start = time.time()
sledge.UpdatePipeline(crossing)
sd = servermanager.Fetch(sledge).GetFieldData()
print("the sledge: %d steps of %g s in %.1f s; snow mass %.6g kg (from %.6g kg, balance error "
      "%.2g kg), %.3g m3 compressed, %.3g m3 pushed aside" % (
          value(sd, "steps"), sledge.TimeStep, time.time() - start, value(sd, "snow_mass"),
          value(sd, "initial_mass"), value(sd, "balance_error"), value(sd, "compressed_volume"),
          value(sd, "displaced_volume")))
end = acc.EndTime
SaveData(os.path.join(args.out, "snow_accumulation.vti"),
         proxy=ForceTime(Input=acc, IgnorePipelineTime=1, ForcedTime=end))

view = snow_scene.show_accumulation(acc, end)
SaveScreenshot(os.path.join(args.out, "snow_accumulation.png"), view, ImageResolution=[1024, 768])
Delete(view)
SetActiveView(None)
view = CreateView("RenderView")
SetActiveView(view)
view = snow_scene.show_accumulation(acc, end, sledge, crossing)
SaveScreenshot(os.path.join(args.out, "snow_accumulation_sledge.png"), view,
               ImageResolution=[1024, 768])
print("wrote %s" % ", ".join(sorted(f for f in os.listdir(args.out)
                                    if f.startswith("snow_accumulation"))))
