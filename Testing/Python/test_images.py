"""pvbatch under xvfb-run: a scene rendered and compared with its baseline in
Testing/Baseline/ by VTK's image comparison.
  --scene terrain  the procedural terrain, warped by elevation and coloured
  --scene rain     ten minutes of 100 mm/h on a procedural terrain (Rain
                   Runoff), warped by the water surface, coloured by depth
  --scene snow     a wheel rolled along an S through snow (Snow Deformation,
                   Examples/snow_scene.py on a 160 x 160 grid), seen whole
Regenerate a baseline only on purpose (--generate-baseline, or
GRAUPEL_GENERATE_BASELINE=1 in ctest's environment), and look at it."""
import os
import shutil
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args(lambda p: p.add_argument("--scene", choices=("terrain", "rain", "snow"),
                                    default="terrain"))

from paraview.simple import *  # noqa: E402,F401,F403
from vtkmodules.vtkTestingRendering import vtkTesting  # noqa: E402

LoadPlugin(a.plugin, ns=globals())
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "Examples"))
import graupel_scene  # noqa: E402

if a.scene == "terrain":
    terrain = ProceduralTerrain(Dimensions=[192, 192], Spacing=4.0, Seed=2026)
    view = graupel_scene.show_terrain(terrain, size=(400, 300))
elif a.scene == "snow":
    import snow_scene  # noqa: E402

    # The demo's 12.8 m patch at 8 cm, one cell per step.
    snow, times = snow_scene.build(cells=160, spacing=0.08, time_step=0.032, frames=1)
    snow.UpdatePipeline(times[-1])
    # What the picture claims: a trench down to the wheel's underside, rims
    # above the untouched snow, pressed snow denser, and the mass kept.
    from paraview import servermanager  # noqa: E402

    out = servermanager.Fetch(snow)
    depth = out.GetPointData().GetArray("snow_depth").GetRange()
    rho = out.GetPointData().GetArray("snow_density").GetRange()
    floor = snow_scene.DEPTH - snow_scene.SINK
    T.check(floor - 0.02 < depth[0] < floor + 0.02,
            "the trench floor %.3f m is the wheel's underside, %.3f m" % (depth[0], floor))
    T.check(depth[1] > snow_scene.DEPTH + 0.05, "rims %.3f m above the snow's %.2f m" % (
        depth[1], snow_scene.DEPTH))
    T.check(rho[0] == snow_scene.DENSITY and 300.0 < rho[1] <= 400.0,
            "densities %.1f..%.1f kg/m^3" % rho)
    fd = out.GetFieldData()
    mass = fd.GetArray("snow_mass").GetValue(0)
    T.check(abs(fd.GetArray("balance_error").GetValue(0)) < 1e-6 * mass, "snow mass kept")
    view = snow_scene.show(snow, times[-1], size=(400, 300), bar=False, label=False)
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
if a.generate_baseline or os.environ.get("GRAUPEL_GENERATE_BASELINE") == "1":
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
