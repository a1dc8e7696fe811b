"""Run by the ParaView GUI (paraview --script=... --exit) with PV_PLUGIN_PATH
pointing at the plugin: records whether the GUI session loaded Graupel's
proxies and could run the terrain. Written for check_gui_plugin.py."""
import os

from paraview import servermanager
from paraview.simple import *  # noqa: F401,F403

pxm = servermanager.ProxyManager()
names = ["ProceduralTerrain", "EXRHeightFieldReader"]
found = [n for n in names if pxm.GetPrototypeProxy("sources", n) is not None]
points = 0
if "ProceduralTerrain" in found:
    t = ProceduralTerrain(Dimensions=[32, 24])
    Show(t)
    Render()
    points = t.GetDataInformation().GetNumberOfPoints()
# The abort button (ParaView 5.11 with the plugin's GraupelGui): with
# GRAUPEL_GUI_TEST_ABORT_MS set, GraupelGui clicks it that long after the
# simulation's first progress, inside this Render. The un-aborted update
# takes tens of seconds here; an abort returns at once with an empty output
# and no second run of the simulation inside the same Render.
abort = ""
if os.environ.get("GRAUPEL_GUI_TEST_ABORT_MS") and "ProceduralTerrain" in found:
    import time
    from vtkmodules.vtkCommonExecutionModel import vtkAlgorithm

    big = ProceduralTerrain(Dimensions=[512, 512], Spacing=2.0, Seed=3)
    rain = RainRunoff(Input=big, RainRate=50.0, EndTime=3600.0, OutputInterval=1800.0)
    Show(rain)
    scene = GetAnimationScene()
    scene.UpdateAnimationUsingDataTimeSteps()
    Render()
    alg = rain.GetClientSideObject()
    start = time.time()
    scene.AnimationTime = 1800.0
    Render()
    end = time.time()
    out = alg.GetOutputDataObject(0)
    abort = "aborted=%d points=%d restarts=%d start=%.3f end=%.3f" % (
        alg.GetOutputInformation(0).Get(vtkAlgorithm.ABORTED()) or 0,
        out.GetNumberOfPoints(), alg.GetRestartCount(), start, end)
with open(os.environ["GRAUPEL_GUI_RESULT"], "w") as f:
    f.write("found=%s points=%d\n%s\n" % (",".join(found), points, abort))
