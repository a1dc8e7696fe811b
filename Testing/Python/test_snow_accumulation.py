"""vtkSnowAccumulationFilter in a pipeline (pvpython in the plugin build, plain
python3 on Debian's VTK): snow falling on a terrain with objects. Checks the
ledger (snowfall = stored + shed), exactly no snow under a box and a cap on
its top (the objects' output with snow_depth and snow_offset), the exposure
against an independent ray caster (vtkOBBTree) on a scene with a hut, trees
and rough terrain, the lee-side bare patch behind a wall under wind, the same
snow whatever the OutputInterval and TimeStep, results bit-identical whatever
the order of requested times, a moving object carrying its snow (also along a
curved Path, turned along its tangent), chaining into
Snow Deformation (its mass ledger starts from this filter's snow mass), the
accumulation textures of textured objects (port 2: rate x t in the open, 0
under a lid, the ledger untouched), the
defaults (and, under pvpython, the proxy's), and bad input (no or NaN
elevation, a degenerate direction, objects that are not polydata, an
ExposureResolution beyond the device, a Path at zero speed): one sentence,
empty outputs, and the next good update works."""
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args()

from vtkmodules.util.numpy_support import vtk_to_numpy, numpy_to_vtk  # noqa: E402
from vtkmodules.vtkCommonCore import vtkPoints  # noqa: E402
from vtkmodules.vtkCommonDataModel import (  # noqa: E402
    vtkCellArray,
    vtkImageData,
    vtkMultiBlockDataSet,
    vtkPolyData,
)
from vtkmodules.vtkCommonExecutionModel import vtkTrivialProducer  # noqa: E402
from vtkmodules.vtkFiltersGeneral import vtkOBBTree  # noqa: E402
from vtkmodules.vtkFiltersCore import vtkTriangleFilter  # noqa: E402
from vtkmodules.vtkFiltersSources import vtkConeSource, vtkCubeSource  # noqa: E402

from graupel import vtkSnowAccumulationFilter, vtkSnowDeformationFilter  # noqa: E402

N, DX = 48, 0.25  # a 11.75 m square
HOUR = 3600.0
_keep = []  # a vtkAlgorithmOutput does not keep its producer alive


def producer(data):
    p = vtkTrivialProducer()
    p.SetOutput(data)
    _keep.append(p)
    return p.GetOutputPort()


def terrain(arrays=None, n=N, dx=DX):
    img = vtkImageData()
    img.SetDimensions(n, n, 1)
    img.SetSpacing(dx, dx, 1.0)
    img.SetOrigin(0.0, 0.0, 0.0)
    if arrays is None:
        arrays = {"elevation": np.zeros((n, n))}
    for name, values in arrays.items():
        arr = numpy_to_vtk(np.ascontiguousarray(values, dtype=np.float32).reshape(-1), deep=1)
        arr.SetName(name)
        img.GetPointData().AddArray(arr)
    return img


def box(bounds):
    c = vtkCubeSource()
    c.SetBounds(*bounds)
    c.Update()
    out = vtkPolyData()
    out.DeepCopy(c.GetOutput())
    return out


def cone(centre, height, radius, res=12):
    c = vtkConeSource()
    c.SetCenter(*centre)
    c.SetHeight(height)
    c.SetRadius(radius)
    c.SetDirection(0.0, 0.0, 1.0)
    c.SetResolution(res)
    c.Update()
    out = vtkPolyData()
    out.DeepCopy(c.GetOutput())
    return out


def polys(points, faces):
    """A polydata of the given points and polygons (counter-clockwise from outside)."""
    pts = vtkPoints()
    for p in points:
        pts.InsertNextPoint(*p)
    cells = vtkCellArray()
    for f in faces:
        cells.InsertNextCell(len(f), f)
    out = vtkPolyData()
    out.SetPoints(pts)
    out.SetPolys(cells)
    return out


def blocks(*leaves):
    mb = vtkMultiBlockDataSet()
    for k, leaf in enumerate(leaves):
        mb.SetBlock(k, leaf)
    return mb


def snow(objects=None, ground=None, **kw):
    f = vtkSnowAccumulationFilter()
    f.SetInputConnection(producer(ground if isinstance(ground, vtkImageData) else terrain(ground)))
    if objects is not None:
        f.SetObjectsConnection(producer(objects))
    f.SetEndTime(kw.pop("EndTime", 2 * HOUR))
    f.SetOutputInterval(kw.pop("OutputInterval", 0.5 * HOUR))
    f.SetTimeStep(kw.pop("TimeStep", 600.0))
    f.SetExposureResolution(kw.pop("ExposureResolution", 256))
    for k, v in kw.items():
        getattr(f, "Set" + k)(*(v if isinstance(v, tuple) else (v,)))
    return f


def at(f, t, n=N):
    f.UpdateTimeStep(t)
    out = f.GetOutput()
    if out.GetNumberOfPoints() == 0:
        return None, out
    return vtk_to_numpy(out.GetPointData().GetArray("snow_depth")).reshape(n, n).copy(), out


def array(data, name, n=N):
    return vtk_to_numpy(data.GetPointData().GetArray(name)).reshape(n, n).copy()


def field(data, name):
    arr = data.GetFieldData().GetArray(name)
    return None if arr is None else arr.GetTuple(0)[0]


j, i = np.mgrid[0:N, 0:N]
X, Y = i * DX, j * DX

# ---- defaults ---------------------------------------------------------------------
f = vtkSnowAccumulationFilter()
T.check(f.GetSnowDirection() == (0.0, 0.0, -1.0) and f.GetTimeStep() == 300.0,
        "defaults SnowDirection 0 0 -1, TimeStep 300 s: %r %r"
        % (f.GetSnowDirection(), f.GetTimeStep()))
T.check((f.GetSnowfallRate(), f.GetSnowDensity(), f.GetMaxDepth(), f.GetStabilityFactor(),
         f.GetExposureResolution(), f.GetBlurRadius(), f.GetDilation())
        == (2.0, 100.0, 1.0, 1.0, 1024, 1, 0) and f.GetAccumulationTextureSize() == 256,
        "defaults 2 cm/h, 100 kg/m^3, MaxDepth 1 m, factor 1, 1024 texels, blur 1, no dilation, "
        "256-texel accumulation textures")
T.check((f.GetEndTime(), f.GetOutputInterval()) == (6 * HOUR, 900.0)
        and (f.GetDefaultEndTime(), f.GetDefaultOutputInterval()) == (6 * HOUR, 900.0),
        "time defaults EndTime 6 h, OutputInterval 15 min: %r"
        % ((f.GetEndTime(), f.GetOutputInterval()),))
f.SetSnowfallRate(1e9)
f.SetStabilityFactor(-3.0)
T.check(f.GetSnowfallRate() == 1000.0 and f.GetStabilityFactor() == 0.0,
        "setters clamp to the table: %r %r" % (f.GetSnowfallRate(), f.GetStabilityFactor()))

# ---- the proxy (pvpython with the plugin) -------------------------------------------
plugin = a.plugin
if plugin is None:
    import glob  # noqa: E402
    import graupel  # noqa: E402
    lib = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(graupel.__file__))))
    found = glob.glob(os.path.join(lib, "paraview-*", "plugins", "Graupel", "Graupel.so"))
    plugin = found[0] if found else None
if plugin is not None:
    from paraview import simple as pv  # noqa: E402

    px = globals()  # where LoadPlugin puts the plugin's proxies
    pv.LoadPlugin(plugin, ns=px)
    ground = px["ProceduralTerrain"](Dimensions=[8, 8])
    sa = px["SnowAccumulation"](Input=ground)
    T.check((sa.EndTime, sa.OutputInterval, sa.TimeStep) == (6 * HOUR, 900.0, 300.0)
            and list(sa.SnowDirection) == [0.0, 0.0, -1.0] and sa.SnowfallRate == 2.0,
            "proxy defaults are the class's: %r" % ((sa.EndTime, sa.OutputInterval, sa.TimeStep),))
    T.check(sa.ListProperties().count("Device") == 1 and "ExposureResolution" in sa.ListProperties()
            and sa.AccumulationTextureSize == 256,
            "proxy properties keep their names (no units in labels): %r" % sa.ListProperties())

# ---- a box on flat ground: nothing under it, a cap on top, the ledger ---------------
RATE = 2.0  # cm/h
B = (4.0, 7.0, 4.0, 7.0, 0.0, 1.0)
g = snow(box(B), NoiseAmplitude=0.0)
d, out = at(g, 2 * HOUR)
inside = (X > B[0] + 2 * DX) & (X < B[1] - 2 * DX) & (Y > B[2] + 2 * DX) & (Y < B[3] - 2 * DX)
far = (X < B[0] - 3 * DX) | (X > B[1] + 3 * DX) | (Y < B[2] - 3 * DX) | (Y > B[3] + 3 * DX)
want = RATE * 0.01 * 2.0
T.check(inside.sum() >= 25 and np.all(d[inside] == 0.0),
        "exactly no snow under the box (%d points, max %g m)" % (inside.sum(), d[inside].max()))
T.check(np.allclose(d[far], want, rtol=1e-5),
        "open ground grows as rate x t: %g..%g m, want %g" % (d[far].min(), d[far].max(), want))
T.check(np.all(array(out, "exposure")[inside] == 0) and np.all(array(out, "exposure")[far] == 1),
        "exposure 0 under the box, 1 in the open")
T.check(np.allclose(array(out, "snow_surface"), d + 0.0, atol=1e-6)
        and np.all(array(out, "snow_density") == 100.0) and np.all(array(out, "elevation") == 0.0),
        "snow_surface = elevation + depth, snow_density = SnowDensity, elevation passed on")
objs = g.GetOutputDataObject(1)
T.check(objs.IsA("vtkPolyData") and objs.GetNumberOfPoints() == 24,
        "the objects' output: the box's 24 points")
od = vtk_to_numpy(objs.GetPointData().GetArray("snow_depth"))
off = vtk_to_numpy(objs.GetPointData().GetArray("snow_offset"))
# The cube's faces keep their own corners: the top's four face up.
top = vtk_to_numpy(objs.GetPointData().GetNormals())[:, 2] > 0.5
T.check(top.sum() == 4 and np.allclose(od[top], want, rtol=1e-5) and np.all(od[~top] == 0.0),
        "a cap of rate x t on the top face, none on the sides or under it: %r" % od)
T.check(np.allclose(off[top], np.column_stack([0 * od[top], 0 * od[top], od[top]]), atol=1e-7),
        "snow_offset on the top is (0, 0, depth): %r" % off[top])
area = (N - 1) ** 2 * DX * DX
cap = (B[1] - B[0]) * (B[3] - B[2]) * want
T.near(field(out, "stored_volume_objects"), cap, 1e-5 * cap, "the objects' stored volume is the cap")
T.check(field(out, "time") == 2 * HOUR and field(out, "steps") == 12.0, "time 2 h in 12 steps")

# The ledger with shedding: heavy snow over a low MaxDepth and noise.
g = snow(box(B), SnowfallRate=20.0, MaxDepth=0.2, StabilityFactor=0.3, NoiseAmplitude=0.5,
         Flutter=3.0, BlurRadius=2, Dilation=1, EndTime=4 * HOUR, TimeStep=300.0)
d, out = at(g, 4 * HOUR)
fall, stored, shed = (field(out, n) for n in ("snowfall_volume", "stored_volume", "shed_volume"))
print("ledger: snowfall %.9g, stored %.9g, shed %.9g m^3, balance_error %.3g"
      % (fall, stored, shed, field(out, "balance_error")))
T.check(shed > 0.1 * fall, "the cap sheds (%g of %g m^3)" % (shed, fall))
T.check(abs(fall - stored - shed) <= 1e-6 * fall and abs(field(out, "balance_error")) <= 1e-6 * fall,
        "ledger: snowfall %r = stored %r + shed %r (error %g)"
        % (fall, stored, shed, field(out, "balance_error")))
T.near(field(out, "stored_volume_terrain") + field(out, "stored_volume_objects"), stored,
       1e-9 * stored, "stored = terrain + objects")
T.near(d.sum() * DX * DX, field(out, "stored_volume_terrain"), 1e-4 * stored,
       "stored_volume_terrain is the depths summed")
T.check(d.max() <= 0.2 + 20 * 0.01 * 300 / HOUR + 1e-6, "MaxDepth holds (%g m)" % d.max())

# ---- exposure against a ray caster: a hut, trees, rough terrain ---------------------
M, DM = 64, 0.25
jm, im = np.mgrid[0:M, 0:M]
XM, YM = im * DM, jm * DM
rng = np.random.default_rng(7)
rough = (0.35 * np.sin(XM * 0.7) * np.cos(YM * 0.55) + 0.15 * np.sin(1.3 * XM + 0.9 * YM)
         + 0.03 * rng.standard_normal((M, M)))


def ground_z(x, y):
    return float(rough[int(round(y / DM)), int(round(x / DM))])


hx, hy = 5.0, 8.0  # the hut: walls 4 x 3 x 2 m, a gable roof overhanging 0.4 m
base = ground_z(hx, hy) - 0.4
walls = box((hx - 2, hx + 2, hy - 1.5, hy + 1.5, base, base + 2.0))
e, r = base + 2.0, base + 3.0
roof = polys([(hx - 2.4, hy - 1.9, e), (hx + 2.4, hy - 1.9, e), (hx + 2.4, hy, r), (hx - 2.4, hy, r),
              (hx - 2.4, hy + 1.9, e), (hx + 2.4, hy + 1.9, e)],
             [(0, 1, 2, 3), (3, 2, 5, 4)])
trees = [cone((x, y, ground_z(x, y) + 1.8), 4.0, 1.2) for x, y in
         ((10.5, 3.5), (11.5, 11.0), (8.5, 13.0))]
D = np.array([0.45, 0.25, -1.0])
scene = snow(blocks(walls, roof, *trees), terrain({"elevation": rough}, M, DM),
             SnowDirection=tuple(D), NoiseAmplitude=0.0, BlurRadius=0, ExposureResolution=512,
             EndTime=60.0, OutputInterval=60.0, TimeStep=60.0)
_, out = at(scene, 60.0, M)
exposure = array(out, "exposure", M)

# The ray caster: the terrain's triangles and the objects in one OBB tree;
# a point is exposed when the ray from it towards the snow hits nothing.
world = vtkPoints()
cells = vtkCellArray()
for jj in range(M):
    for ii in range(M):
        world.InsertNextPoint(ii * DM, jj * DM, rough[jj, ii])
for jj in range(M - 1):
    for ii in range(M - 1):
        p = jj * M + ii
        cells.InsertNextCell(3, (p, p + 1, p + M + 1))
        cells.InsertNextCell(3, (p, p + M + 1, p + M))
for leaf in [walls, roof] + trees:
    first = world.GetNumberOfPoints()
    for k in range(leaf.GetNumberOfPoints()):
        world.InsertNextPoint(leaf.GetPoint(k))
    ids = leaf.GetPolys()
    ids.InitTraversal()
    from vtkmodules.vtkCommonCore import vtkIdList  # noqa: E402
    idl = vtkIdList()
    while ids.GetNextCell(idl):
        cells.InsertNextCell(idl.GetNumberOfIds(),
                             [first + idl.GetId(k) for k in range(idl.GetNumberOfIds())])
mesh = vtkPolyData()
mesh.SetPoints(world)
mesh.SetPolys(cells)
tree = vtkOBBTree()
tree.SetDataSet(mesh)
tree.BuildLocator()
up = -D / np.linalg.norm(D)
hits = vtkPoints()
cast = np.zeros((M, M), dtype=int)
for jj in range(M):
    for ii in range(M):
        p = np.array([ii * DM, jj * DM, rough[jj, ii]])
        cast[jj, ii] = 0 if tree.IntersectWithLine(p + 1e-3 * up, p + 60.0 * up, hits, None) else 1
agree = np.mean(cast == exposure)
shadowed = np.mean(cast == 0)
agree_shadow = np.mean(exposure[cast == 0] == 0)
print("exposure vs ray caster: %.2f %% of %d points agree, %.2f %% of the %.1f %% it shadows"
      % (100 * agree, M * M, 100 * agree_shadow, 100 * shadowed))
T.check(shadowed > 0.1, "the scene shadows a good part of the ground (%.1f %%)" % (100 * shadowed))
T.check(agree >= 0.98, "exposure agrees with the ray caster on %.2f %% of the points" % (100 * agree))
T.check(agree_shadow >= 0.95,
        "and on %.2f %% of the points the ray caster shadows" % (100 * agree_shadow))
hut = (np.abs(XM - hx) < 1.7) & (np.abs(YM - hy) < 1.2)
T.check(np.all(exposure[hut] == 0), "no exposure under the hut")

# ---- wind: the bare patch behind a wall moves to the lee side -----------------------
H, TILT = 2.0, math.radians(30.0)
wall = box((5.0, 5.25, 2.0, 9.0, 0.0, H))
row = N // 2
lee = []
for tilt in (0.0, TILT):
    w = snow(wall, SnowDirection=(math.tan(tilt), 0.0, -1.0), NoiseAmplitude=0.0, BlurRadius=0,
             ExposureResolution=512, EndTime=HOUR, OutputInterval=HOUR, TimeStep=HOUR)
    _, out = at(w, HOUR)
    bare = array(out, "exposure")[row] == 0
    xs = X[row][bare]
    lee.append((xs.min(), xs.max()))
T.check(lee[0][0] >= 5.0 - DX and lee[0][1] <= 5.25 + DX,
        "vertical snow: bare only under the wall (x %g..%g)" % lee[0])
length = lee[1][1] - 5.25
print("wind: bare x %g..%g m straight down, %g..%g m at 30 degrees (lee %g m, h tan = %g m)"
      % (lee[0] + lee[1] + (length, H * math.tan(TILT))))
T.check(lee[1][0] >= 5.0 - DX and abs(length - H * math.tan(TILT)) <= DX,
        "snow driven to +x: the bare patch runs %g m to the lee side, h tan(tilt) = %g m"
        % (length, H * math.tan(TILT)))

# ---- the same simulated time in other steps: the same snow -------------------------
SCENE = dict(objects=blocks(box(B), cone((9.0, 9.0, 1.0), 2.0, 0.8)), SnowfallRate=5.0,
             MaxDepth=0.3, EndTime=2 * HOUR)
volumes = []
for interval, step in ((2 * HOUR, 720.0), (1000.0, 720.0), (2 * HOUR, 72.0), (432.0, 72.0)):
    s = snow(SCENE["objects"], **{k: v for k, v in SCENE.items() if k != "objects"},
             OutputInterval=interval, TimeStep=step)
    _, out = at(s, 2 * HOUR)
    T.check(field(out, "time") == 2 * HOUR, "interval %g s: the last output is at 2 h" % interval)
    volumes.append(field(out, "stored_volume"))
spread = (max(volumes) - min(volumes)) / max(volumes)
print("stored volume at 2 h with intervals and steps (10 and 100 steps): %r, spread %.2e"
      % (volumes, spread))
T.check(spread <= 0.01, "the same stored volume within 1 %%: %r" % volumes)

# ---- results do not depend on the order of requested times --------------------------
times = [900.0 * k for k in range(1, 9)]
ref = {}
fw = snow(SCENE["objects"], NoiseAmplitude=0.4, Flutter=4.0, EndTime=2 * HOUR, OutputInterval=900.0)
for t in times:
    d, out = at(fw, t)
    ref[t] = (d, vtk_to_numpy(fw.GetOutputDataObject(1).GetBlock(1).GetPointData()
                              .GetArray("snow_depth")).copy())
bw = snow(SCENE["objects"], NoiseAmplitude=0.4, Flutter=4.0, EndTime=2 * HOUR, OutputInterval=900.0)
bw.SetCheckpointInterval(2)
same = True
for t in [times[-1], times[2], times[5], times[0], times[7], times[3]]:
    d, out = at(bw, t)
    o = vtk_to_numpy(bw.GetOutputDataObject(1).GetBlock(1).GetPointData().GetArray("snow_depth"))
    same = same and np.array_equal(d, ref[t][0]) and np.array_equal(o, ref[t][1])
T.check(same, "any order of times gives the same bits (grid and objects)")
T.check(bw.GetRestoreCount() > 0, "going back restored checkpoints (%d)" % bw.GetRestoreCount())

# ---- a moving object carries its snow -----------------------------------------------
mover = box((2.0, 3.0, 5.0, 6.0, 0.0, 0.5))
mv = snow(mover, ObjectVelocity=(5.0 / (2 * HOUR), 0.0, 0.0), NoiseAmplitude=0.0, BlurRadius=0)
_, out = at(mv, 2 * HOUR)
mo = mv.GetOutputDataObject(1)
mpts = vtk_to_numpy(mo.GetPoints().GetData())
mtop = vtk_to_numpy(mo.GetPointData().GetNormals())[:, 2] > 0.5
T.check(np.allclose(mpts[:, 0].min(), 7.0) and np.allclose(
        vtk_to_numpy(mo.GetPointData().GetArray("snow_depth"))[mtop], want, rtol=1e-5),
        "the box moved 5 m and kept its cap of %g m" % want)

# ---- an object following a curved Path carries its snow ----------------------------
# A 1 x 0.4 x 0.4 m box on a quarter circle (radius 3 m about (6, 6)), its
# centre 0.2 m up so that it rests on the ground; at 80 % of the path's
# length at 2 h it ends inside a segment, which the walk below finds
# independently of vtkGraupelMotion.
arc = np.array([(6.0 + 3.0 * math.cos(a), 6.0 + 3.0 * math.sin(a), 0.2)
                for a in np.linspace(-0.5 * math.pi, 0.0, 13)])
seg = np.linalg.norm(np.diff(arc, axis=0), axis=1)
speed = 0.8 * seg.sum() / (2 * HOUR)
arc_path = polys([tuple(p) for p in arc], [])
arc_line = vtkCellArray()
arc_line.InsertNextCell(len(arc), list(range(len(arc))))
arc_path.SetLines(arc_line)
cart = box((-0.5, 0.5, -0.2, 0.2, -0.2, 0.2))
tag = numpy_to_vtk(np.array([7.0]), deep=1)
tag.SetName("tag")
cart.GetFieldData().AddArray(tag)
pf = snow(cart, ObjectVelocity=(speed, 0.0, 0.0), NoiseAmplitude=0.0, BlurRadius=0)
pf.SetPathConnection(producer(arc_path))
_, pout = at(pf, 2 * HOUR)
s_left, k = speed * 2 * HOUR, 0
while s_left > seg[k]:
    s_left -= seg[k]
    k += 1
tangent = (arc[k + 1] - arc[k]) / seg[k]
end = arc[k] + tangent * s_left
po = pf.GetOutputDataObject(1)
ppts = vtk_to_numpy(po.GetPoints().GetData())
centre = ppts.mean(axis=0)
# The box's long axis (its +x) lies along the tangent.
_, _, axes = np.linalg.svd(ppts - centre)
ptop = vtk_to_numpy(po.GetPointData().GetNormals())[:, 2] > 0.5
pdepth = vtk_to_numpy(po.GetPointData().GetArray("snow_depth"))
print("path: the box ends at (%.6f, %.6f, %.6f), the path says (%.6f, %.6f, %.6f); cap %g m"
      % (tuple(centre) + tuple(end) + (pdepth[ptop].min(),)))
T.check(0 < k < len(seg) - 1 and np.linalg.norm(centre - end) <= 1e-3,
        "along the Path the box ends where the path says at 2 h (segment %d, off by %.2e m)"
        % (k, np.linalg.norm(centre - end)))
T.check(abs(np.dot(axes[0], tangent)) >= 0.999,
        "the box's +x lies along the path's tangent (cos %.6f)" % abs(np.dot(axes[0], tangent)))
T.check(ptop.sum() == 4 and np.all(pdepth[ptop] > 0.0)
        and np.allclose(pdepth[ptop], want, rtol=1e-3),
        "the box carried its cap along the Path: %r m (want %g m)" % (pdepth[ptop], want))
T.check(po.GetFieldData().GetArray("tag") is not None
        and po.GetFieldData().GetArray("tag").GetTuple1(0) == 7.0
        and field(pout, "time") == 2 * HOUR, "port 1 keeps the object's field data at 2 h")

# ---- objects with time steps: a crate carried under a roof keeps its snow -----------
from gr_timed import TimedSource  # noqa: E402


class CarriedCrate(TimedSource):
    """A roof (an open quad at 3 m over x 6-11 m) and a crate that stands in the
    open until 1 h, then under the roof."""

    TIMES = [0.0, HOUR, 2 * HOUR]

    def __init__(self):
        TimedSource.__init__(self, "vtkMultiBlockDataSet")

    def RequestData(self, request, inInfo, outInfo):
        t = self.requested_time(outInfo)
        x = 1.5 if t < HOUR else 7.5
        out = vtkMultiBlockDataSet.GetData(outInfo)
        out.ShallowCopy(blocks(polys([(6, 1, 3), (11, 1, 3), (11, 10, 3), (6, 10, 3)], [(0, 1, 2, 3)]),
                               box((x, x + 1.0, 4.0, 5.0, 0.0, 0.5))))
        out.GetInformation().Set(out.DATA_TIME_STEP(), t)
        return 1


crate = CarriedCrate()
tc = vtkSnowAccumulationFilter()
tc.SetInputConnection(producer(terrain()))
tc.SetObjectsConnection(crate.GetOutputPort())
tc.SetEndTime(2 * HOUR)
tc.SetOutputInterval(0.5 * HOUR)
tc.SetTimeStep(600.0)
tc.SetExposureResolution(256)
tc.SetNoiseAmplitude(0.0)
d2, out = at(tc, 2 * HOUR)
T.check(d2 is not None and tc.IsInputTemporal(1), "objects with time steps are read in time")
T.check(sorted(set(crate.requested)) == [0.0, HOUR], "each time step read: %r" % crate.requested)
if d2 is not None:
    cb = tc.GetOutputDataObject(1).GetBlock(1)
    cd = vtk_to_numpy(cb.GetPointData().GetArray("snow_depth"))
    ctop = vtk_to_numpy(cb.GetPointData().GetNormals())[:, 2] > 0.5
    hour = RATE * 0.01
    T.check(np.allclose(cd[ctop], hour, rtol=1e-5) and cb.GetBounds()[0] == 7.5,
            "under the roof the crate keeps its first hour's %g m: %r" % (hour, cd[ctop]))
    d1, _ = at(tc, HOUR)
    d2b, _ = at(tc, 2 * HOUR)
    T.check(np.array_equal(d2b, d2), "temporal objects: back and forth gives the same bits")

# ---- chaining into Snow Deformation -------------------------------------------------
acc = snow(box(B), NoiseAmplitude=0.3, SnowfallRate=10.0, SnowDensity=120.0)
defo = vtkSnowDeformationFilter()
defo.SetInputConnection(acc.GetOutputPort(0))
defo.SetEndTime(1.0)
defo.SetOutputInterval(0.5)
defo.UpdateTimeStep(0.0)
dout = defo.GetOutput()
acc_out = acc.GetOutput()
mass = float(np.sum(array(acc_out, "snow_depth").astype(np.float64)
                    * array(acc_out, "snow_density")) * DX * DX)
T.check(field(acc_out, "time") == 2 * HOUR,
        "Snow Deformation reads the accumulation at its EndTime (%r s)" % field(acc_out, "time"))
# Snow Deformation keeps depths in quanta of 2^-20 m.
T.check(dout.GetNumberOfPoints() == N * N
        and np.abs(array(dout, "snow_depth") - array(acc_out, "snow_depth")).max() <= 2.0 ** -20,
        "Snow Deformation takes snow_depth as it is")
print("chaining: accumulated %.6f kg, Snow Deformation's initial mass %.6f kg"
      % (mass, field(dout, "initial_mass")))
T.check(mass > 0 and abs(field(dout, "initial_mass") - mass) <= 1e-5 * mass,
        "its mass ledger starts from the accumulation's %g kg: %r" % (mass, field(dout, "initial_mass")))

# ---- accumulation textures: port 2, one image per object ------------------------------
from vtkmodules.vtkFiltersCore import vtkTriangleFilter  # noqa: E402
from vtkmodules.vtkFiltersSources import vtkPlaneSource  # noqa: E402


def plane(origin, p1, p2, res=4):
    ps = vtkPlaneSource()
    ps.SetOrigin(*origin)
    ps.SetPoint1(*p1)
    ps.SetPoint2(*p2)
    ps.SetResolution(res, res)
    tf = vtkTriangleFilter()
    tf.SetInputConnection(ps.GetOutputPort())
    tf.Update()
    out = vtkPolyData()
    out.DeepCopy(tf.GetOutput())
    return out


# A textured plane at z = 0.5 (x, y 1 to 5 m, u along x), its half x > 3 m
# under a lid; the lid has no texture coordinates.
R = 32
lid = box((3.0, 6.0, 0.0, 6.0, 1.5, 1.7))
lid.GetPointData().SetTCoords(None)
sheet = plane((1.0, 1.0, 0.5), (5.0, 1.0, 0.5), (1.0, 5.0, 0.5))
T.check(sheet.GetPointData().GetTCoords() is not None, "vtkPlaneSource gives texture coordinates")
tx = snow(blocks(sheet, lid), NoiseAmplitude=0.0, AccumulationTextureSize=R)
d_tx, out_tx = at(tx, 2 * HOUR)
texs = tx.GetOutputDataObject(2)
T.check(texs is not None and texs.IsA("vtkMultiBlockDataSet") and texs.GetNumberOfBlocks() == 2,
        "port 2: a multiblock with one image per object")
img = texs.GetBlock(0)
T.check(img.IsA("vtkImageData") and img.GetDimensions() == (R, R, 1)
        and texs.GetBlock(1).GetNumberOfPoints() == 0,
        "the plane's texture is %d x %d, the lid without UVs has an empty image: %r, %d"
        % (R, R, img.GetDimensions(), texs.GetBlock(1).GetNumberOfPoints()))
tex = vtk_to_numpy(img.GetPointData().GetArray("snow_depth")).reshape(R, R)
u = (np.arange(R) + 0.5) / R
x_of = 1.0 + 4.0 * u  # the plane's x at each texel column
open_cols, lid_cols = x_of < 2.8, x_of > 3.2
want = RATE * 0.01 * 2.0
print("textures: open texels %.6f..%.6f m (want %g), under the lid at most %g m"
      % (tex[:, open_cols].min(), tex[:, open_cols].max(), want, tex[:, lid_cols].max()))
T.check(np.allclose(tex[:, open_cols], want, rtol=1e-5),
        "open texels grow as rate x t: %g..%g m, want %g"
        % (tex[:, open_cols].min(), tex[:, open_cols].max(), want))
T.check(lid_cols.sum() >= 10 and np.all(tex[:, lid_cols] == 0.0),
        "texels under the lid stay exactly 0 (max %g m)" % tex[:, lid_cols].max())
# The texture is a finer picture of the same snow: the plane's points agree
# where they are open, and the ledger is that of the run without textures.
sheet_out = tx.GetOutputDataObject(1).GetBlock(0)
pd_depth = vtk_to_numpy(sheet_out.GetPointData().GetArray("snow_depth"))
px = vtk_to_numpy(sheet_out.GetPoints().GetData())[:, 0]
T.check(np.allclose(pd_depth[px < 2.8], want, rtol=1e-5) and np.all(pd_depth[px > 3.2] == 0.0),
        "the plane's points: %g m in the open, 0 under the lid" % want)
nt = snow(blocks(sheet, lid), NoiseAmplitude=0.0, AccumulationTextureSize=0)
d_nt, out_nt = at(nt, 2 * HOUR)
nt_texs = nt.GetOutputDataObject(2)
T.check(nt_texs.GetNumberOfBlocks() == 2 and nt_texs.GetBlock(0).GetNumberOfPoints() == 0,
        "AccumulationTextureSize 0: empty images")
T.check(np.array_equal(d_tx, d_nt)
        and field(out_tx, "stored_volume_objects") == field(out_nt, "stored_volume_objects")
        and abs(field(out_tx, "balance_error")) <= 1e-6 * field(out_tx, "snowfall_volume"),
        "textures leave the terrain and the ledger as they are: %r vs %r"
        % (field(out_tx, "stored_volume_objects"), field(out_nt, "stored_volume_objects")))
# A single textured polydata (not a multiblock) and times requested out of
# order: the texture at 1 h is half of that at 2 h.
single = snow(sheet, NoiseAmplitude=0.0, AccumulationTextureSize=16)
at(single, 2 * HOUR)
at(single, HOUR)
t1 = vtk_to_numpy(single.GetOutputDataObject(2).GetBlock(0).GetPointData()
                  .GetArray("snow_depth")).copy()
T.check(t1.size == 256 and np.allclose(t1, want / 2, rtol=1e-5),
        "a single polydata at 1 h: 16 x 16 texels of %g m (%g..%g)" % (want / 2, t1.min(), t1.max()))

# ---- growth and shedding together: the same snow in 10 steps or 100 ---------------
# "Snow physics, checked from outside", defect 4: 20 cm/h for 4 h over MaxDepth 0.3 m
# with StabilityFactor 0.001/s stored 7.8 % less in 10 steps than in 100 (growth added,
# then a step's worth of shedding). Now each step is the exact solution of
# dS/dt = r - k max(0, S - c), k = -ln(1 - f): the ground in the open and the box's top
# sit at it, whatever the TimeStep.
R20, T4 = 0.2 / HOUR, 4 * HOUR
for factor in (0.001, 0.01):
    k = -math.log1p(-factor)
    exact = 0.3 + R20 / k * -math.expm1(-k * (T4 - 0.3 / R20))
    vols = []
    for steps in (10, 100):
        g = snow(box(B), SnowfallRate=20.0, MaxDepth=0.3, StabilityFactor=factor,
                 NoiseAmplitude=0.0, BlurRadius=0, EndTime=T4, OutputInterval=T4,
                 TimeStep=T4 / steps)
        d, out = at(g, T4)
        vols.append(field(out, "stored_volume"))
        objs = g.GetOutputDataObject(1)
        od = vtk_to_numpy(objs.GetPointData().GetArray("snow_depth"))
        top = vtk_to_numpy(objs.GetPointData().GetNormals())[:, 2] > 0.5
        print("stability %g/s, %d steps: open ground %.6f m, box top %.6f m, exact %.6f m; "
              "stored %.6f m^3" % (factor, steps, d[far].mean(), od[top].mean(), exact, vols[-1]))
        T.check(np.allclose(d[far], exact, atol=0.01 * (exact - 0.3))
                and np.allclose(od[top], exact, atol=0.01 * (exact - 0.3)),
                "StabilityFactor %g, %d steps: the open ground and the box's top at the continuous "
                "solution %.6f m (excess within 1 %%): %.6f, %.6f"
                % (factor, steps, exact, d[far].mean(), od[top].mean()))
    T.check(abs(vols[1] - vols[0]) <= 0.01 * vols[1],
            "StabilityFactor %g: 10 and 100 steps store %.6f and %.6f m^3 (within 1 %%)"
            % (factor, vols[0], vols[1]))

# ---- snow from the faces: a capped cone, its flat-shaded copy, a box of 8 corners ----
# Defect 5: snow followed the points' averaged normals, so a capped cone got the flat
# ground's snow at its apex and none on its base ring. Now the faces grow and the points
# show their faces' snow weighted by the area each turns to the sky.
ALPHA, RC = math.radians(70.0), 1.0
HC = RC * math.tan(ALPHA)
smooth = cone((3.0, 3.0, 0.2 + HC / 2), HC, RC, res=32)
tri = vtkTriangleFilter()
tri.SetInputData(smooth)
tri.Update()
tris = tri.GetOutput()
tp = vtk_to_numpy(tris.GetPoints().GetData())
cells = [[tris.GetCell(c).GetPointId(q) for q in range(3)] for c in range(tris.GetNumberOfCells())]
flat_pts = [tuple(tp[v] + np.array([5.5, 0.0, 0.0])) for c in cells for v in c]
flat = polys(flat_pts, [(3 * c, 3 * c + 1, 3 * c + 2) for c in range(len(cells))])
corners = [(x, y, z) for z in (0.2, 1.2) for y in (7.5, 9.5) for x in (2.0, 4.0)]
box8 = polys(corners, [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2),
                       (1, 3, 7, 5)])
g = snow(blocks(smooth, flat, box8), NoiseAmplitude=0.0)
d, out = at(g, 2 * HOUR)
want = RATE * 0.01 * 2.0
chord = RC * math.cos(math.pi / 32)
side = want * chord / math.hypot(chord, HC)  # a side face's rate x t x cos(slope)
clear = (X > 5.0) & (X < 7.0) & (Y > 5.0) & (Y < 7.0)  # ground away from the three
res_out = g.GetOutputDataObject(1)
for b, name in ((0, "capped cone"), (1, "flat-shaded cone")):
    leaf = res_out.GetBlock(b)
    od = vtk_to_numpy(leaf.GetPointData().GetArray("snow_depth"))
    pz = vtk_to_numpy(leaf.GetPoints().GetData())[:, 2]
    off = vtk_to_numpy(leaf.GetPointData().GetArray("snow_offset"))
    ring = np.abs(pz - 0.2) < 1e-4
    apex = pz > 1.0
    if b == 1:  # the base's own points face down and hold nothing
        base = np.array([c for c in range(len(cells)) for _ in range(3)])
        on_base = np.array([tris.GetCell(c).GetNumberOfPoints() == 3 and
                            np.all(tp[cells[c]][:, 2] < 0.2 + 1e-4) for c in base])
        T.check(np.all(od[on_base] == 0.0), "%s: the base's faces hold nothing" % name)
        ring &= ~on_base
    print("%s: %d base ring points %.6f..%.6f m, apex %.6f m; the sides' %.6f m (rate t cos 70 "
          "%.6f), flat ground %.6f m" % (name, ring.sum(), od[ring].min(), od[ring].max(),
                                          od[apex].mean(), side, want * math.cos(ALPHA),
                                          d[clear].mean()))
    T.check(ring.sum() >= 32 and np.allclose(od[ring], side, rtol=5e-3)
            and np.allclose(od[apex], side, rtol=5e-3),
            "%s: base ring and apex carry the sides' %.6f m (ring %.6f..%.6f, apex %.6f)"
            % (name, side, od[ring].min(), od[ring].max(), od[apex].mean()))
    T.check(np.all(off[ring][:, 2] > 0.3 * od[ring]),
            "%s: the ring's snow_offset points up and out" % name)
top8 = vtk_to_numpy(res_out.GetBlock(2).GetPoints().GetData())[:, 2] > 1.0
od8 = vtk_to_numpy(res_out.GetBlock(2).GetPointData().GetArray("snow_depth"))
T.check(np.allclose(od8[top8], want, rtol=1e-5) and np.all(od8[~top8] == 0.0)
        and np.allclose(d[clear], want, rtol=1e-5),
        "a box of 8 shared corners: its top corners carry the flat ground's %g m: %r"
        % (want, od8))

# ---- bad input: one sentence, empty outputs, the next good update works ------------
nan_ground = np.zeros((N, N))
nan_ground[5, 7] = np.nan
good = snow(box(B), NoiseAmplitude=0.0)
ref_d, _ = at(good, 2 * HOUR)
cases = [
    # Two arrays, neither elevation nor the active scalars: nothing to take as heights.
    ("no elevation", {"ground": {"height": np.zeros((N, N)), "roughness": np.zeros((N, N))}},
     ["'elevation'", "Height Array"]),
    ("NaN elevation", {"ground": {"elevation": nan_ground}}, ["elevation", "nan", "(7, 5)"]),
    ("degenerate direction", {"props": {"SnowDirection": (0.0, 0.0, 0.0)}}, ["SnowDirection"]),
    ("upward direction", {"props": {"SnowDirection": (0.0, 0.2, 1.0)}}, ["SnowDirection", "down"]),
    ("objects not polydata", {"objects": blocks(box(B), terrain())},
     ["Objects", "vtkPolyData", "Extract Surface"]),
    ("zero-area triangle", {"objects": polys([(1, 1, 1), (2, 1, 1), (3, 1, 1)], [(0, 1, 2)])},
     ["Objects", "zero area"]),
    ("ExposureResolution beyond the device", {"props": {"ExposureResolution": 65536}},
     ["ExposureResolution 65536", "beyond the device", "Device"]),
    ("zero-speed path", {"path": True}, ["Path", "ObjectVelocity", "0 m/s"]),
]
for what, case, words in cases:
    g = snow(case.get("objects", box(B)), case.get("ground"), NoiseAmplitude=0.0)
    if case.get("path"):
        g.SetPathConnection(producer(arc_path))
    for k, v in case.get("props", {}).items():
        getattr(g, "Set" + k)(*(v if isinstance(v, tuple) else (v,)))
    errs = T.ErrorCatcher(g)
    for t in (HOUR, HOUR, 2 * HOUR):
        s, out = at(g, t)
    objects_out = g.GetOutputDataObject(1)
    T.check(s is None and (objects_out.GetNumberOfPoints() == 0
                           if objects_out.IsA("vtkPolyData") else
                           objects_out.GetNumberOfBlocks() == 0)
            and g.GetOutputDataObject(2).GetNumberOfBlocks() == 0,
            "%s: empty outputs" % what)
    T.check(len(errs.messages) == 1 and all(w in errs.text() for w in words),
            "%s: one sentence naming %r: %r" % (what, words, errs.text()[:300]))
    # Fixed, the same filter works again.
    g.SetInputConnection(producer(terrain()))
    g.SetObjectsConnection(producer(box(B)))
    g.SetSnowDirection(0.0, 0.0, -1.0)
    g.SetExposureResolution(256)
    g.SetInputConnection(2, None)
    s, _ = at(g, 2 * HOUR)
    T.check(s is not None and np.array_equal(s, ref_d), "%s: fixed, it works again" % what)

T.finish()
