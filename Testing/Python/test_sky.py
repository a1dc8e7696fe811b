"""vtkLightningSource and vtkCloudCoverSource in a pipeline (pvpython in the
plugin build, plain python3 on Debian's VTK): the bolt's point count
ControlPoints + Strands * max(2, ControlPoints / 2) as one polyline per
strand, Start and End exact, intensity 1 on the main strand and less on the
branches, every branch rooted on a main-strand point, bit-identical bolts
for one Seed and different ones for another, the shape at a time Variant +
floor(t FlickerRate), a strike on a terrain's surface; the clouded fraction within 0.05 of Cover and monotone in it,
bit-identical skies, the drift at t + dt the image at t shifted by
WindSpeed dt; bad input (ControlPoints 1, Start = End, Resolution 0, an
empty terrain: one sentence, an empty output, then the next good update
works); under pvpython the two proxies."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args()

from vtkmodules.util.numpy_support import vtk_to_numpy, numpy_to_vtk  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkPolyData  # noqa: E402
from vtkmodules.vtkCommonExecutionModel import vtkTrivialProducer  # noqa: E402

from graupel import vtkCloudCoverSource, vtkLightningSource  # noqa: E402

_keep = []


def producer(data):
    p = vtkTrivialProducer()
    p.SetOutput(data)
    _keep.append(p)
    return p.GetOutputPort()


def bolt(**kw):
    s = vtkLightningSource()
    for k, v in kw.items():
        getattr(s, "Set" + k)(*v) if isinstance(v, tuple) else getattr(s, "Set" + k)(v)
    s.Update()
    return s, s.GetOutput()


def points(out):
    return vtk_to_numpy(out.GetPoints().GetData()).astype(np.float64)


def parray(out, name):
    return vtk_to_numpy(out.GetPointData().GetArray(name))


# ---- lightning ------------------------------------------------------------------
START, END = (120.0, -40.0, 1500.0), (-60.0, 210.0, 35.5)
for n, strands in ((50, 4), (2, 3), (7, 0), (51, 10)):
    _, out = bolt(ControlPoints=n, Strands=strands, Start=START, End=END)
    m = max(2, n // 2)
    want = n + strands * m
    T.check(out.GetNumberOfPoints() == want,
            "N %d, S %d: %d points, want %d" % (n, strands, out.GetNumberOfPoints(), want))
    T.check(out.GetNumberOfLines() == strands + 1, "one polyline per strand: %d" % out.GetNumberOfLines())
    xyz, inten, strand = points(out), parray(out, "intensity"), parray(out, "strand")
    T.check((xyz[0] == START).all() and (xyz[n - 1] == END).all(),
            "N %d: starts at Start and ends exactly at End (%r, %r)" % (n, xyz[0], xyz[n - 1]))
    T.check((inten[:n] == 1.0).all() and (inten[n:] < 1.0).all() and (strand[:n] == 0).all(),
            "N %d: intensity 1 on the main strand, less on branches" % n)
    lines = out.GetLines()
    ids = vtk_to_numpy(lines.GetConnectivityArray())
    offsets = vtk_to_numpy(lines.GetOffsetsArray())
    T.check(list(np.diff(offsets)) == [n] + [m] * strands, "polyline lengths %r" % list(np.diff(offsets)))
    T.check((ids == np.arange(want)).all(), "polylines in point order")
    for s in range(1, strands + 1):
        root = xyz[n + (s - 1) * m]
        T.check(((xyz[:n] == root).all(axis=1)).any(),
                "N %d: branch %d is rooted on the main strand" % (n, s))
        T.check((strand[n + (s - 1) * m: n + s * m] == s).all(), "branch %d's strand ids" % s)

_, a0 = bolt(Seed=11)
_, a1 = bolt(Seed=11)
_, b0 = bolt(Seed=12)
T.check(points(a0).tobytes() == points(a1).tobytes() and
        parray(a0, "intensity").tobytes() == parray(a1, "intensity").tobytes(),
        "one Seed, one bolt, bit for bit")
moved = (points(a0) != points(b0)).any(axis=1).sum()
T.check(moved >= a0.GetNumberOfPoints() - 2 - 4, "another Seed moves %d of %d points"
        % (moved, a0.GetNumberOfPoints()))
_, v1 = bolt(Seed=11, Variant=1)
T.check((points(a0) != points(v1)).any(axis=1).sum() > 100, "another Variant reshapes the bolt")

# Flicker: at 4 reshapes a second, t = 0.3 s shows Variant 1's bolt, t = 0.2 s Variant 0's.
f = vtkLightningSource()
f.SetSeed(11)
f.SetFlickerRate(4.0)
for t, want in ((0.2, a0), (0.3, v1), (0.1, a0)):
    f.UpdateTimeStep(t)
    out = f.GetOutput()
    T.check(points(out).tobytes() == points(want).tobytes(),
            "FlickerRate 4 at t = %g s draws shape %d" % (t, out.GetFieldData().GetArray("shape").GetValue(0)))

# A strike on a terrain: End is one of the surface's points, Start far above.
NX, NY = 40, 30
terrain = vtkImageData()
terrain.SetDimensions(NX, NY, 1)
terrain.SetSpacing(5.0, 5.0, 1.0)
terrain.SetOrigin(-100.0, 50.0, 0.0)
jj, ii = np.mgrid[0:NY, 0:NX]
elev = (20.0 + 10.0 * np.sin(ii / 6.0) + 0.5 * jj).astype(np.float32)
arr = numpy_to_vtk(elev.reshape(-1), deep=1)
arr.SetName("elevation")
terrain.GetPointData().AddArray(arr)
surface = np.stack([-100.0 + 5.0 * ii, 50.0 + 5.0 * jj, elev.astype(np.float64)], -1).reshape(-1, 3)
hits = set()
for seed in range(20):
    s = vtkLightningSource()
    s.SetInputConnection(producer(terrain))
    s.SetSeed(seed)
    s.Update()
    xyz = points(s.GetOutput())
    end = xyz[49]
    k = np.nonzero((np.abs(surface - end) < 1e-9).all(axis=1))[0]
    T.check(len(k) == 1, "seed %d strikes a point of the terrain's surface: %r" % (seed, end))
    hits.update(int(x) for x in k)
    T.check(xyz[0][2] >= elev.max() + 0.5 * 195.0 - 1e-9, "seed %d starts high above the terrain" % seed)
T.check(len(hits) >= 15, "20 seeds strike %d different points" % len(hits))

# ---- cloud cover -------------------------------------------------------------------


def sky(t=None, **kw):
    s = vtkCloudCoverSource()
    for k, v in kw.items():
        getattr(s, "Set" + k)(v)
    if t is None:
        s.Update()
    else:
        s.UpdateTimeStep(t)
    return s, s.GetOutput()


def cloud(out):
    n = out.GetDimensions()
    return vtk_to_numpy(out.GetPointData().GetArray("cloud")).reshape(n[1], n[0])


fracs = []
for cover in (0.0, 0.1, 0.25, 0.5, 0.75, 0.9, 1.0):
    _, out = sky(Cover=cover, Resolution=512, Size=65536.0, Scale=1024.0, Seed=3)
    c = cloud(out)
    frac = float((c > 0).mean())
    fracs.append(frac)
    T.near(frac, cover, 0.05, "Cover %.2f: clouded fraction" % cover)
    T.check(c.min() >= 0.0 and c.max() <= 1.0, "cloud in 0..1")
T.check(fracs == sorted(fracs) and fracs[0] == 0.0 and fracs[-1] == 1.0,
        "clouded fraction monotone in Cover, 0 and 1 at the ends: %r" % fracs)
print("clouded fractions for Cover 0, .1, .25, .5, .75, .9, 1: %s" % ", ".join("%.4f" % f for f in fracs))

_, s0 = sky(t=30.0, Resolution=128)
_, s1 = sky(t=30.0, Resolution=128)
T.check(cloud(s0).tobytes() == cloud(s1).tobytes(), "one Seed and time, one sky, bit for bit")
rgb = vtk_to_numpy(s0.GetPointData().GetArray("sky_rgb"))
T.check(rgb.shape == (128 * 128, 3) and rgb.dtype == np.uint8, "sky_rgb: 3 bytes a pixel")
T.check(s0.GetFieldData().GetArray("time").GetValue(0) == 30.0, "the time in the field data")
T.check(abs(s0.GetOrigin()[2] - 3000.0) < 1e-12, "the image lies at Altitude")

# Drift: 10 m/s east for 12.8 s moves the sky 128 m, 4 pixels of 32 m.
_, d0 = sky(t=100.0, Resolution=256, Size=8192.0, WindSpeed=10.0, WindDirection=90.0)
_, d1 = sky(t=112.8, Resolution=256, Size=8192.0, WindSpeed=10.0, WindDirection=90.0)
c0, c1 = cloud(d0), cloud(d1)
err = np.abs(c1[:, 4:] - c0[:, :-4]).max()
change = np.abs(c1 - c0).max()
T.check(err < 2e-4 and change > 0.1, "the sky at t + 12.8 s is the sky at t moved 4 pixels east "
        "(within %.2g; unmoved %.2g)" % (err, change))

# The class clamps Cover to 0..1 (the table's range): 1.5 reads back 1.
s = vtkCloudCoverSource()
s.SetCover(1.5)
T.check(s.GetCover() == 1.0, "Cover 1.5 reads back %r" % s.GetCover())

# ---- bad input: one sentence, an empty output, then the next good update works -----
cases = [
    (vtkLightningSource, lambda s: s.SetControlPoints(1), lambda s: s.SetControlPoints(50),
     ("ControlPoints", "2")),
    (vtkLightningSource, lambda s: s.SetEnd(0.0, 0.0, 1000.0), lambda s: s.SetEnd(0.0, 0.0, 0.0),
     ("Start", "End")),
    (vtkLightningSource, lambda s: s.SetInputConnection(producer(vtkPolyData())),
     lambda s: s.RemoveAllInputConnections(0), ("terrain", "no points")),
    (vtkCloudCoverSource, lambda s: s.SetResolution(0), lambda s: s.SetResolution(64),
     ("Resolution", "0")),
]
example = ""
for cls_, spoil, mend, words in cases:
    s = cls_()
    if cls_ is vtkCloudCoverSource:
        s.SetResolution(64)
    catcher = T.ErrorCatcher(s)
    spoil(s)
    s.Update()
    label = "%s %s" % (cls_.__name__, words[0])
    T.check(len(catcher.messages) == 1 and all(w in catcher.text() for w in words),
            "%s: one sentence naming %r: %r" % (label, words, catcher.messages))
    T.check(s.GetOutput().GetNumberOfPoints() == 0, "%s: an empty output" % label)
    example = example or catcher.text()
    catcher.clear()
    mend(s)
    s.Update()
    T.check(not catcher.messages and s.GetOutput().GetNumberOfPoints() > 0,
            "%s: the next good update works (%r)" % (label, catcher.messages))
print("e.g. " + example)

# ---- the proxies (pvpython with the plugin) -----------------------------------------
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

    px = globals()
    pv.LoadPlugin(plugin, ns=px)
    pxm = servermanager.ProxyManager()
    units = {"CloudCover": {"Scale": "Metres", "Size": "Metres", "WindSpeed": "m/s",
                            "WindDirection": "Degrees", "Altitude": "Metres", "Duration": "Seconds"},
             "Lightning": {"Start": "Metres", "End": "Metres"}}
    for name, props in units.items():
        proto = pxm.GetPrototypeProxy("sources", name)
        T.check(proto is not None, "proxy %s is registered" % name)
        if proto is None:
            continue
        for prop, unit in props.items():
            doc = proto.GetProperty(prop).GetDocumentation().GetDescription()
            T.check(doc.strip().startswith(unit), "%s.%s documents its unit: %r" % (name, prop, doc))
    T.check(pxm.GetPrototypeProxy("sources", "CloudCover").GetProperty("Device") is not None,
            "Cloud Cover has a Device")
    terrain_px = px["ProceduralTerrain"](Dimensions=[64, 48])
    bolt_px = px["Lightning"](Input=terrain_px, Strands=3)
    bolt_px.UpdatePipeline()
    info = bolt_px.GetDataInformation()
    T.check(info.GetNumberOfPoints() == 50 + 3 * 25, "Lightning on a terrain: %d points"
            % info.GetNumberOfPoints())
    sky_px = px["CloudCover"](Resolution=96)
    sky_px.UpdatePipeline(60.0)
    T.check(sky_px.GetDataInformation().GetNumberOfPoints() == 96 * 96, "Cloud Cover 96 x 96")
    lo, hi = sky_px.PointData["cloud"].GetRange()
    T.check(lo == 0.0 and 0.0 < hi <= 1.0, "cloud range %g..%g" % (lo, hi))
else:
    print("no ParaView plugin beside the module: proxy checks skipped (plain VTK)")

T.finish()
