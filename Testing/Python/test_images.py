"""pvbatch under xvfb-run: a scene rendered and compared with its baseline in
Testing/Baseline/ by VTK's image comparison.
  --scene terrain  the procedural terrain, warped by elevation and coloured
  --scene rain     ten minutes of 100 mm/h on a procedural terrain (Rain
                   Runoff), warped by the water surface, coloured by depth
Regenerate a baseline only on purpose (--generate-baseline), and look at it."""
import os
import shutil
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args(lambda p: p.add_argument("--scene", choices=("terrain", "rain"), default="terrain"))

from paraview.simple import *  # noqa: E402,F401,F403
from vtkmodules.vtkTestingRendering import vtkTesting  # noqa: E402

LoadPlugin(a.plugin, ns=globals())
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "Examples"))
import graupel_scene  # noqa: E402

if a.scene == "terrain":
    terrain = ProceduralTerrain(Dimensions=[192, 192], Spacing=4.0, Seed=2026)
    view = graupel_scene.show_terrain(terrain, size=(400, 300))
else:
    terrain = ProceduralTerrain(Dimensions=[128, 128], Spacing=4.0, Seed=2026, HeightScale=40.0)
    rain = RainRunoff(Input=terrain, RainRate=100.0, EndTime=600.0, OutputInterval=600.0,
                      MaxTimeStep=2.0)
    rain.UpdatePipeline(600.0)
    view = graupel_scene.show_water(rain, 600.0, size=(400, 300), deep=0.5)
shot = os.path.join(a.scratch, a.scene + ".png")
SaveScreenshot(shot, view, ImageResolution=[400, 300])

# The threshold is VTK's image difference (summed per-pixel error after its
# tolerance for shifted pixels); 10 is VTK's usual default for its own tests.
THRESHOLD = 10.0
if a.generate_baseline:
    shutil.copyfile(shot, a.baseline)
    print("baseline written to %s: look at it before committing" % a.baseline)
else:
    testing = vtkTesting()
    testing.AddArgument("-T")
    testing.AddArgument(a.scratch)
    testing.AddArgument("-V")
    testing.AddArgument(a.baseline)
    result = testing.RegressionTest(shot, THRESHOLD)
    T.check(result == vtkTesting.PASSED, "image matches %s (threshold %g)" % (a.baseline, THRESHOLD))
T.finish()
