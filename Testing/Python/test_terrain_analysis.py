"""vtkTerrainAnalysisFilter and vtkTerrainShadowFilter in a pipeline
(pvpython in the plugin build, plain python3 on Debian's VTK): a tilted
plane's slope, aspect, normal and hillshade against their formulas, the
cover classes either side of RockSlope and below WaterLevel, another height
array (snow_surface) chosen, the input's arrays passed through, a spike's
shadow h / tan E long and nowhere else, the soft edge, ModelShadows, the
clamps, bad input (a missing height array, NaN heights, a 3-D image: one
sentence, an empty output, and the next good update works), and under
pvpython the two proxies: units in their documentation, the shared sun
properties alike, the surface representation, a run on Procedural
Terrain."""
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args()

from vtkmodules.util.numpy_support import vtk_to_numpy, numpy_to_vtk  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkDataObject, vtkImageData  # noqa: E402
from vtkmodules.vtkCommonExecutionModel import vtkTrivialProducer  # noqa: E402

from graupel import vtkTerrainAnalysisFilter, vtkTerrainShadowFilter  # noqa: E402

NX, NY, DX, DY = 40, 30, 2.0, 1.5
_keep = []  # a vtkAlgorithmOutput does not keep its producer alive
RAD = math.pi / 180.0


def producer(data):
    p = vtkTrivialProducer()
    p.SetOutput(data)
    _keep.append(p)
    return p.GetOutputPort()


def image(arrays, nx=NX, ny=NY, dx=DX, dy=DY, nz=1):
    img = vtkImageData()
    img.SetDimensions(nx, ny, nz)
    img.SetSpacing(dx, dy, 1.0)
    img.SetOrigin(100.0, -50.0, 0.0)
    for name, values in arrays.items():
        arr = numpy_to_vtk(np.ascontiguousarray(values, dtype=np.float32).reshape(-1), deep=1)
        arr.SetName(name)
        img.GetPointData().AddArray(arr)
    return img


j, i = np.mgrid[0:NY, 0:NX]
X, Y = i * DX, j * DY


def tilted(slope, aspect, c=0.0):
    """A plane of slope degrees falling towards the bearing aspect."""
    m = math.tan(slope * RAD)
    return -m * math.sin(aspect * RAD) * X - m * math.cos(aspect * RAD) * Y + c


def arr(data, name, comps=1):
    a_ = data.GetPointData().GetArray(name)
    if a_ is None:
        return None
    v = vtk_to_numpy(a_).copy()
    nx, ny, _ = data.GetDimensions()
    return v.reshape(ny, nx, comps) if comps > 1 else v.reshape(ny, nx)


def analyse(img, cls=vtkTerrainAnalysisFilter, **kw):
    f = cls()
    f.SetInputConnection(producer(img))
    for k, v in kw.items():
        getattr(f, "Set" + k)(v)
    f.Update()
    return f, f.GetOutput()


# ---- defaults and clamps (the core's table) ---------------------------------------
f = vtkTerrainAnalysisFilter()
T.check((f.GetSunAzimuth(), f.GetSunElevation(), f.GetPenumbraWidth()) == (315.0, 45.0, 0.0),
        "sun defaults")
T.check((f.GetSnowExponent(), f.GetSnowCoverLimit(), f.GetRockSlope(), f.GetWaterLevel(),
         f.GetCoverMode(), f.GetModelShadows()) == (4.0, 0.5, 45.0, 0.0, 0, False),
        "cover defaults")
f.SetSunElevation(120.0)
f.SetRockSlope(-3.0)
f.SetCoverMode(5)
T.check((f.GetSunElevation(), f.GetRockSlope(), f.GetCoverMode()) == (90.0, 0.0, 1),
        "setters clamp to the table: %r" % ((f.GetSunElevation(), f.GetRockSlope(), f.GetCoverMode()),))

# ---- a tilted plane: slope, aspect, normal, hillshade -----------------------------
S, ASP, AZ, EL = 30.0, 120.0, 250.0, 35.0
h = tilted(S, ASP, 200.0)
extra = np.arange(NX * NY, dtype=np.float32)
f, out = analyse(image({"elevation": h, "extra": extra}), SunAzimuth=AZ, SunElevation=EL,
                 WaterLevel=-1e4)
T.check(out.GetDimensions() == (NX, NY, 1), "output dimensions %r" % (out.GetDimensions(),))
names = {out.GetPointData().GetArrayName(k) for k in range(out.GetPointData().GetNumberOfArrays())}
T.check(names == {"elevation", "extra", "normal", "slope", "aspect", "hillshade", "snow_cover",
                  "cover_class"}, "arrays %r" % sorted(names))
T.check((arr(out, "extra") == extra.reshape(NY, NX)).all(), "the input's arrays pass through")
T.check(out.GetPointData().GetScalars() is None, "the input's active scalars (none) stay")
T.check(out.GetPointData().GetNormals().GetName() == "normal", "lit by the normals")
T.check(out.GetPointData().GetArray("cover_class").GetDataTypeAsString() == "unsigned char",
        "cover_class is bytes")
dev = out.GetFieldData().GetAbstractArray("graupel_device")
T.check(dev is not None and len(dev.GetValue(0)) > 0, "graupel_device in the field data")
T.check(np.abs(arr(out, "slope") - S).max() < 1e-3, "slope %.6f deg, everywhere, edges included"
        % np.abs(arr(out, "slope") - S).max())
T.check(np.abs(arr(out, "aspect") - ASP).max() < 1e-3, "aspect within 1e-3 deg of %g" % ASP)
m = math.tan(S * RAD)
gx, gy = -m * math.sin(ASP * RAD), -m * math.cos(ASP * RAD)
n = np.array([-gx, -gy, 1.0]) / math.sqrt(gx * gx + gy * gy + 1)
N = arr(out, "normal", 3)
# Heights near 200 m: float32's step there (1.5e-5 m) bounds the normal's error.
T.check(np.abs(N - n).max() < 2e-5, "normal off by %.3g" % np.abs(N - n).max())
T.check(np.abs(np.linalg.norm(N, axis=2) - 1).max() < 1e-6, "unit normals")
z = (90 - EL) * RAD
esri = max(0.0, math.cos(z) * math.cos(S * RAD) + math.sin(z) * math.sin(S * RAD) *
           math.cos((AZ - ASP) * RAD))
T.near(float(arr(out, "hillshade")[7, 9]), esri, 2e-6, "hillshade = ESRI's Lambert term")
T.check(np.abs(arr(out, "snow_cover") - math.cos(S * RAD) ** 4).max() < 1e-5,
        "snow_cover = n_z^4")
T.check((arr(out, "cover_class") == 1).all(), "a 30-degree plane is snow (cos^4 = 0.56)")

# flat: normal exactly (0, 0, 1), aspect -1, hillshade sin E, no shadow
f, out = analyse(image({"elevation": np.full((NY, NX), 7.0)}), SunElevation=EL, ModelShadows=1)
N = arr(out, "normal", 3)
T.check((N[..., 0] == 0).all() and (N[..., 1] == 0).all() and (N[..., 2] == 1).all(),
        "a flat field's normals are (0, 0, 1)")
T.check((arr(out, "aspect") == -1).all() and (arr(out, "slope") == 0).all(), "flat: aspect -1")
T.check(np.abs(arr(out, "hillshade") - math.sin(EL * RAD)).max() < 1e-6, "flat hillshade sin E")
T.check((arr(out, "shadow") == 1).all(), "flat ground has no shadow")

# cover classes: just below and above RockSlope, and ice below WaterLevel
for side, want in ((-0.01, 0), (0.01, 2)):
    f, out = analyse(image({"elevation": tilted(40.0 + side, 10.0, 5.0)}), RockSlope=40.0,
                     WaterLevel=-1e4)
    T.check((arr(out, "cover_class") == want).all(),
            "RockSlope 40, slope %+.2f: class %d (ground: cos^4 < 0.5)" % (side, want))
f, out = analyse(image({"elevation": tilted(40.0 - 0.01, 10.0, 5.0)}), RockSlope=40.0,
                 WaterLevel=-1e4, CoverMode=1)
T.check((arr(out, "cover_class") == 1).all() and (arr(out, "snow_cover") == 1).all(),
        "Threshold mode: snow up to RockSlope")
h = tilted(10.0, 90.0, 3.0)  # falls to the east, through 0 m
f, out = analyse(image({"elevation": h}), WaterLevel=0.0)
cls = arr(out, "cover_class")
T.check(((cls == 3) == (h.astype(np.float32) < 0)).all() and (cls[h > 0] == 1).all() and
        (h < 0).any(), "ice exactly below WaterLevel")

# another height array: the snow's surface, not the ground
snow = tilted(20.0, 200.0, 50.0)
f = vtkTerrainAnalysisFilter()
f.SetInputConnection(producer(image({"elevation": np.zeros((NY, NX)), "snow_surface": snow})))
f.SetInputArrayToProcess(0, 0, 0, vtkDataObject.FIELD_ASSOCIATION_POINTS, "snow_surface")
f.Update()
out = f.GetOutput()
T.check(out.GetNumberOfPoints() == NX * NY and np.abs(arr(out, "slope") - 20.0).max() < 1e-3 and
        np.abs(arr(out, "aspect") - 200.0).max() < 1e-3, "slope and aspect of snow_surface")

# ---- shadows -------------------------------------------------------------------------
SN = 64


def spike(**kw):
    g = np.full((SN, SN), 2.0)
    g[32, 32] += 10.0
    f, out = analyse(image({"elevation": g}, SN, SN, 1.0, 1.0), cls=vtkTerrainShadowFilter, **kw)
    return arr(out, "shadow"), out


for az, di, dj in ((90.0, -1, 0), (0.0, 0, -1), (225.0, 1, 1)):
    for el in (30.0, 50.0):
        sh, out = spike(SunAzimuth=az, SunElevation=el)
        dark = np.argwhere(sh < 1)
        rs = [(jj - 32) // dj if dj else (ii - 32) // di for jj, ii in dark]
        on = all(r > 0 and jj == 32 + r * dj and ii == 32 + r * di
                 for (jj, ii), r in zip(dark, rs))
        cell = math.hypot(di, dj)
        length = max(rs) * cell if rs else 0.0
        T.check(on and len(rs) == max(rs, default=0),
                "az %g E %g: the shadow lies behind the spike, unbroken" % (az, el))
        T.check(abs(length - 10.0 / math.tan(el * RAD)) <= cell,
                "az %g E %g: shadow %.2f m, h / tan E = %.2f m" % (az, el, length,
                                                                 10.0 / math.tan(el * RAD)))
names = {out.GetPointData().GetArrayName(k) for k in range(out.GetPointData().GetNumberOfArrays())}
T.check(names == {"elevation", "shadow"}, "Terrain Shadow adds shadow only: %r" % sorted(names))
T.check(out.GetPointData().GetScalars().GetName() == "shadow", "coloured by shadow")
sh, _ = spike(SunAzimuth=270.0, SunElevation=25.0, PenumbraWidth=6.0)
line = sh[32, 33:]
T.check((np.diff(line) >= 0).all() and ((line > 0) & (line < 1)).sum() >= 3,
        "the soft edge rises monotonically: %r" % line[15:28])
T.check((np.delete(sh, 32, axis=0) == 1).all(), "no shadow off the spike's row")

# ModelShadows: hillshade x shadow, and the shadow array
hills = (12 * np.sin(0.2 * X) * np.cos(0.15 * Y)).astype(np.float32)
_, plain = analyse(image({"elevation": hills}), SunElevation=12.0, SunAzimuth=80.0)
_, shaded = analyse(image({"elevation": hills}), SunElevation=12.0, SunAzimuth=80.0,
                    ModelShadows=1)
_, alone = analyse(image({"elevation": hills}), cls=vtkTerrainShadowFilter, SunElevation=12.0,
                   SunAzimuth=80.0)
s = arr(shaded, "shadow")
T.check((s == arr(alone, "shadow")).all() and (s == 0).sum() > 10,
        "ModelShadows' shadow is Terrain Shadow's (%d points dark)" % (s == 0).sum())
T.check((arr(shaded, "hillshade") == (arr(plain, "hillshade") * s).astype(np.float32)).all(),
        "hillshade x shadow")

# ---- bad input: one sentence, an empty output, then the next update works ----------
for cls_ in (vtkTerrainAnalysisFilter, vtkTerrainShadowFilter):
    f = cls_()
    good = image({"elevation": tilted(10.0, 45.0)})
    # Two arrays, neither elevation nor the active scalars: no heights to take.
    for bad, words in ((image({"height": tilted(10.0, 45.0), "roughness": tilted(1.0, 1.0)}),
                        ("elevation", "Height Array")),
                       (image({"elevation": np.where(i == 3, np.nan, 1.0) * np.ones((NY, NX))}),
                        ("NaN", "(3, 0)")),
                       (image({"elevation": np.zeros(NX * NY * 2)}, nz=2), ("2-D", "x 2"))):
        catcher = T.ErrorCatcher(f)
        f.SetInputConnection(producer(bad))
        f.Update()
        label = f.GetClassName()
        T.check(len(catcher.messages) == 1 and all(w in catcher.text() for w in words),
                "%s: one sentence naming %r: %r" % (label, words, catcher.messages))
        T.check(f.GetOutput().GetNumberOfPoints() == 0, "%s: an empty output" % label)
        catcher.clear()
        f.SetInputConnection(producer(good))
        f.Update()
        T.check(not catcher.messages and f.GetOutput().GetNumberOfPoints() == NX * NY,
                "%s: the next good update works (%r)" % (label, catcher.messages))

# ---- the proxies (pvpython with the plugin) -------------------------------------------
plugin = a.plugin
if plugin is None:
    import glob

    import graupel

    lib = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(graupel.__file__))))
    found = glob.glob(os.path.join(lib, "paraview-*", "plugins", "Graupel", "Graupel.so"))
    plugin = found[0] if found else None
if plugin is not None:
    from paraview import servermanager  # noqa: E402
    from paraview import simple as pv  # noqa: E402

    px = globals()  # where LoadPlugin puts the plugin's proxies
    pv.LoadPlugin(plugin, ns=px)
    pxm = servermanager.ProxyManager()
    protos = {name: pxm.GetPrototypeProxy("filters", name)
              for name in ("TerrainAnalysis", "TerrainShadow")}
    units = {"SunAzimuth": "Degrees", "SunElevation": "Degrees", "PenumbraWidth": "Degrees",
             "RockSlope": "Degrees", "WaterLevel": "Metres", "HeightArray": "Metres"}
    for name, proto in protos.items():
        T.check(proto is not None, "proxy %s is registered" % name)
        if proto is None:
            continue
        for prop, unit in units.items():
            p = proto.GetProperty(prop)
            if p is None:
                T.check(name == "TerrainShadow" and prop in ("RockSlope", "WaterLevel"),
                        "%s has %s" % (name, prop))
                continue
            doc = p.GetDocumentation().GetDescription()
            T.check(doc.strip().startswith(unit), "%s.%s documents its unit: %r" % (name, prop, doc))
        hint = proto.GetHints().FindNestedElementByName("RepresentationType")
        T.check(hint is not None and hint.GetAttribute("type") == "Surface",
                "%s shows as a surface" % name)
        doc = proto.GetDocumentation().GetDescription()
        T.check(all(w in doc for w in (("degrees", "normal", "cover_class") if name ==
                                       "TerrainAnalysis" else ("shadow", "tan(SunElevation)"))),
                "%s's documentation names the outputs and units" % name)
    # The sun is one set of properties: Terrain Shadow's domains and defaults
    # are Terrain Analysis's (which py.param_bounds checks against the table).
    for prop in ("SunAzimuth", "SunElevation", "PenumbraWidth"):
        pa, ps = (protos[n].GetProperty(prop) for n in ("TerrainAnalysis", "TerrainShadow"))
        ra, rs_ = pa.GetDomain("range"), ps.GetDomain("range")
        T.check(pa.GetElement(0) == ps.GetElement(0) and
                (ra.GetMinimum(0), ra.GetMaximum(0)) == (rs_.GetMinimum(0), rs_.GetMaximum(0)),
                "%s alike on both proxies" % prop)
    # Made before its input ran, the proxy has no array to list: an empty
    # HeightArray means elevation.
    terrain = px["ProceduralTerrain"](Dimensions=[96, 80])
    early = px["TerrainAnalysis"](Input=terrain)
    early.UpdatePipeline()
    T.check(early.PointData["slope"] is not None, "an empty HeightArray reads elevation")
    pv.Delete(early)
    ta = px["TerrainAnalysis"](Input=terrain)
    T.check(list(ta.HeightArray)[-1] == "elevation", "HeightArray %r" % list(ta.HeightArray))
    ta.ModelShadows = 1
    ta.SunElevation = 20.0
    ta.UpdatePipeline()
    pdi = ta.PointData
    T.check(all(k in pdi.keys() for k in ("normal", "slope", "aspect", "hillshade", "snow_cover",
                                          "cover_class", "shadow", "elevation")),
            "TerrainAnalysis arrays %r" % pdi.keys())
    lo, hi = pdi["slope"].GetRange()
    T.check(0.0 <= lo and hi < 90.0 and hi > 5.0, "slope range %g..%g deg" % (lo, hi))
    T.check(pdi["cover_class"].GetRange()[1] <= 3, "classes 0..3")
    # After Terrain Analysis, the Height Array is still the heights.
    ts = px["TerrainShadow"](Input=ta, SunElevation=10.0, PenumbraWidth=1.0)
    T.check(list(ts.HeightArray)[-1] == "elevation", "HeightArray %r" % list(ts.HeightArray))
    ts.UpdatePipeline()
    lo, hi = ts.PointData["shadow"].GetRange()
    T.check(lo == 0.0 and hi == 1.0, "a low sun casts shadows on the terrain (%g..%g)" % (lo, hi))
    view = pv.CreateRenderView()
    rep = pv.Show(ta, view)
    T.check(rep.Representation == "Surface", "shown as %r" % rep.Representation)
else:
    print("no ParaView plugin beside the module: proxy checks skipped (plain VTK)")

T.finish()
