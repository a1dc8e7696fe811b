"""pvbatch: the plugin loads, every proxy is declared as documented (menu,
defaults, reader and writer found by extension) and runs."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args()

from paraview import servermanager  # noqa: E402
from paraview.simple import *  # noqa: E402,F401,F403

LoadPlugin(a.plugin, ns=globals())
pxm = servermanager.ProxyManager()

# Declarations: menu category, documentation on every property.
for group, name in (("sources", "ProceduralTerrain"), ("sources", "EXRHeightFieldReader"),
                    ("writers", "EXRFieldWriter"), ("filters", "RainRunoff")):
    proto = pxm.GetPrototypeProxy(group, name)
    T.check(proto is not None, "proxy %s/%s is registered" % (group, name))
    if proto is None:
        continue
    it = proto.NewPropertyIterator()
    it.Begin()
    while not it.IsAtEnd():
        prop = it.GetProperty()
        if not prop.GetInformationOnly() and prop.GetPanelVisibility() != "never":
            doc = prop.GetDocumentation()
            T.check(doc is not None and len(doc.GetDescription().strip()) > 10,
                    "%s.%s has documentation" % (name, it.GetKey()))
        it.Next()
    if group in ("sources", "filters"):
        hints = proto.GetHints()
        menu = hints.FindNestedElementByName("ShowInMenu") if hints else None
        T.check(menu is not None and menu.GetAttribute("category") == "Graupel",
                "%s is in the Graupel menu" % name)

# Device and the Time group are declared once (Plugin/GraupelBase.xml) and
# inherited: every proxy that runs kernels has Device in its Compute group,
# every simulation EndTime/OutputInterval/TimestepValues in "Time (s)"; the
# bases themselves are in no menu and not in paraview.simple.
def groups_of(proto):
    out = {}
    for i in range(proto.GetNumberOfPropertyGroups()):
        g = proto.GetPropertyGroup(i)
        names = [proto.GetPropertyName(g.GetProperty(k)) for k in range(g.GetNumberOfProperties())]
        out.setdefault(g.GetXMLLabel(), []).extend(names)
    return out


for group, name, simulation in (("sources", "ProceduralTerrain", False),
                                ("filters", "RainRunoff", True)):
    proto = pxm.GetPrototypeProxy(group, name)
    groups = groups_of(proto)
    T.check(proto.GetProperty("Device") is not None and "Device" in groups.get("Compute", []),
            "%s inherits Device in the Compute group: %r" % (name, groups))
    if simulation:
        T.check(all(proto.GetProperty(p) is not None
                    for p in ("EndTime", "OutputInterval", "TimestepValues")),
                "%s inherits the time properties" % name)
        T.check(set(groups.get("Time (s)", [])) >= {"EndTime", "OutputInterval"},
                "%s has EndTime and OutputInterval in 'Time (s)': %r" % (name, groups))
T.check(pxm.GetPrototypeProxy("graupel_bases", "GraupelSimulation") is not None,
        "the base GraupelSimulation is registered")
T.check(not any(n.startswith("Graupel") for n in dir(servermanager.sources)) and
        not any(n.startswith("Graupel") for n in dir(servermanager.filters)),
        "the bases are not sources or filters")

# The terrain with its documented defaults.
t = ProceduralTerrain()
T.check(list(t.Dimensions) == [512, 512], "Dimensions default")
T.check(t.Spacing[0] == 2.0 if hasattr(t.Spacing, "__len__") else t.Spacing == 2.0, "Spacing default")
T.check(t.NoiseType == "Ridged Multifractal", "NoiseType default %r" % t.NoiseType)
T.check(t.Octaves == 6 and t.Lacunarity == 2.0 and t.Persistence == 0.5, "octave defaults")
T.check(t.Offset == 1.0 and t.Gain == 2.0 and t.HeightScale == 120.0, "ridged defaults")
t.UpdatePipeline()
info = t.GetDataInformation()
T.check(info.GetNumberOfPoints() == 512 * 512, "512 x 512 points")
lo, hi = t.PointData["elevation"].GetRange()
T.check(0.0 <= lo and hi <= 120.0 and hi - lo > 30.0, "elevation range %g..%g" % (lo, hi))
T.check(tuple(info.GetBounds()) == (0.0, 1022.0, 0.0, 1022.0, 0.0, 0.0), "bounds %s" % (info.GetBounds(),))

# Same seed, same data; another seed, other data (fetched to the client).
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402

t.Dimensions = [128, 96]
t.Seed = 7
e1 = vtk_to_numpy(servermanager.Fetch(t).GetPointData().GetArray("elevation")).copy()
t.Seed = 8
e2 = vtk_to_numpy(servermanager.Fetch(t).GetPointData().GetArray("elevation")).copy()
t.Seed = 7
e3 = vtk_to_numpy(servermanager.Fetch(t).GetPointData().GetArray("elevation")).copy()
T.check((e1 == e3).all(), "Seed 7 twice gives the same field")
T.check(not (e1 == e2).all(), "Seed 8 differs from Seed 7")
t.NoiseType = "fBm"
e4 = vtk_to_numpy(servermanager.Fetch(t).GetPointData().GetArray("elevation")).copy()
T.check(not (e4 == e1).all(), "NoiseType changes the field")

# Reader and writer are found by extension.
path = os.path.join(a.scratch, "proxies.exr")
SaveData(path, proxy=t)
with open(path, "rb") as f:
    T.check(f.read(4) == b"\x76\x2f\x31\x01", "SaveData('.exr') wrote an EXR")
r = OpenDataFile(path)
T.check(r is not None and r.GetXMLName() == "EXRHeightFieldReader",
        "OpenDataFile('.exr') picks the EXR reader (%s)" % (r and r.GetXMLName()))
r.Spacing = [2.0, 2.0]
r.UpdatePipeline()
T.check(r.GetDataInformation().GetNumberOfPoints() == 128 * 96, "reader output size")
T.check(r.PointData["elevation"].GetRange() == t.PointData["elevation"].GetRange(),
        "reader range equals source range")

# File > Open on the real DEM, no property set: its spacing and origin come
# from the file (3 arc-seconds, 74.5 m east-west and 92.1 m north-south, the
# south-west point at 0 0), so it opens at its real size, 30 x 31.6 km.
dem = OpenDataFile(os.path.join(a.data, "jacksboro_fault_dem.exr"))
dem.UpdatePipeline()
T.check(dem.PointData["elevation"].GetRange() == (236.0, 1076.0), "real DEM range")
b = dem.GetDataInformation().GetBounds()
T.check(max(abs(x - y) for x, y in zip(b, (0.0, 402 * 74.5, 0.0, 343 * 92.1, 0.0, 0.0))) < 1e-6,
        "the real DEM opens at its real size: bounds %s" % (b,))

# Rain Runoff on the DEM: a time source whose times the animation scene sees.
rr = RainRunoff(Input=dem)
T.check(rr.RainRate == 100.0 and rr.Permeability == 0.0 and rr.ManningN == 0.03
        and rr.BoundaryWest == "Open" and rr.BoundaryNorth == "Open" and rr.LevelEast == 0.0
        and rr.EndTime == 600.0 and rr.OutputInterval == 10.0, "Rain Runoff defaults")
rr.RainRate = 10.0  # the rain the volume below is written for
rr.EndTime = 40.0
rr.OutputInterval = 20.0
rr.UpdatePipelineInformation()
T.check(list(rr.TimestepValues) == [0.0, 20.0, 40.0], "TimestepValues %r" % (list(rr.TimestepValues),))
scene = GetAnimationScene()
scene.UpdateAnimationUsingDataTimeSteps()
T.check(40.0 in list(scene.TimeKeeper.TimestepValues), "the time keeper knows the output times")
rr.UpdatePipeline(40.0)
out = servermanager.Fetch(rr)
fd = out.GetFieldData()
rain_in = fd.GetArray("rain_volume").GetValue(0)
T.near(rain_in, 10.0 / 3.6e6 * 40.0 * (74.5 * 92.1) * out.GetNumberOfPoints(), 1e-6 * rain_in,
       "rain_volume on the DEM")
T.check(abs(fd.GetArray("balance_error").GetValue(0)) <= 1e-5 * rain_in, "DEM water balance")
T.check(rr.PointData["water_depth"].GetRange()[1] > 0.0, "water on the DEM")

T.finish()
