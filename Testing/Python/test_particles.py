"""vtkRainParticlesSource and vtkSnowfallParticlesSource in a pipeline
(pvpython in the plugin build, plain python3 on Debian's VTK): exact counts
of points and vertices, the arrays and their units' ranges, the time stamp,
the same particles for the same (Seed, time) whatever the order of the
requests, the drop sizes' mean against Marshall-Palmer (truncated to 0.1-6
mm) at two rain rates, fall speeds by diameter, the mean drift between two
times = wind * dt, every particle inside the region (the Region box, or a
connected terrain's bounds), flakes' fall speeds in 0.5-1.5 m/s, the
clamps, bad input (a zero-size region, a rain rate of 0, a terrain one
point wide: one sentence, an empty output, and the next good update works),
and under pvpython the two proxies: units in their documentation, the
points representation, a run on Procedural Terrain."""
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

from graupel import vtkRainParticlesSource, vtkSnowfallParticlesSource  # noqa: E402

_keep = []  # a vtkAlgorithmOutput does not keep its producer alive
REGION = (-20.0, 180.0, 0.0, 100.0, 5.0, 45.0)


def producer(data):
    p = vtkTrivialProducer()
    p.SetOutput(data)
    _keep.append(p)
    return p.GetOutputPort()


def terrain(nx=40, ny=30, lo=10.0, hi=30.0):
    img = vtkImageData()
    img.SetDimensions(nx, ny, 1)
    img.SetSpacing(2.0, 1.5, 1.0)
    img.SetOrigin(100.0, -50.0, 0.0)
    j, i = np.mgrid[0:ny, 0:nx]
    h = lo + (hi - lo) * (i + j) / max(nx + ny - 2, 1)
    arr = numpy_to_vtk(np.ascontiguousarray(h, dtype=np.float32).reshape(-1), deep=1)
    arr.SetName("elevation")
    img.GetPointData().AddArray(arr)
    return img


def run(src, t):
    src.UpdateTimeStep(t)
    out = src.GetOutput()
    pd = out.GetPointData()
    get = (lambda n: vtk_to_numpy(pd.GetArray(n)).copy() if pd.GetArray(n) else None)
    pts = vtk_to_numpy(out.GetPoints().GetData()).copy() if out.GetPoints() else np.zeros((0, 3))
    return out, pts, get


def rain(count=1 << 14, rate=10.0, wind=(0.0, 0.0, 0.0), seed=0):
    s = vtkRainParticlesSource()
    s.SetCount(count)
    s.SetRainRate(rate)
    s.SetWind(*wind)
    s.SetSeed(seed)
    s.SetRegion(*REGION)
    return s


def inside(pts, region):
    lo = np.array(region[0::2], dtype=np.float32)
    hi = np.array(region[1::2], dtype=np.float32)
    return bool(((pts >= lo) & (pts <= hi)).all())


def unwrap(d, w):
    return d - w * np.floor(d / w + 0.5)


# ---- defaults and clamps (the core's table) -------------------------------------------
r = vtkRainParticlesSource()
T.check((r.GetCount(), r.GetRainRate(), r.GetExposureTime(), r.GetSeed()) == (131072, 10.0, 0.02, 0),
        "defaults %r" % ((r.GetCount(), r.GetRainRate(), r.GetExposureTime(), r.GetSeed()),))
r.SetCount(100)
T.check(r.GetCount() == 1024, "Count clamps to 2^10: %d" % r.GetCount())
r.SetCount(1 << 30)
T.check(r.GetCount() == 1 << 24, "Count clamps to 2^24: %d" % r.GetCount())
s = vtkSnowfallParticlesSource()
T.check(s.GetFlutterAmplitude() == 0.3 and s.GetCount() == 131072, "snowfall defaults")

# ---- counts, arrays, time stamp ---------------------------------------------------------
for cls, size_name, n in ((vtkRainParticlesSource, "diameter", 5000),
                          (vtkSnowfallParticlesSource, "size", 1 << 12)):
    src = cls()
    src.SetCount(n)
    src.SetRegion(*REGION)
    out, pts, get = run(src, 4.25)
    name = src.GetClassName()
    T.check(out.GetNumberOfPoints() == n and out.GetNumberOfVerts() == n and
            out.GetNumberOfCells() == n, "%s: %d points and vertices (%d, %d)"
            % (name, n, out.GetNumberOfPoints(), out.GetNumberOfVerts()))
    T.check(get("velocity").shape == (n, 3) and get("streak").shape == (n, 3) and
            get(size_name).shape == (n,), "%s: velocity, %s, streak" % (name, size_name))
    T.check(out.GetPointData().GetScalars().GetName() == size_name, "%s coloured by size" % name)
    ft = out.GetFieldData().GetArray("time")
    T.check(ft is not None and ft.GetValue(0) == 4.25, "%s: field data time 4.25" % name)
    T.check(out.GetInformation().Get(vtkDataObject.DATA_TIME_STEP()) == 4.25,
            "%s: DATA_TIME_STEP" % name)
    dev = out.GetFieldData().GetAbstractArray("graupel_device")
    T.check(dev is not None and len(dev.GetValue(0)) > 0, "%s: graupel_device" % name)
    T.check(inside(pts, REGION), "%s: inside the region" % name)
    T.check(np.allclose(get("streak"), 0.02 * get("velocity"), atol=1e-5) or cls is
            vtkSnowfallParticlesSource, "%s: streak = velocity * ExposureTime" % name)

# ---- determinism: the same (Seed, time) whatever was asked for before -------------------
for cls in (vtkRainParticlesSource, vtkSnowfallParticlesSource):
    src = cls()
    src.SetCount(1 << 12)
    src.SetWind(3.0, -1.0, 0.0)
    src.SetSeed(5)
    first = run(src, 7.5)[1]
    run(src, 2.0)
    run(src, 100.0)
    again = run(src, 7.5)[1]
    fresh = cls()
    fresh.SetCount(1 << 12)
    fresh.SetWind(3.0, -1.0, 0.0)
    fresh.SetSeed(5)
    other = run(fresh, 7.5)[1]
    T.check(first.tobytes() == again.tobytes() == other.tobytes(),
            "%s: t = 7.5 bit for bit after 2 and 100, and on a new source" % cls.__name__)
    fresh.SetSeed(6)
    T.check((run(fresh, 7.5)[1] != first).any(axis=1).mean() > 0.9, "another Seed, other particles")

# ---- drop sizes: Marshall-Palmer's mean; fall speeds by diameter ------------------------
means = []
for rate in (2.0, 60.0):
    out, pts, get = run(rain(1 << 16, rate, (0.0, 0.0, -1.0)), 3.0)
    d = get("diameter").astype(np.float64)
    lam = 4.1 * rate ** -0.21
    e = math.exp(-lam * 5.9)
    want = 0.1 + 1.0 / lam - 5.9 * e / (1.0 - e)
    means.append(d.mean())
    T.near(d.mean() / want, 1.0, 0.015, "R = %g mm/h: mean diameter %.4f mm vs Marshall-Palmer "
           "%.4f mm" % (rate, d.mean(), want))
    T.check(d.min() >= 0.1 - 1e-6 and d.max() <= 6.0 + 1e-5, "diameters within 0.1-6 mm")
    v = np.maximum(9.65 - 10.3 * np.exp(-0.6 * d), 0.0)
    vz = get("velocity")[:, 2].astype(np.float64)
    T.check(np.abs((-1.0 - vz) - v).max() < 1e-5,
            "fall speed 9.65 - 10.3 exp(-0.6 D) by diameter (+ the wind's -1 m/s): worst %.3g"
            % np.abs((-1.0 - vz) - v).max())
T.check(means[1] > 1.4 * means[0], "heavier rain, larger drops: %r" % means)

# ---- drift: the mean horizontal motion between two times is wind * dt -------------------
drifts = []
for wind in ((0.0, 0.0), (2.0, 0.5), (9.0, -4.0)):
    src = rain(1 << 14, 10.0, (wind[0], wind[1], 0.0))
    p1 = run(src, 10.0)[1]
    p2 = run(src, 10.5)[1]
    same = p2[:, 2] < p1[:, 2]  # not respawned in between
    dx = unwrap(p2[same, 0] - p1[same, 0], REGION[1] - REGION[0]).mean()
    dy = unwrap(p2[same, 1] - p1[same, 1], REGION[3] - REGION[2]).mean()
    want = np.array(wind) * 0.5
    T.check(np.abs(np.array([dx, dy]) - want).max() <= 0.01 * max(np.hypot(*want), 1e-4),
            "wind %r: mean drift (%.5f, %.5f) m over 0.5 s, wind * dt %r" % (wind, dx, dy, want))
    T.check((~same).sum() > 0, "some drops respawned")
    drifts.append(math.hypot(dx, dy))
T.check(drifts[0] < drifts[1] < drifts[2], "the drift grows with the wind: %r" % drifts)

# ---- snowfall: 0.5-1.5 m/s, flutter, sizes ----------------------------------------------
src = vtkSnowfallParticlesSource()
src.SetCount(1 << 14)
src.SetWind(1.0, 2.0, 0.0)
src.SetRegion(*REGION)
out, pts, get = run(src, 12.0)
vel = get("velocity").astype(np.float64)
fall = -vel[:, 2]
T.check(fall.min() >= 0.5 - 1e-6 and fall.max() <= 1.5 + 1e-6 and fall.min() < 0.52 and
        fall.max() > 1.48, "flakes fall at 0.5-1.5 m/s: %.4f..%.4f" % (fall.min(), fall.max()))
sway = np.hypot(vel[:, 0] - 1.0, vel[:, 1] - 2.0)
bound = 2 * math.pi * 0.8 * 0.3
T.check(sway.max() <= bound * (1 + 1e-5) and sway.max() > 0.5 * bound,
        "flutter about the wind, at most 2 pi f a: %.4f (bound %.4f)" % (sway.max(), bound))
size = get("size")
T.check(size.min() >= 2.0 - 1e-6 and size.max() <= 10.0 + 1e-5, "flake sizes 2-10 mm")
T.check(inside(pts, REGION), "flakes inside the region")

# ---- a terrain gives the region -----------------------------------------------------------
img = terrain()
for cls in (vtkRainParticlesSource, vtkSnowfallParticlesSource):
    src = cls()
    src.SetCount(1 << 12)
    src.SetRegion(0.0, 1.0, 0.0, 1.0, 0.0, 20.0)  # only its height (20 m) counts
    src.SetWind(-30.0, 12.0, 0.0)
    src.SetInputConnection(producer(img))
    region = (100.0, 100.0 + 39 * 2.0, -50.0, -50.0 + 29 * 1.5, 10.0, 50.0)
    for t in (0.0, 3.3, 250.0):
        pts = run(src, t)[1]
        T.check(len(pts) == 1 << 12 and inside(pts, region),
                "%s on a terrain, t = %g: inside its bounds, z 10..50" % (cls.__name__, t))
    T.check(pts[:, 2].max() > 45.0 and pts[:, 2].min() < 15.0, "the column is used top to bottom")

# ---- bad input: one sentence, an empty output, then the next update works --------------
flat = list(REGION)
flat[5] = flat[4]
cases = (("region", lambda s: s.SetRegion(*flat), ("region", "z", "zmax")),
         ("rain rate", lambda s: s.SetRainRate(-3.0), ("RainRate", "mm/h", "above 0")),
         ("terrain one point wide", lambda s: s.SetInputConnection(producer(terrain(nx=1))),
          ("region", "along x")))
for what, spoil, words in cases:
    src = rain(2048)
    catcher = T.ErrorCatcher(src)
    spoil(src)
    out = run(src, 1.0)[0]
    T.check(len(catcher.messages) == 1 and all(w in catcher.text() for w in words),
            "%s: one sentence naming %r: %r" % (what, words, catcher.messages))
    T.check(out.GetNumberOfPoints() == 0, "%s: an empty output" % what)
    catcher.clear()
    src.SetRegion(*REGION)
    src.SetRainRate(10.0)
    src.SetInputConnection(None)
    src.RemoveAllInputConnections(0)
    out = run(src, 1.0)[0]
    T.check(not catcher.messages and out.GetNumberOfPoints() == 2048,
            "%s: the next good update works (%r)" % (what, catcher.messages))

# ---- the proxies (pvpython with the plugin) ---------------------------------------------
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
    units = {"Count": "Particles", "Wind": "m/s", "ExposureTime": "Seconds", "Region": "Metres",
             "RainRate": "mm/h", "FlutterAmplitude": "Metres"}
    for name in ("RainParticles", "SnowfallParticles"):
        proto = pxm.GetPrototypeProxy("sources", name)
        T.check(proto is not None, "proxy %s is registered" % name)
        if proto is None:
            continue
        for prop, unit in units.items():
            p = proto.GetProperty(prop)
            if p is None:
                T.check((name, prop) in (("RainParticles", "FlutterAmplitude"),
                                         ("SnowfallParticles", "RainRate")),
                        "%s has %s" % (name, prop))
                continue
            doc = p.GetDocumentation().GetDescription()
            T.check(doc.strip().startswith(unit), "%s.%s documents its unit: %r" % (name, prop, doc))
        hint = proto.GetHints().FindNestedElementByName("RepresentationType")
        T.check(hint is not None and hint.GetAttribute("type") == "Points",
                "%s shows as points" % name)
        doc = proto.GetDocumentation().GetDescription()
        T.check(all(w in doc for w in ("velocity", "streak", "(m/s)", "mm")),
                "%s's documentation names the outputs and units" % name)
    ground = px["ProceduralTerrain"](Dimensions=[64, 48])
    for name in ("RainParticles", "SnowfallParticles"):
        pv.SetActiveSource(None)  # else paraview.simple makes the active source the Input
        alone = px[name](Count=4096)
        alone.UpdatePipeline(2.0)
        info = alone.GetDataInformation()
        T.check(info.GetNumberOfPoints() == 4096, "%s alone: 4096 points" % name)
        pvi = info.DataInformation
        T.check(pvi.GetHasTime() and pvi.GetTime() == 2.0, "%s: computed for t = 2" % name)
        T.check(tuple(pvi.GetTimeRange()) == (0.0, 60.0),
                "%s: the time range 0-60 s: %r" % (name, tuple(pvi.GetTimeRange())))
        on = px[name](Input=ground, Count=8192, Wind=[4.0, 0.0, 0.0])
        on.UpdatePipeline(5.0)
        b = on.GetDataInformation().GetBounds()
        tb = ground.GetDataInformation().GetBounds()
        T.check(on.GetDataInformation().GetNumberOfPoints() == 8192 and
                b[0] >= tb[0] and b[1] <= tb[1] and b[2] >= tb[2] and b[3] <= tb[3],
                "%s on Procedural Terrain: inside its bounds %r (%r)" % (name, tb[:4], b[:4]))
        view = pv.CreateRenderView()
        rep = pv.Show(on, view)
        T.check(rep.Representation == "Points", "%s shown as %r" % (name, rep.Representation))
else:
    print("no ParaView plugin beside the module: proxy checks skipped (plain VTK)")

T.finish()
