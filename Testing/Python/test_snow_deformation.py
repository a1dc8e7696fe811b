"""vtkSnowDeformationFilter in a pipeline (pvpython in the plugin build, plain
python3 on Debian's VTK): a sphere pressed into and dragged across a flat
64 x 64 snow field. Checks the mass ledger, the spherical-cap hole the
imprint leaves, the rim and the front bulge, results bit-identical whatever
the order of requested times (and with checkpoints), the field data, the
objects' output posed at the output time with its force and contact area,
multiblock objects with a per-block velocity, a Path, a wheel rolling along a
curved Path, the resistance against speed and density, the density presets,
the time defaults (and, under pvpython, the proxies' own), and bad input (an
open mesh, an object outside the grid, a missing or NaN elevation, a
mismatched array, a path without speed, a backwards DensityRange): one
sentence, an empty output, and the next good update works."""
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args()

from vtkmodules.util.numpy_support import vtk_to_numpy, numpy_to_vtk  # noqa: E402
from vtkmodules.vtkCommonCore import vtkDoubleArray, vtkPoints  # noqa: E402
from vtkmodules.vtkCommonDataModel import (  # noqa: E402
    vtkCellArray,
    vtkImageData,
    vtkMultiBlockDataSet,
    vtkPolyData,
)
from vtkmodules.vtkCommonExecutionModel import (  # noqa: E402
    vtkStreamingDemandDrivenPipeline as SDDP,
    vtkTrivialProducer,
)
from vtkmodules.vtkFiltersSources import (  # noqa: E402
    vtkCubeSource,
    vtkCylinderSource,
    vtkPlaneSource,
    vtkSphereSource,
)

from graupel import vtkSnowDeformationFilter  # noqa: E402

N, DX = 64, 0.05  # a 3.15 m square of snow
DEPTH, RHO = 0.5, 150.0
_keep = []  # a vtkAlgorithmOutput does not keep its producer alive


def producer(data):
    p = vtkTrivialProducer()
    p.SetOutput(data)
    _keep.append(p)
    return p.GetOutputPort()


def terrain(arrays=None):
    img = vtkImageData()
    img.SetDimensions(N, N, 1)
    img.SetSpacing(DX, DX, 1.0)
    img.SetOrigin(0.0, 0.0, 0.0)
    if arrays is None:
        arrays = {"elevation": np.zeros((N, N))}
    for name, values in arrays.items():
        arr = numpy_to_vtk(np.ascontiguousarray(values, dtype=np.float32).reshape(-1), deep=1)
        arr.SetName(name)
        img.GetPointData().AddArray(arr)
    return img


def sphere(centre, radius, res=32):
    s = vtkSphereSource()
    s.SetCenter(*centre)
    s.SetRadius(radius)
    s.SetThetaResolution(res)
    s.SetPhiResolution(res)
    s.Update()
    out = vtkPolyData()
    out.DeepCopy(s.GetOutput())
    return out


def snow(objects, ground=None, **kw):
    f = vtkSnowDeformationFilter()
    f.SetInputConnection(producer(terrain(ground)))
    if objects is not None:
        f.SetObjectsConnection(producer(objects))
    f.SetEndTime(kw.pop("EndTime", 1.0))
    f.SetOutputInterval(kw.pop("OutputInterval", 0.25))
    for k, v in kw.items():
        getattr(f, "Set" + k)(*(v if isinstance(v, tuple) else (v,)))
    return f


def at(f, t):
    f.UpdateTimeStep(t)
    out = f.GetOutput()
    if out.GetNumberOfPoints() == 0:
        return None, out
    surf = vtk_to_numpy(out.GetPointData().GetArray("snow_surface")).reshape(N, N).copy()
    return surf, out


def field(data, name):
    arr = data.GetFieldData().GetArray(name)
    return None if arr is None else arr.GetTuple(0)[0]


def centre_of(data):
    b = data.GetBounds()
    return np.array([(b[0] + b[1]) / 2, (b[2] + b[3]) / 2, (b[4] + b[5]) / 2])


j, i = np.mgrid[0:N, 0:N]
X, Y = i * DX, j * DX
AREA = N * N * DX * DX

# ---- defaults -------------------------------------------------------------------
f = vtkSnowDeformationFilter()
T.check(abs(f.GetTimeStep() - 1.0 / 60.0) < 1e-15 and f.GetInitialSnowDepth() == DEPTH
        and f.GetInitialDensity() == RHO, "defaults TimeStep 1/60 s, 0.5 m, 150 kg/m^3")
T.check((f.GetMinDensity(), f.GetMaxDensity(), f.GetCompressionModel()) == (100.0, 400.0, 0),
        "defaults DensityRange 100-400 kg/m^3, density-driven compression")
T.check(f.GetMaxSlope() == 0.6 and f.GetDirectionFalloff() == 8.0, "defaults MaxSlope, K")
f.SetMaxSlope(1e9)
T.check(f.GetMaxSlope() == 100.0, "MaxSlope clamps to the table's 100: %r" % f.GetMaxSlope())
# Steps of 1/60 s want seconds, not Rain Runoff's minutes: the class's own
# time defaults, which ParaView's proxy takes (checked below under pvpython).
T.check((f.GetEndTime(), f.GetOutputInterval()) == (10.0, 0.25)
        and (f.GetDefaultEndTime(), f.GetDefaultOutputInterval()) == (10.0, 0.25),
        "time defaults EndTime 10 s, OutputInterval 0.25 s: %r"
        % ((f.GetEndTime(), f.GetOutputInterval()),))

# ---- density presets: the thesis' Table 3.1 (kg/m^3), and sand -------------------
TABLE_3_1 = {1: (30, 50), 2: (50, 100), 3: (100, 200), 4: (200, 400), 5: (300, 500),
             6: (150, 300), 7: (500, 800), 8: (800, 900)}
for k, want in TABLE_3_1.items():
    r = [0.0, 0.0]
    ok = vtkSnowDeformationFilter.GetDensityPresetRange(k, r)
    T.check(ok and tuple(r) == want, "preset %d is Table 3.1's %r: %r" % (k, want, r))
r = [0.0, 0.0]
T.check(vtkSnowDeformationFilter.GetDensityPresetRange(vtkSnowDeformationFilter.SAND, r)
        and r[0] > 900.0 and r[1] / r[0] < 1.2,
        "sand: denser than ice, close ends (little compression): %r" % r)
T.check(not vtkSnowDeformationFilter.GetDensityPresetRange(0, [0.0, 0.0]),
        "Custom has no preset range")
f.SetDensityRange(120.0, 350.0)
f.SetInitialDensity(140.0)
f.SetDensityPreset(vtkSnowDeformationFilter.FIRN)
r = [0.0, 0.0]
f.GetDensityRangeInUse(r)
T.check(tuple(r) == (500.0, 800.0) and f.GetInitialDensityInUse() == 500.0,
        "Firn sets the range 500-800 and the initial density 500: %r %r"
        % (r, f.GetInitialDensityInUse()))
f.SetDensityPreset(vtkSnowDeformationFilter.CUSTOM)
f.GetDensityRangeInUse(r)
T.check(tuple(r) == (120.0, 350.0) and f.GetInitialDensityInUse() == 140.0
        and (f.GetMinDensity(), f.GetMaxDensity()) == (120.0, 350.0),
        "back to Custom, the custom range and density are kept: %r" % r)
f.SetDensityPreset(42)
T.check(f.GetDensityPreset() == vtkSnowDeformationFilter.SAND, "DensityPreset clamps to Sand")

# ---- the proxies (pvpython with the plugin) ------------------------------------
# The plugin lies beside the module in the build tree (or comes as --plugin);
# plain python3 on Debian's VTK has no ParaView and skips this.
plugin = a.plugin
if plugin is None:
    import glob  # noqa: E402
    import graupel  # noqa: E402
    lib = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(graupel.__file__))))
    found = glob.glob(os.path.join(lib, "paraview-*", "plugins", "Graupel", "Graupel.so"))
    plugin = found[0] if found else None
if plugin is not None:
    from paraview import simple as pv  # noqa: E402
    from graupel import vtkRainRunoffFilter  # noqa: E402

    px = globals()  # where LoadPlugin puts the plugin's proxies
    pv.LoadPlugin(plugin, ns=px)
    ground = px["ProceduralTerrain"](Dimensions=[8, 8])
    sd, rr = px["SnowDeformation"](Input=ground), px["RainRunoff"](Input=ground)
    vs, vr = vtkSnowDeformationFilter(), vtkRainRunoffFilter()
    T.check((sd.EndTime, sd.OutputInterval) == (vs.GetEndTime(), vs.GetOutputInterval())
            and (rr.EndTime, rr.OutputInterval) == (vr.GetEndTime(), vr.GetOutputInterval())
            and sd.EndTime != rr.EndTime and sd.OutputInterval != rr.OutputInterval,
            "proxy time defaults are each class's: Snow Deformation %r, Rain Runoff %r"
            % ((sd.EndTime, sd.OutputInterval), (rr.EndTime, rr.OutputInterval)))
    sd2 = px["SnowDeformation"](Input=ground, EndTime=3.0)
    T.check((sd2.EndTime, sd2.OutputInterval) == (3.0, 0.25), "a given EndTime is kept")
    T.check(list(sd.DensityRange) == [100.0, 400.0] and sd.DensityPreset == "Custom",
            "proxy DensityRange 100 400, DensityPreset Custom")
    sd.DensityRange = [120.0, 350.0]
    sd.DensityPreset = "Dry old snow"
    sd.UpdateVTKObjects()
    obj = sd.GetClientSideObject()
    obj.GetDensityRangeInUse(r)
    T.check(tuple(r) == (200.0, 400.0), "proxy preset Dry old snow: range in use %r" % r)
    sd.DensityPreset = "Custom"
    sd.UpdateVTKObjects()
    obj.GetDensityRangeInUse(r)
    T.check(tuple(r) == (120.0, 350.0), "proxy back to Custom keeps 120 350: %r" % r)
    for p in (sd, sd2, rr, ground):
        pv.Delete(p)
else:
    print("no ParaView plugin beside the module: proxy checks skipped (plain VTK)")

# ---- a sphere pressed straight down ------------------------------------------------
# Radius 0.4 m, its bottom starting at 0.4 m (0.1 m into the 0.5 m snow) and
# going down at 0.25 m/s: at 1 s the bottom is at 0.15 m.
R, Z0, VZ = 0.4, 0.8, -0.25
C = (1.6, 1.6)
press = lambda **kw: snow(sphere((C[0], C[1], Z0), R), ObjectVelocity=(0.0, 0.0, VZ), **kw)  # noqa
f = press()
f.UpdateInformation()
info = f.GetOutputInformation(0)
steps = [info.Get(SDDP.TIME_STEPS(), k) for k in range(info.Length(SDDP.TIME_STEPS()))]
T.check(steps == [0.0, 0.25, 0.5, 0.75, 1.0], "TIME_STEPS every 0.25 s: %r" % steps)
info1 = f.GetOutputInformation(1)
T.check(info1.Length(SDDP.TIME_STEPS()) == 5, "the objects' port advertises the same times")

s0, out = at(f, 0.0)
T.check(s0 is not None and np.allclose(s0, DEPTH), "t = 0: flat snow of 0.5 m")
s1, out = at(f, 1.0)
T.check(s1 is not None, "the pressed sphere gives an output")
names = [out.GetPointData().GetArrayName(k) for k in range(out.GetPointData().GetNumberOfArrays())]
for n in ("snow_depth", "snow_surface", "snow_density", "overlap", "contact", "elevation"):
    T.check(n in names, "output array %s" % n)
for n in ("time", "snow_volume", "snow_mass", "compressed_volume", "displaced_volume",
          "balance_error"):
    T.check(field(out, n) is not None, "field data %s" % n)
T.near(field(out, "time"), 1.0, 1e-12, "field data time")
T.check(field(out, "steps") == 60, "60 steps of 1/60 s: %r" % field(out, "steps"))
mass0 = DEPTH * RHO * AREA
T.near(field(out, "snow_mass"), mass0, 1e-5 * mass0, "snow mass kept")
T.check(abs(field(out, "balance_error")) <= 1e-5 * mass0,
        "balance_error %g kg within 1e-5 of %g kg" % (field(out, "balance_error"), mass0))
vol = field(out, "snow_volume")
T.check(field(out, "compressed_volume") > 0.0 and field(out, "displaced_volume") > 0.0,
        "snow was compressed (%g m^3) and displaced (%g m^3)"
        % (field(out, "compressed_volume"), field(out, "displaced_volume")))
T.near(vol + field(out, "compressed_volume"), DEPTH * AREA, 1e-5 * DEPTH * AREA,
       "volume ledger: snow_volume + compressed_volume = initial volume")
dens = vtk_to_numpy(out.GetPointData().GetArray("snow_density")).reshape(N, N)
depth = vtk_to_numpy(out.GetPointData().GetArray("snow_depth")).reshape(N, N)
T.near(float((depth * dens).sum() * DX * DX), mass0, 1e-5 * mass0, "sum depth rho area = mass")
T.check(float(dens.max()) > RHO and float(dens.max()) <= 400.0 + 1e-3,
        "snow under the sphere compressed, never past MaxDensity: %g" % dens.max())

# The hole: where the sphere's footprint reaches 80 % of its radius, the
# surface is the spherical cap (the 32 x 32 facets lie within 2 mm inside it).
zc = Z0 + VZ * 1.0
rho2 = (X - C[0]) ** 2 + (Y - C[1]) ** 2
inner = rho2 < (0.8 * R) ** 2
cap = zc - np.sqrt(np.maximum(R * R - rho2, 0.0))
err = np.abs(s1 - cap)[inner]
T.check(float(err.max()) <= 0.004, "the hole is the spherical cap within 4 mm: %.4f m" % err.max())
T.check(abs(float(s1[32, 32]) - (zc - R)) <= 0.004, "the hole's bottom at %.3f m: %.4f m"
        % (zc - R, s1[32, 32]))
contact = vtk_to_numpy(out.GetPointData().GetArray("contact")).reshape(N, N)
T.check(bool(contact[inner].all()) and float(contact[rho2 > (1.2 * R) ** 2].max()) == 0.0,
        "contact 1 under the sphere, 0 beyond it")
ring = (rho2 > (1.05 * R) ** 2) & (rho2 < (1.6 * R) ** 2)
T.check(float(s1[ring].max()) > DEPTH + 0.01, "a rim round the hole: %.3f m > 0.51 m"
        % s1[ring].max())
T.check(float(s1[rho2 > (2.5 * R) ** 2].max()) <= DEPTH + 1e-6, "far snow untouched")

# The objects' output: the sphere where it is at 1 s, with the snow's resistance.
obj = f.GetOutputDataObject(1)
T.check(obj.IsA("vtkPolyData") and obj.GetNumberOfPoints() > 0, "port 1 holds the sphere")
T.check(np.allclose(centre_of(obj), (C[0], C[1], zc), atol=1e-6),
        "port 1 posed at the output time: %r" % (centre_of(obj),))
force = obj.GetFieldData().GetArray("force")
T.check(force is not None and force.GetNumberOfComponents() == 3 and force.GetTuple3(0)[2] > 0.0,
        "the force pushes up against a sphere going down: %r" % (force.GetTuple3(0),))
T.check(field(obj, "contact_area") > 0.5 * math.pi * (0.8 * R) ** 2,
        "contact_area %g m^2" % field(obj, "contact_area"))
T.check(obj.GetInformation().Get(obj.DATA_TIME_STEP()) == 1.0, "port 1 stamped with 1 s")

# Port 1 asked for alone, at another time.
g = press()
g.UpdateInformation()
g.GetOutputInformation(1).Set(SDDP.UPDATE_TIME_STEP(), 0.5)
g.Update(1)
T.check(np.allclose(centre_of(g.GetOutputDataObject(1)), (C[0], C[1], Z0 + VZ * 0.5), atol=1e-6),
        "port 1 alone at 0.5 s: %r" % (centre_of(g.GetOutputDataObject(1)),))

# ---- order of requests and checkpoints: identical bits ----------------------------
ref = {t: at(f, t)[0] for t in (0.0, 0.25, 0.5, 0.75, 1.0)}
mixed = press(CheckpointInterval=0)
same = True
for t in (0.75, 0.25, 1.0, 0.0, 0.5, 0.5):
    s, _ = at(mixed, t)
    same = same and s is not None and np.array_equal(s, ref[t])
T.check(same, "every time equals the forward run bit for bit, whatever the order")
ck = press(CheckpointInterval=2)
at(ck, 1.0)
s, _ = at(ck, 0.75)
T.check(np.array_equal(s, ref[0.75]) and ck.GetRestoreCount() == 1,
        "back to 0.75 s from the 0.5 s checkpoint gives the same bits (restores %d)"
        % ck.GetRestoreCount())
T.check(not np.array_equal(ref[0.5], ref[1.0]), "the snow does change in time")

# ---- progress, and an abort inside an interval -----------------------------------
pr = press(OutputInterval=1.0, TimeStep=0.004)
texts = []
pr.AddObserver("ProgressEvent", lambda o, e: texts.append((o.GetProgressText(), o.GetProgress())))
full, _ = at(pr, 1.0)
inside = [t for t, p in texts if 0.0 < p < 1.0]
T.check(len(inside) > 0 and all(t.startswith("Snow Deformation: t = ") and t.endswith(" s of 1 s")
                                for t in inside), "progress inside the interval: %r" % inside[:3])
ab = press(OutputInterval=1.0, TimeStep=0.004)
abort = T.AbortOnce(ab)
warns = T.ErrorCatcher(ab, event="WarningEvent")
s, _ = at(ab, 1.0)
T.check(abort.hits == 1 and s is None and "aborted" in warns.text(),
        "an abort inside the interval leaves an empty output: %r" % warns.text()[:200])
abort.remove()
s, _ = at(ab, 1.0)
T.check(s is not None and np.array_equal(s, full), "the next update gives the same bits")

# ---- a sphere dragged across: a trench, a bulge ahead, the force against it -------
r2 = 0.3
drag = snow(sphere((0.8, 1.6, 0.5), r2), ObjectVelocity=(1.0, 0.0, 0.0))
s, out = at(drag, 1.0)
T.check(s is not None, "the dragged sphere gives an output")
T.check(abs(field(out, "balance_error")) <= 1e-5 * mass0,
        "dragging keeps the mass: %g kg" % field(out, "balance_error"))
trench = s[32, int(1.2 / DX)]
T.check(trench < DEPTH - 0.1, "a trench behind the sphere: %.3f m" % trench)
ahead = s[24:41, int(2.1 / DX):int(2.4 / DX)].max()
behind = s[24:41, : int(0.4 / DX)].max()
T.check(ahead > DEPTH + 0.02 and behind <= DEPTH + 1e-6,
        "a bulge ahead (%.3f m) and nothing pushed behind the start (%.3f m)" % (ahead, behind))
obj = drag.GetOutputDataObject(1)
T.check(np.allclose(centre_of(obj), (1.8, 1.6, 0.5), atol=1e-6), "the sphere ends at x = 1.8 m")
fx = obj.GetFieldData().GetArray("force").GetTuple3(0)[0]
T.check(fx < 0.0, "the resistance opposes the motion: Fx = %g N" % fx)

# ---- a multiblock of two objects, one held by its block's velocity ----------------
mb = vtkMultiBlockDataSet()
mb.SetBlock(0, sphere((0.8, 1.0, 0.5), 0.25, 16))
still = sphere((2.2, 2.2, 0.6), 0.25, 16)
v = vtkDoubleArray()
v.SetName("velocity")
v.SetNumberOfComponents(3)
v.InsertNextTuple3(0.0, 0.0, 0.0)
still.GetFieldData().AddArray(v)
mb.SetBlock(1, still)
mb.SetBlock(2, vtkPolyData())  # an empty block is no object
two = snow(mb, ObjectVelocity=(1.0, 0.0, 0.0))
s, out = at(two, 0.5)
o = two.GetOutputDataObject(1)
T.check(s is not None and o.IsA("vtkMultiBlockDataSet") and o.GetNumberOfBlocks() == 3,
        "port 1 is a multiblock of the input's structure")
if o.IsA("vtkMultiBlockDataSet") and o.GetNumberOfBlocks() == 3:
    T.check(np.allclose(centre_of(o.GetBlock(0)), (1.3, 1.0, 0.5), atol=1e-6)
            and np.allclose(centre_of(o.GetBlock(1)), (2.2, 2.2, 0.6), atol=1e-6),
            "block 0 moved by ObjectVelocity, block 1 held by its own velocity")
    T.check(all(o.GetBlock(k).GetFieldData().GetArray("force") is not None for k in (0, 1)),
            "each block has its force")
    T.check(field(o.GetBlock(1), "contact_area") > 0.0, "the resting sphere touches the snow")
    T.check(o.GetBlock(2) is None or o.GetBlock(2).GetNumberOfPoints() == 0, "block 2 stays empty")
    T.check(field(o, "contact_area") == field(o.GetBlock(0), "contact_area")
            + field(o.GetBlock(1), "contact_area"), "the multiblock's contact_area is the sum")

# ---- a box (corners repeated per face: merged) turning about z --------------------
box = vtkCubeSource()
box.SetCenter(1.6, 1.6, 0.55)
box.SetXLength(1.0)
box.SetYLength(0.2)
box.SetZLength(0.2)  # 0.05 m into the snow
turn = snow(None, ObjectAngularVelocity=90.0, RotationAxis=(0.0, 0.0, 1.0))
turn.SetObjectsConnection(box.GetOutputPort())
s, out = at(turn, 1.0)
obj = turn.GetOutputDataObject(1)
b = obj.GetBounds() if obj.GetNumberOfPoints() else (0,) * 6
T.check(s is not None and abs(b[1] - b[0] - 0.2) < 1e-6 and abs(b[3] - b[2] - 1.0) < 1e-6,
        "the box turned a quarter about z: bounds %r" % (b,))
if s is not None:
    T.check(s[32, 32] < DEPTH - 0.04 and s[int(2.0 / DX), 32] < DEPTH - 0.04
            and s[int(1.2 / DX), 32] < DEPTH - 0.04,
            "its imprint lies along y at 1 s: %.3f %.3f %.3f"
            % (s[32, 32], s[int(2.0 / DX), 32], s[int(1.2 / DX), 32]))

# ---- a path: the sphere follows it at |ObjectVelocity| ----------------------------
pts = vtkPoints()
for p in ((0.8, 0.8, 0.5), (1.6, 0.8, 0.5), (1.6, 2.4, 0.5)):
    pts.InsertNextPoint(*p)
line = vtkCellArray()
line.InsertNextCell(3)
for k in range(3):
    line.InsertCellPoint(k)
path = vtkPolyData()
path.SetPoints(pts)
path.SetLines(line)
pf = snow(sphere((0.0, 0.0, 0.0), 0.25, 16), ObjectVelocity=(0.0, 2.0, 0.0))
pf.SetPathConnection(producer(path))
s, out = at(pf, 1.0)  # 2 m along: 0.8 m east, then 1.2 m north
obj = pf.GetOutputDataObject(1)
T.check(s is not None and np.allclose(centre_of(obj), (1.6, 2.0, 0.5), atol=1e-3),
        "the sphere follows the path to (1.6, 2.0): %r" % (centre_of(obj),))
T.check(s is not None and s[int(0.8 / DX), int(1.2 / DX)] < DEPTH - 0.1
        and s[int(1.4 / DX), int(1.6 / DX)] < DEPTH - 0.1, "a trench along both legs")

# ---- a preset in a pipeline: the snow starts at its loose end, stays in its range --
ps = press(DensityPreset=vtkSnowDeformationFilter.DRY_OLD_SNOW, DensityRange=(120.0, 350.0),
           OutputInterval=1.0)
s, out = at(ps, 0.0)
d0 = vtk_to_numpy(out.GetPointData().GetArray("snow_density")) if s is not None else None
T.check(d0 is not None and float(d0.min()) == 200.0 and float(d0.max()) == 200.0,
        "Dry old snow starts at 200 kg/m^3 everywhere")
s, out = at(ps, 1.0)
d1 = vtk_to_numpy(out.GetPointData().GetArray("snow_density")) if s is not None else None
T.check(d1 is not None and 200.0 < float(d1.max()) <= 400.0 + 1e-3,
        "pressed Dry old snow compresses within 200-400: max %r"
        % (None if d1 is None else float(d1.max())))
T.check(s is not None and abs(field(out, "balance_error")) <= 1e-5 * DEPTH * 200.0 * AREA,
        "the preset run keeps the mass")
cu = press(DensityRange=(120.0, 350.0), OutputInterval=1.0)
s, out = at(cu, 1.0)
d1 = vtk_to_numpy(out.GetPointData().GetArray("snow_density")) if s is not None else None
T.check(d1 is not None and float(d1.min()) == RHO and RHO < float(d1.max()) <= 350.0 + 1e-3,
        "a custom 120-350 is the range in force: density from-to %r"
        % ((None if d1 is None else (float(d1.min()), float(d1.max()))),))


# ---- resistance: grows with speed and density, zero without contact --------------
# A sphere 0.3 m into the snow, dragged from x = 0.8 m; the force is the mean
# over the output interval 0.25-0.5 s, when it ploughs (the first interval
# holds the imprint made at the start): F = -m v / dt with m the snow moved in
# a step, about rho A v^2 for a frontal area A.
def resistance(speed, rho=RHO, z=0.5):
    g = snow(sphere((0.8, 1.6, z), 0.3, 16), ObjectVelocity=(speed, 0.0, 0.0),
             InitialDensity=rho, EndTime=0.5, OutputInterval=0.25)
    s, _ = at(g, 0.5)
    o = g.GetOutputDataObject(1)
    fd = o.GetFieldData()
    fa = fd.GetArray("force")
    return (s, fa.GetTuple3(0) if fa else None, field(o, "contact_area"))


_, f_slow, _ = resistance(0.5)
_, f_fast, _ = resistance(1.0)
_, f_dense, _ = resistance(1.0, rho=300.0)
print("resistance Fx: 0.5 m/s %.4g N, 1 m/s %.4g N, 1 m/s at 300 kg/m^3 %.4g N"
      % (f_slow[0], f_fast[0], f_dense[0]))
T.check(f_slow[0] < 0.0 and f_fast[0] < 0.0 and f_dense[0] < 0.0, "the resistance opposes x")
T.check(3.0 < f_fast[0] / f_slow[0] < 5.0,
        "twice the speed, about four times the resistance (v^2): %.4g vs %.4g N"
        % (f_fast[0], f_slow[0]))
T.check(f_dense[0] / f_fast[0] > 1.8,
        "twice the density, at least 1.8 times the resistance: %.4g vs %.4g N"
        % (f_dense[0], f_fast[0]))
s, f_air, area_air = resistance(1.0, z=0.85)  # its bottom 5 cm above the snow
T.check(f_air == (0.0, 0.0, 0.0) and area_air == 0.0 and s is not None
        and float(np.abs(s - DEPTH).max()) == 0.0,
        "no contact: no force (%r), no contact_area (%r), snow untouched" % (f_air, area_air))

# ---- a wheel rolling along a curved path leaves a curved trench ------------------
# A cylinder (radius 0.25 m, 0.2 m wide, its axle along y: rolling along its
# +x, which the path turns along the tangent) rolls at 2 m/s, 458 deg/s, on
# an arc of radius 1.1 m about (1.6, 0.4) from 160 degrees on; in 1 s it goes
# 2 m, to 55.8 degrees. Its bottom is 0.1 m into the snow.
AC, AR, WR = np.array([1.6, 0.4]), 1.1, 0.25
arc = vtkPoints()
angles = np.radians(np.arange(160.0, 19.0, -5.0))
for th in angles:
    arc.InsertNextPoint(AC[0] + AR * math.cos(th), AC[1] + AR * math.sin(th), 0.5 - 0.1 + WR)
arc_line = vtkCellArray()
arc_line.InsertNextCell(len(angles))
for k in range(len(angles)):
    arc_line.InsertCellPoint(k)
arc_path = vtkPolyData()
arc_path.SetPoints(arc)
arc_path.SetLines(arc_line)
cyl = vtkCylinderSource()
cyl.SetRadius(WR)
cyl.SetHeight(0.2)
cyl.SetResolution(24)
cyl.Update()
wheel = snow(cyl.GetOutput(), ObjectVelocity=(2.0, 0.0, 0.0),
             ObjectAngularVelocity=2.0 / WR * 180.0 / math.pi, RotationAxis=(0.0, 1.0, 0.0),
             OutputInterval=1.0)
wheel.SetPathConnection(producer(arc_path))
s, out = at(wheel, 1.0)
T.check(s is not None, "the wheel on the arc gives an output")
if s is not None:
    worst = 0.0
    for deg in (150.0, 135.0, 120.0, 105.0, 90.0, 75.0):
        th = math.radians(deg)
        rs = np.arange(0.6, 1.6, 0.005)
        ii = np.rint((AC[0] + rs * math.cos(th)) / DX).astype(int)
        jj = np.rint((AC[1] + rs * math.sin(th)) / DX).astype(int)
        h = s[jj, ii]
        bottom = rs[h <= h.min() + 1e-3].mean()
        worst = max(worst, abs(bottom - AR))
        T.check(h.min() < DEPTH - 0.05, "a trench at %g degrees: %.3f m" % (deg, h.min()))
    print("wheel trench: deepest points within %.3f m of the arc" % worst)
    T.check(worst <= 2 * DX, "across the path, the trench's deepest point lies within two "
            "cells of the arc: %.3f m" % worst)
    T.check(abs(field(out, "balance_error")) <= 1e-5 * mass0, "the wheel keeps the mass")
    obj = wheel.GetOutputDataObject(1)
    th = math.radians(160.0) - 2.0 / AR
    T.check(np.allclose(centre_of(obj)[:2], AC + AR * np.array([math.cos(th), math.sin(th)]),
                        atol=0.02), "the wheel ends 2 m along the arc: %r" % (centre_of(obj),))

# An object that starts off the grid and drives onto it is no error.
enter = snow(sphere((-0.5, 1.6, 0.5), 0.3, 16), ObjectVelocity=(2.0, 0.0, 0.0),
             EndTime=0.5, OutputInterval=0.5)
s, _ = at(enter, 0.5)
T.check(s is not None and float(s.min()) < DEPTH - 0.1,
        "a sphere driving onto the grid from outside is simulated")

# ---- objects with time steps: each step's geometry is the pose -------------------
from gr_timed import TimedSource  # noqa: E402


class SinkingSphere(TimedSource):
    """A sphere whose centre sits at Z0 + VZ t at the time steps 0, 0.25, ... 1 s."""

    TIMES = [0.0, 0.25, 0.5, 0.75, 1.0]

    def __init__(self):
        TimedSource.__init__(self, "vtkPolyData")

    def RequestData(self, request, inInfo, outInfo):
        t = self.requested_time(outInfo)
        out = vtkPolyData.GetData(outInfo)
        out.ShallowCopy(sphere((C[0], C[1], Z0 + VZ * t), R))
        out.GetInformation().Set(out.DATA_TIME_STEP(), t)
        return 1


src = SinkingSphere()
tf = vtkSnowDeformationFilter()
tf.SetInputConnection(producer(terrain()))
tf.SetObjectsConnection(src.GetOutputPort())
tf.SetEndTime(1.0)
tf.SetOutputInterval(0.25)
st, out = at(tf, 1.0)
T.check(st is not None and tf.IsInputTemporal(1), "objects with time steps are read in time")
T.check(sorted(set(src.requested)) == [0.0, 0.25, 0.5, 0.75],
        "each time step of the objects was read: %r" % (src.requested,))
obj = tf.GetOutputDataObject(1)
T.check(obj.GetNumberOfPoints() > 0 and obj.GetFieldData().GetArray("force") is not None,
        "port 1 holds the temporal sphere with its force")
# Sample and hold: over [0.75, 1] the sphere sits where it is at 0.75 s.
if st is not None:
    hold = Z0 + VZ * 0.75 - R
    T.check(abs(float(st[32, 32]) - hold) <= 0.004, "the hole's bottom at the held %.4f m: %.4f m"
            % (hold, st[32, 32]))
    T.check(abs(field(out, "balance_error")) <= 1e-5 * mass0, "temporal objects keep the mass")
    s2, _ = at(tf, 0.5)
    s3, _ = at(tf, 1.0)
    T.check(np.array_equal(s3, st), "temporal: back and forth gives the same bits")
# With a checkpoint at every output, a time restored from its own checkpoint
# showed the objects' time step at that time (0.5 s) instead of the one held
# over the interval before it (0.25 s): every output, objects included, must
# be the forward run's.
forward = {}
for t in (0.5, 1.0):
    one = vtkSnowDeformationFilter()
    one.SetInputConnection(producer(terrain()))
    _keep.append(SinkingSphere())
    one.SetObjectsConnection(_keep[-1].GetOutputPort())
    one.SetEndTime(1.0)
    one.SetOutputInterval(0.25)
    forward[t] = T.digest_all(one, t)
ck = vtkSnowDeformationFilter()
ck.SetInputConnection(producer(terrain()))
ck_src = SinkingSphere()
ck.SetObjectsConnection(ck_src.GetOutputPort())
ck.SetEndTime(1.0)
ck.SetOutputInterval(0.25)
ck.SetCheckpointInterval(1)
revisits = [(t, T.digest_all(ck, t) == forward[t]) for t in (1.0, 0.5, 1.0, 0.5)]
T.check(all(ok for _, ok in revisits) and ck.GetRestoreCount() >= 2,
        "temporal objects with checkpoints: revisits equal the forward run, objects included "
        "%r (restores %d)" % (revisits, ck.GetRestoreCount()))

# ---- bad input: one sentence, empty outputs, the next good update works ----------
plane = vtkPlaneSource()
plane.SetOrigin(1.0, 1.0, 0.3)
plane.SetPoint1(2.0, 1.0, 0.3)
plane.SetPoint2(1.0, 2.0, 0.3)
plane.Update()
nan_ground = np.zeros((N, N))
nan_ground[5, 7] = np.nan
cases = [
    ("open mesh", {"objects": plane.GetOutput()}, ["Objects", "open"]),
    # Two arrays, neither elevation nor the active scalars: nothing to take as heights.
    ("no elevation", {"ground": {"height": np.zeros((N, N)), "roughness": np.zeros((N, N))}},
     ["'elevation'", "Height Array"]),
    ("NaN elevation", {"ground": {"elevation": nan_ground}}, ["elevation"]),
    ("mismatched snow_depth", {"ground": {"elevation": np.zeros((N, N)),
                                          "snow_depth": np.zeros((N, N - 1))}}, ["snow_depth"]),
    ("zero-speed path", {"path": True}, ["Path", "ObjectVelocity"]),
    ("NaN TimeStep", {"props": {"TimeStep": float("nan")}}, ["TimeStep", " s"]),
    ("backwards DensityRange", {"props": {"DensityRange": (500.0, 400.0)}},
     ["DensityRange", "kg/m^3"]),
    ("InitialDensity outside DensityRange", {"props": {"InitialDensity": 50.0}},
     ["InitialDensity", "DensityRange"]),
    ("object outside the grid", {"objects": sphere((10.0, 10.0, 0.8), 0.3, 16)},
     ["Objects", "outside", "10", "grid x 0 to 3.15 m"]),
]
for what, case, words in cases:
    g = snow(case.get("objects", sphere((1.6, 1.6, 0.8), 0.3, 16)), case.get("ground"))
    if case.get("path"):
        g.SetPathConnection(producer(path))
    for k, v in case.get("props", {}).items():
        getattr(g, "Set" + k)(v)
    errs = T.ErrorCatcher(g)
    for t in (0.5, 0.5, 1.0):
        s, out = at(g, t)
    T.check(s is None and g.GetOutputDataObject(1).GetNumberOfPoints() == 0,
            "%s: empty outputs" % what)
    T.check(len(errs.messages) == 1 and all(w in errs.text() for w in words),
            "%s: one sentence naming %r: %r" % (what, words, errs.text()[:300]))
    # Fixed, the same filter works again.
    g.SetInputConnection(producer(terrain()))
    g.SetObjectsConnection(producer(sphere((C[0], C[1], Z0), R)))
    g.SetInputConnection(2, None)
    g.SetObjectVelocity(0.0, 0.0, VZ)
    g.SetTimeStep(1.0 / 60.0)
    g.SetDensityRange(100.0, 400.0)
    g.SetInitialDensity(RHO)
    s, _ = at(g, 1.0)
    T.check(s is not None and np.array_equal(s, ref[1.0]), "%s: fixed, it works again" % what)

T.finish()
