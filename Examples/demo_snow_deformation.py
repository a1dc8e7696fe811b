"""Graupel demo, snow deformation (the README's first command runs it with
pvbatch after demo_terrain.py): a wheel rolls through 0.3 m of snow of
200 kg/m^3 along an S-shaped path over a 12.8 m patch of procedural terrain
(Snow Deformation, seed 000). Writes pictures at a third, two thirds and the
end of the crossing and one close up behind the wheel at the end, the snow at
the end as .vti, and prints the snow's ledger and the wheel's resistance.

    pvbatch Examples/demo_snow_deformation.py [--out out] [--cells 320] [--plugin .../Graupel.so]
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
p.add_argument("--cells", type=int, default=320)
p.add_argument("--plugin", default=os.path.join(
    here, "..", "build", "lib", "paraview-5.11", "plugins", "Graupel", "Graupel.so"))
args, _ = p.parse_known_args()
os.makedirs(args.out, exist_ok=True)

if "SnowDeformation" not in globals():
    LoadPlugin(os.path.abspath(args.plugin), ns=globals())
import snow_scene  # noqa: E402

# The same 12.8 m patch at any --cells: a coarser grid is a quicker check.
spacing = 0.04 * 319 / (args.cells - 1)
snow, times = snow_scene.build(cells=args.cells, spacing=spacing)
start = time.time()
snow.UpdatePipeline(times[-1])
fd = servermanager.Fetch(snow).GetFieldData()
wheel = servermanager.Fetch(snow, idx=1).GetFieldData()
value = lambda data, name: data.GetArray(name).GetValue(0)  # noqa: E731
print("snow deformation: %d x %d cells of %.1f cm, %d steps of %g s in %.1f s" % (
    args.cells, args.cells, 100 * spacing, value(fd, "steps"), snow.TimeStep,
    time.time() - start))
print("the snow after %.2f s: mass %.6g kg (balance error %.2g kg), %.3g m3 compressed, "
      "%.3g m3 pushed aside; the wheel's contact %.3g m2, resistance %.0f N" % (
          times[-1], value(fd, "snow_mass"), value(fd, "balance_error"),
          value(fd, "compressed_volume"), value(fd, "displaced_volume"),
          value(wheel, "contact_area"),
          sum(c * c for c in wheel.GetArray("force").GetTuple3(0)) ** 0.5))
SaveData(os.path.join(args.out, "snow_deformation.vti"), proxy=snow)

for k, t in enumerate(times, start=1):
    SetActiveView(None)
    view = CreateView("RenderView")
    SetActiveView(view)
    view = snow_scene.show(snow, t)
    SaveScreenshot(os.path.join(args.out, "snow_deformation_t%d.png" % k), view,
                   ImageResolution=[1024, 768])
    Delete(view)
# And close up behind the wheel at the end.
SetActiveView(None)
view = CreateView("RenderView")
SetActiveView(view)
view = snow_scene.show(snow, times[-1], close=True)
SaveScreenshot(os.path.join(args.out, "snow_deformation_close.png"), view,
               ImageResolution=[1024, 768])
print("wrote %s" % ", ".join(sorted(f for f in os.listdir(args.out) if f.startswith("snow_"))))
