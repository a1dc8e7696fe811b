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
with open(os.environ["GRAUPEL_GUI_RESULT"], "w") as f:
    f.write("found=%s points=%d\n" % (",".join(found), points))
