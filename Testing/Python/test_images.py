"""pvbatch under xvfb-run: the terrain, warped by elevation and coloured,
compared with Testing/Baseline/terrain.png by VTK's image comparison.
Regenerate the baseline only on purpose (--generate-baseline), and look at it."""
import os
import shutil
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args()

from paraview.simple import *  # noqa: E402,F401,F403
from vtkmodules.vtkTestingRendering import vtkTesting  # noqa: E402

LoadPlugin(a.plugin, ns=globals())
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "Examples"))
import graupel_scene  # noqa: E402

terrain = ProceduralTerrain(Dimensions=[192, 192], Spacing=4.0, Seed=2026)
view = graupel_scene.show_terrain(terrain, size=(400, 300))
shot = os.path.join(a.scratch, "terrain.png")
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
