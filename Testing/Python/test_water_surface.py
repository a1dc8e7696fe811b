"""vtkWaterSurfaceFilter in a pipeline (pvpython in the plugin build, plain
python3 on Debian's VTK): a lake's waves (the mean level conserved, dry
points still, level water's normals exactly (0, 0, 1), water_surface =
elevation + depth + wave), raindrop ripples, the advertised times, results
independent of the order in which times are requested (checkpoints and
restarts), a temporal input (Rain Runoff's water followed in time), clamped
properties, bad input (no water and no LakeLevel, NaN elevation, WaveSpeed
at 0: one sentence, an empty output, and the next good update works), and
under pvpython the proxy: units in its documentation, the surface
representation, a water look through physically based rendering."""
import glob
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args()

from vtkmodules.util.numpy_support import vtk_to_numpy, numpy_to_vtk  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData  # noqa: E402
from vtkmodules.vtkCommonExecutionModel import (  # noqa: E402
    vtkStreamingDemandDrivenPipeline as SDDP,
    vtkTrivialProducer,
)

from graupel import vtkRainRunoffFilter, vtkWaterSurfaceFilter  # noqa: E402

NX, NY, DX = 48, 40, 1.0
_keep = []  # a vtkAlgorithmOutput does not keep its producer alive


def image(arrays, dims=(NX, NY), spacing=DX):
    img = vtkImageData()
    img.SetDimensions(dims[0], dims[1], 1)
    img.SetSpacing(spacing, spacing, 1.0)
    img.SetOrigin(10.0, -5.0, 0.0)
    for name, values in arrays.items():
        arr = numpy_to_vtk(np.ascontiguousarray(values, dtype=np.float32).reshape(-1), deep=1)
        arr.SetName(name)
        img.GetPointData().AddArray(arr)
    return img


def producer(img):
    p = vtkTrivialProducer()
    p.SetOutput(img)
    _keep.append(p)
    return p.GetOutputPort()


j, i = np.mgrid[0:NY, 0:NX]
x = (i - (NX - 1) / 2.0) * DX
y = (j - (NY - 1) / 2.0) * DX
bowl = 0.004 * (x * x + y * y) + 0.2 * np.sin(0.3 * i)  # metres; an island-free bowl


def water(arrays, **kw):
    f = vtkWaterSurfaceFilter()
    f.SetInputConnection(producer(image(arrays)))
    f.SetEndTime(kw.pop("EndTime", 10.0))
    f.SetOutputInterval(kw.pop("OutputInterval", 1.0))
    for k, v in kw.items():
        getattr(f, "Set" + k)(v)
    return f


def at(f, t, name="wave_height", comps=1):
    f.UpdateTimeStep(t)
    out = f.GetOutput()
    if out.GetNumberOfPoints() == 0:
        return None, out
    nx, ny, _ = out.GetDimensions()
    v = vtk_to_numpy(out.GetPointData().GetArray(name)).copy()
    return (v.reshape(ny, nx, comps) if comps > 1 else v.reshape(ny, nx)), out


def field(out, name):
    return out.GetFieldData().GetArray(name).GetValue(0)


# ---- defaults and advertised times ---------------------------------------------
f = vtkWaterSurfaceFilter()
T.check(f.GetWaveSpeed() == 1.0 and f.GetDamping() == 0.1 and f.GetWetDepth() == 0.01,
        "defaults WaveSpeed 1 m/s, Damping 0.1 /s, WetDepth 0.01 m")
T.check(f.GetUseLakeLevel() == 0 and f.GetDropRate() == 0.1 and f.GetCourantNumber() == 0.5,
        "defaults UseLakeLevel off, DropRate 0.1, CourantNumber 0.5")
T.check(f.GetEndTime() == 60.0 and f.GetOutputInterval() == 0.5,
        "time defaults EndTime 60 s, OutputInterval 0.5 s")
f.SetWaveSpeed(1e9)
T.check(f.GetWaveSpeed() == 300.0, "WaveSpeed clamps to 300 m/s")
f.SetDamping(-1.0)
T.check(f.GetDamping() == 0.0, "Damping clamps to 0")

lake = water({"elevation": bowl}, UseLakeLevel=1, LakeLevel=1.0, DropRate=0.5,
             DropAmplitude=0.01, DropRadius=1.0, WaveSpeed=2.0, Damping=0.0, EndTime=10.0)
lake.UpdateInformation()
info = lake.GetOutputInformation(0)
steps = [info.Get(SDDP.TIME_STEPS(), k) for k in range(info.Length(SDDP.TIME_STEPS()))]
T.check(steps == [float(k) for k in range(11)], "TIME_STEPS every 1 s up to 10: %r" % steps)

# ---- a lake with raindrops -------------------------------------------------------
h0, out = at(lake, 0.0)
T.check(h0 is not None and float(np.abs(h0).max()) == 0.0, "still water at t = 0")
n0, _ = at(lake, 0.0, "normal", 3)
T.check(np.array_equal(n0.reshape(-1, 3), np.tile([0.0, 0.0, 1.0], (NX * NY, 1))),
        "level water's normals are exactly (0, 0, 1)")
h10, out = at(lake, 10.0)
wet = vtk_to_numpy(out.GetPointData().GetArray("wet")).reshape(NY, NX)
T.check(0 < wet.sum() < NX * NY, "part of the bowl is wet (%d of %d)" % (wet.sum(), NX * NY))
T.check(np.array_equal(wet == 1.0, bowl < 1.0), "wet exactly where elevation < LakeLevel")
T.check(float(np.abs(h10[wet == 0]).max()) == 0.0, "dry points hold no wave")
T.check(float(np.abs(h10).max()) > 1e-3, "raindrops made ripples (max %g m)" % np.abs(h10).max())
l1 = float(np.abs(h10).sum())
T.check(abs(float(h10[wet == 1].astype(np.float64).sum())) <= 1e-5 * l1,
        "drops keep the mean level: sum %g vs sum |h| %g" % (h10.sum(), l1))
T.near(field(out, "wave_volume"), field(out, "initial_volume"), 1e-5 * l1,
       "field data: wave_volume = initial_volume")
T.check(field(out, "wet_points") == wet.sum() and field(out, "energy") > 0.0, "ledger fields")
surf = vtk_to_numpy(out.GetPointData().GetArray("water_surface")).reshape(NY, NX)
T.check(np.allclose(surf, np.where(wet == 1, 1.0 + h10, bowl), atol=1e-5),
        "water_surface = LakeLevel + wave on water, the ground elsewhere")
depth = vtk_to_numpy(out.GetPointData().GetArray("water_depth")).reshape(NY, NX)
T.check(np.allclose(depth, np.where(wet == 1, 1.0 - bowl, 0.0), atol=1e-6), "water_depth")
T.check(out.GetPointData().GetScalars().GetName() == "wave_height", "active scalars wave_height")
T.check(out.GetPointData().GetNormals() is not None, "normal is the active normals")

# ---- order of requests: same bits ------------------------------------------------
ref = {t: at(lake, t)[0] for t in [float(k) for k in range(11)]}
mixed = water({"elevation": bowl}, UseLakeLevel=1, LakeLevel=1.0, DropRate=0.5,
              DropAmplitude=0.01, DropRadius=1.0, WaveSpeed=2.0, Damping=0.0, EndTime=10.0,
              CheckpointInterval=3)
order = (7.0, 2.0, 10.0, 0.0, 5.0, 5.0, 1.0, 9.0, 4.0)
same = True
for t in order:
    h, _ = at(mixed, t)
    same = same and h is not None and np.array_equal(h, ref[t])
T.check(same, "every time equals the forward run bit for bit, whatever the order %r" % (order,))
T.check(mixed.GetRestoreCount() >= 1, "going back restored a checkpoint (%d)"
        % mixed.GetRestoreCount())
other = water({"elevation": bowl}, UseLakeLevel=1, LakeLevel=1.0, DropRate=0.5,
              DropAmplitude=0.01, DropRadius=1.0, WaveSpeed=2.0, Damping=0.0, Seed=2)
h, _ = at(other, 10.0)
T.check(h is not None and not np.array_equal(h, ref[10.0]), "another Seed, other ripples")

# ---- Rain Runoff's water, followed in time ---------------------------------------
rr = vtkRainRunoffFilter()
rr.SetInputConnection(producer(image({"elevation": bowl})))
rr.SetRainRate(200.0)
rr.SetBoundary(1)
rr.SetEndTime(120.0)
rr.SetOutputInterval(30.0)
ws = vtkWaterSurfaceFilter()
ws.SetInputConnection(rr.GetOutputPort())
ws.SetEndTime(120.0)
ws.SetOutputInterval(30.0)
ws.SetWetDepth(0.003)
ws.SetDropRate(0.2)
ws.SetFollowInputTime(1)
errors = T.ErrorCatcher(ws)
wet_counts = []
for t in (30.0, 60.0, 120.0):
    _, out = at(ws, t)
    wet_counts.append(field(out, "wet_points") if out.GetNumberOfPoints() else -1)
T.check(not errors.messages, "Rain Runoff -> Water Surface runs: %r" % errors.text())
# Each output holds the water of the input's time step before it (sample and
# hold): at 30 s the water of 0 s (dry: no point moves, no error), later the
# pools that Rain Runoff has gathered.
T.check(wet_counts[0] == 0 and 0 < wet_counts[1] < wet_counts[2],
        "the water follows Rain Runoff's pooling: wet points %r" % wet_counts)
rdepth = vtk_to_numpy(out.GetPointData().GetArray("water_depth"))
rr.UpdateTimeStep(90.0)
rr_depth = vtk_to_numpy(rr.GetOutput().GetPointData().GetArray("water_depth"))
T.check(np.array_equal(rdepth, rr_depth),
        "at 120 s the water is Rain Runoff's of 90 s (its time step that holds over 90..120 s)")
# Revisits with a checkpoint at every output: a time whose checkpoint is
# restored shows the water held over the advance into it, not the last one
# read, and time 0 (a reset) the water of 0 s (both showed a later water).


def followed(**kw):
    up = vtkRainRunoffFilter()
    up.SetInputConnection(producer(image({"elevation": bowl})))
    up.SetRainRate(200.0)
    up.SetBoundary(1)
    up.SetEndTime(120.0)
    up.SetOutputInterval(30.0)
    _keep.append(up)
    f = vtkWaterSurfaceFilter()
    f.SetInputConnection(up.GetOutputPort())
    f.SetEndTime(120.0)
    f.SetOutputInterval(15.0)
    f.SetWetDepth(0.003)
    f.SetDropRate(0.2)
    f.SetFollowInputTime(1)
    for k, v in kw.items():
        getattr(f, "Set" + k)(v)
    return f


forward = {t: T.digest_all(followed(), t) for t in (0.0, 60.0, 90.0, 105.0)}
back = followed(CheckpointInterval=1)
revisits = [(t, T.digest_all(back, t) == forward[t]) for t in (105.0, 60.0, 90.0, 0.0, 105.0)]
T.check(all(ok for _, ok in revisits) and back.GetRestoreCount() >= 2,
        "followed water: revisits equal the forward run bit for bit %r (restores %d)"
        % (revisits, back.GetRestoreCount()))

# ---- bad input: one sentence, an empty output, the next good update works --------
bad = water({"elevation": bowl, "water_depth": np.zeros_like(bowl)}, UseLakeLevel=0)
errors = T.ErrorCatcher(bad)
h, out = at(bad, 1.0)
T.check(h is None and len(errors.messages) == 1 and "WetDepth" in errors.text(),
        "no wet point: one sentence, empty output: %r" % errors.text())
nowater = water({"elevation": bowl})
errors = T.ErrorCatcher(nowater)
h, out = at(nowater, 1.0)
T.check(h is None and len(errors.messages) == 1 and "no water" in errors.text()
        and "UseLakeLevel" in errors.text(),
        "no water_depth and no LakeLevel: one sentence, empty output: %r" % errors.text())
errors.clear()
h, out = at(nowater, 1.0)
T.check(h is None and not errors.messages, "the same request is not retried nor reported again")
nowater.SetUseLakeLevel(1)
nowater.SetLakeLevel(1.0)
h, out = at(nowater, 1.0)
T.check(h is not None and not errors.messages, "with a lake the next update works")
nan = bowl.copy()
nan[3, 5] = np.nan
bad = water({"elevation": nan}, UseLakeLevel=1, LakeLevel=1.0)
errors = T.ErrorCatcher(bad)
h, out = at(bad, 1.0)
T.check(h is None and len(errors.messages) == 1 and "NaN" in errors.text(),
        "NaN elevation: one sentence, empty output: %r" % errors.text())
slow = water({"elevation": bowl}, UseLakeLevel=1, LakeLevel=1.0)
slow.SetWaveSpeed(0.0)
T.check(slow.GetWaveSpeed() == 0.0, "WaveSpeed 0 is kept (the open end), to be refused")
errors = T.ErrorCatcher(slow)
h, out = at(slow, 1.0)
T.check(h is None and len(errors.messages) == 1 and "WaveSpeed" in errors.text(),
        "WaveSpeed 0: one sentence, empty output: %r" % errors.text())
slow.SetWaveSpeed(1.5)
h, out = at(slow, 1.0)
T.check(h is not None and len(errors.messages) == 1, "a good WaveSpeed works again")
print("\n".join(errors.messages))

# ---- the ParaView proxy -------------------------------------------------------------
plugin = a.plugin
if plugin is None:
    import graupel

    lib = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(graupel.__file__))))
    found = glob.glob(os.path.join(lib, "paraview-*", "plugins", "Graupel", "Graupel.so"))
    plugin = found[0] if found else None
if plugin is not None:
    from paraview import servermanager  # noqa: E402
    from paraview import simple as pv  # noqa: E402

    px = globals()
    pv.LoadPlugin(plugin, ns=px)
    proto = servermanager.ProxyManager().GetPrototypeProxy("filters", "WaterSurface")
    T.check(proto is not None, "proxy WaterSurface is registered")
    units = {"WaveSpeed": "m/s", "Damping": "1/s", "WetDepth": "Metres", "LakeLevel": "Metres",
             "DropAmplitude": "Metres", "DropRadius": "Metres", "DropRate": "Raindrops per"}
    for prop, unit in units.items():
        doc = proto.GetProperty(prop).GetDocumentation().GetDescription()
        T.check(doc.strip().startswith(unit), "WaterSurface.%s documents its unit: %r" % (prop, doc))
    hint = proto.GetHints().FindNestedElementByName("RepresentationType")
    T.check(hint is not None and hint.GetAttribute("type") == "Surface", "shows as a surface")
    terrain = px["ProceduralTerrain"](Dimensions=[64, 64])
    terrain.UpdatePipeline()
    lo, hi = terrain.PointData["elevation"].GetRange()
    wsp = px["WaterSurface"](Input=terrain, UseLakeLevel=1, LakeLevel=lo + 0.4 * (hi - lo))
    T.check(wsp.EndTime == 60.0 and wsp.OutputInterval == 0.5, "the proxy's time defaults")
    wsp.UpdatePipeline(5.0)
    T.check(all(k in wsp.PointData.keys() for k in ("wave_height", "water_surface", "normal",
                                                     "wet", "elevation", "water_depth")),
            "WaterSurface arrays %r" % wsp.PointData.keys())
    view = pv.CreateRenderView()
    rep = pv.Show(wsp, view)
    T.check(rep.Representation == "Surface", "shown as %r" % rep.Representation)
    # The water look docs/Scenes.md describes: physically based shading, low
    # roughness, one teal colour, lit by the water's own normals.
    pv.ColorBy(rep, None)
    rep.DiffuseColor = [0.05, 0.35, 0.4]
    rep.Interpolation = "PBR"
    rep.Roughness = 0.08
    rep.Metallic = 0.0
    T.check(rep.Interpolation == "PBR" and abs(rep.Roughness - 0.08) < 1e-9,
            "PBR interpolation and roughness are accepted")
    view.UseEnvironmentLighting = 1
    T.check(view.UseEnvironmentLighting == 1, "the view lights by its environment")
    pv.Render(view)
else:
    print("no ParaView plugin beside the module: proxy checks skipped (plain VTK)")

T.finish()
