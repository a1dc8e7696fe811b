"""The snow deformation scene shared by the demo (demo_snow_deformation.py)
and the reference-image test (Testing/Python/test_images.py --scene snow): a
wheel rolling through snow along an S-shaped path over a small patch of
procedural terrain, rendered with the snow surface warped, coloured by
density, and the wheel at its pose. And the snow accumulation scene of
demo_snow_accumulation.py and test_images.py --scene accumulation: a hut and
trees under wind-driven snow, then a sledge across it (build_accumulation,
show_accumulation)."""
import math

import numpy as np
from paraview import servermanager
from paraview.simple import (AddLight, ColorBy, Cylinder, ExtractSurface,
                             GenerateSurfaceNormals, GetActiveViewOrCreate,
                             GetColorTransferFunction, GetScalarBar, OutputPort, PolyLineSource,
                             Render, Show, Text, Triangulate, WarpByScalar)
import paraview.simple as pvs
from vtkmodules.util.numpy_support import vtk_to_numpy

# The wheel: 0.35 m radius, 0.3 m wide, riding 0.18 m deep into 0.3 m of
# snow of 200 kg/m^3 (dry old snow, in the middle of the default density range
# 100-400, so that part of what the wheel presses is compressed and the rest
# pushed aside into rims) at 2.5 m/s. The walls of a rut stand steep:
# MaxSlope 1.2 (50 degrees) keeps trench and rims crisp.
RADIUS, WIDTH, SINK = 0.35, 0.3, 0.18
DEPTH, DENSITY = 0.3, 200.0
SPEED = 2.5
MAX_SLOPE = 1.2


def _constructor(name):
    """paraview.simple's constructor for a Graupel proxy: LoadPlugin(..., ns=)
    adds them to the caller's namespace only, so add them here too."""
    if not hasattr(pvs, name):
        pvs._add_functions(vars(pvs))
    return getattr(pvs, name)


def _elevation_at(terrain, x, y):
    """The terrain's elevation (m) at world points x, y, interpolated
    bilinearly: the path rides on the ground the snow lies on."""
    img = servermanager.Fetch(terrain)
    nx, ny, _ = img.GetDimensions()
    ox, oy, _ = img.GetOrigin()
    sx, sy, _ = img.GetSpacing()
    z = vtk_to_numpy(img.GetPointData().GetArray("elevation")).reshape(ny, nx)
    fx = np.clip((np.asarray(x) - ox) / sx, 0, nx - 1.000001)
    fy = np.clip((np.asarray(y) - oy) / sy, 0, ny - 1.000001)
    i, j = fx.astype(int), fy.astype(int)
    u, v = fx - i, fy - j
    return ((1 - u) * (1 - v) * z[j, i] + u * (1 - v) * z[j, i + 1]
            + (1 - u) * v * z[j + 1, i] + u * v * z[j + 1, i + 1])


def build(cells=320, spacing=0.04, time_step=0.016, frames=3):
    """The pipeline: a cells x cells terrain of `spacing` metres (12.8 m at
    the defaults) with a metre of gentle relief, the wheel, its S-shaped path
    and Snow Deformation, with an output every 1/frames of the crossing.
    Returns (snow, output times)."""
    size = (cells - 1) * spacing
    # Rounded hills a few metres across (Frequency is in cycles per km).
    terrain = _constructor("ProceduralTerrain")(
        Dimensions=[cells, cells], Spacing=spacing, Seed=8, NoiseType="fBm", Octaves=3,
        Frequency=100.0, HeightScale=1.2)
    terrain.UpdatePipeline()

    # An S from the west edge to the east edge, 1 m inside the patch.
    u = np.linspace(0.0, 1.0, 161)
    x = 0.09 * size + 0.82 * size * u
    y = 0.5 * size + 0.17 * size * np.sin(2.0 * math.pi * u)
    # The wheel's centre: its radius above the snow surface, less how deep it rides.
    z = _elevation_at(terrain, x, y) + DEPTH + RADIUS - SINK
    path = PolyLineSource(Points=np.column_stack([x, y, z]).ravel().tolist())
    length = float(np.sum(np.hypot(np.hypot(np.diff(x), np.diff(y)), np.diff(z))))

    # vtkCylinderSource's axis is y: the RotationAxis a wheel rolling along +x
    # turns about, and the Path turns the wheel's +x along its tangent.
    wheel = Triangulate(Input=Cylinder(Radius=RADIUS, Height=WIDTH, Resolution=48, Capping=1))

    # The last output just short of the path's end: the wheel still rolling.
    end = round(0.97 * length / SPEED, 2)
    snow = _constructor("SnowDeformation")(Input=terrain, Objects=wheel, Path=path)
    snow.TimeStep = time_step
    snow.EndTime = end
    snow.OutputInterval = end / frames
    snow.InitialSnowDepth = DEPTH
    snow.InitialDensity = DENSITY
    snow.MaxSlope = MAX_SLOPE
    snow.ObjectVelocity = [SPEED, 0.0, 0.0]
    # Rolling without slipping: v / r radians per second.
    snow.ObjectAngularVelocity = math.degrees(SPEED / RADIUS)
    snow.RotationAxis = [0.0, 1.0, 0.0]
    times = [end * k / frames for k in range(1, frames + 1)]
    return snow, times


def _legend(sb, title, fmt, x=0.30, length=0.40):
    """A horizontal legend titled with units, at the bottom from `x` (a
    fraction of the width) `length` long."""
    sb.Title = title
    sb.ComponentTitle = ""
    sb.TitleColor = sb.LabelColor = [1.0, 1.0, 1.0]
    sb.TitleFontSize = sb.LabelFontSize = 14
    sb.WindowLocation = "Any Location"
    sb.Orientation = "Horizontal"
    sb.Position = [x, 0.03]
    sb.ScalarBarLength = length
    sb.RangeLabelFormat = sb.LabelFormat = fmt
    # White letters on a dark band: the legend lies over white snow.
    sb.DrawBackground = 1
    sb.BackgroundColor = [0.12, 0.13, 0.17, 0.65]


def _readable(text):
    """White text on a dark, half-clear band, readable over snow."""
    text.ShowBorder = "Always"
    text.BackgroundColor = [0.12, 0.13, 0.17, 0.65]
    text.BorderThickness = 0


def _note(view, exaggeration):
    """The vertical exaggeration, written in the upper right as on the
    terrain pictures (Examples/graupel_scene.py)."""
    text = Show(Text(Text="vertical exaggeration \u00d7%g" % exaggeration), view)
    text.WindowLocation = "Upper Right Corner"
    text.FontSize = 14
    text.Color = [1.0, 1.0, 1.0]
    _readable(text)


def show(snow, time, size=(1024, 768), bar=True, label=True, close=False):
    """Renders `snow` (a Snow Deformation proxy) at `time` (s): the snow
    surface lit and coloured by snow_density, the objects at their pose:
    the whole path, or `close` up behind the wheel. Returns the view."""
    view = GetActiveViewOrCreate("RenderView")
    view.ViewTime = time
    view.ViewSize = list(size)
    view.OrientationAxesVisibility = 0
    view.Background = [0.32, 0.34, 0.43]
    if hasattr(view, "UseColorPaletteForBackground"):
        view.UseColorPaletteForBackground = 0
    # The image lies at z = 0; snow_surface is the absolute height of the snow.
    surface = WarpByScalar(Input=snow, Scalars=["POINTS", "snow_surface"], ScaleFactor=1.0)
    # Point normals: smooth shading of the snow (flat facets hide the rims).
    surface = GenerateSurfaceNormals(Input=ExtractSurface(Input=surface), Splitting=0)
    display = Show(surface, view)
    display.Representation = "Surface"
    ColorBy(display, ("POINTS", "snow_density"))
    # The plugin's snow density map from the untouched snow's density
    # (white) to 400 kg/m^3 (deep blue, the default top of the density
    # range): on its own range (50-500) untouched snow would be pale blue
    # and the ruts' contrast halved.
    lut = GetColorTransferFunction("snow_density")
    lut.ApplyPreset("Graupel Snow Density", False)
    lut.AutomaticRescaleRangeMode = "Never"
    lut.RescaleTransferFunction(DENSITY, 400.0)
    display.SetScalarBarVisibility(view, bar)
    if bar:
        _legend(GetScalarBar(lut, view), "snow density (kg/m\u00b3)", "%.0f")
    _note(view, 1.0)
    if label:
        # Two lines, the first short: on one line it ran into the exaggeration
        # note (upper right) in pictures narrower than about 700 pixels.
        text = Show(Text(Text="Snow Deformation, t = %.1f s\na wheel (r = %.2f m) at %.1f m/s in "
                              "%.1f m of snow" % (time, RADIUS, SPEED, DEPTH)), view)
        text.WindowLocation = "Upper Left Corner"
        text.Justification = "Left"
        text.FontSize = 15
        text.Color = [1.0, 1.0, 1.0]
        _readable(text)
    wheel = Show(OutputPort(snow, 1), view)
    wheel.Representation = "Surface"
    wheel.ColorArrayName = ["POINTS", ""]
    wheel.AmbientColor = wheel.DiffuseColor = [0.16, 0.16, 0.18]
    wheel.Specular = 0.3

    # A low light from the north-west (scene coordinates, so the same in every
    # frame) draws the trench walls and rims as light and shadow; the
    # camera's headlight only fills in.
    view.UseLight = 0
    sun = AddLight(view=view)
    sun.Coords = "Scene"
    sun.Type = "Directional"
    sun.Position = [-1.0, 0.6, 0.7]
    sun.FocalPoint = [0.0, 0.0, 0.0]
    sun.Intensity = 1.0
    fill = AddLight(view=view)
    fill.Coords = "Camera"
    fill.Type = "Directional"
    fill.Position = [0.0, 0.0, 1.0]
    fill.FocalPoint = [0.0, 0.0, 0.0]
    fill.Intensity = 0.6

    # Seen from the south, a little above, framing the band the path crosses.
    # (paraview.simple resets the camera at its first render: do it first.)
    Render(view)
    b = surface.GetDataInformation().GetBounds()
    cx, cy = 0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3])
    span = b[1] - b[0]
    cam = view.GetActiveCamera()
    cam.SetViewUp(0, 0, 1)
    cam.SetViewAngle(25.0)
    if close:
        # Nine metres back from the wheel, to its south-west, along the trench.
        w = OutputPort(snow, 1).GetDataInformation().GetBounds()
        wx, wy, wz = 0.5 * (w[0] + w[1]), 0.5 * (w[2] + w[3]), w[4]
        cam.SetFocalPoint(wx - 1.4, wy - 0.9, wz)
        cam.SetPosition(wx - 5.4, wy - 7.7, wz + 4.0)
        cam.SetViewAngle(35.0)
    else:
        cam.SetFocalPoint(cx, cy, b[4])
        cam.SetPosition(cx + 0.1 * span, cy - 0.95 * span, b[5] + 0.5 * span)
        view.ResetCamera(b[0] + 0.04 * span, b[1] - 0.04 * span, cy - 0.2 * span,
                         cy + 0.32 * span, b[4], b[5], False)
        # ResetCamera fits the band's bounding sphere, with room to spare.
        cam.Dolly(1.45)
    view.CenterOfRotation = cam.GetFocalPoint()
    Render(view)
    return view


# ---- Snow Accumulation: a hut and trees under wind-driven snow, then a sledge ----
# (demo_snow_accumulation.py and test_images.py --scene accumulation)

# Heavy snow, 8 cm/h for 4 h, driven by a west wind 30 degrees off vertical
# and fluttering by up to 3 degrees a step: walls and roofs leave their
# shadows to the east. A slope holds 0.6 m at most (MaxDepth cos(slope)).
TILT, FLUTTER = 30.0, 3.0
RATE, HOURS, MAX_DEPTH = 8.0, 4.0, 0.6
# The hut, in metres: walls 3 m (x) by 4 m (y), eaves 2.2 m and ridge 3.3 m
# above the ground; the roof overhangs 0.4 m at the sides and the north
# gable, and runs on 1.8 m over a porch on two posts at the south gable.
HUT = dict(x=6.2, y=8.6, width=3.0, length=4.0, eave=2.2, ridge=3.3, overhang=0.4, porch=1.8)
# Trees: (x, y, height, crown radius) on the 14.35 m patch.
TREES = ((2.0, 11.0, 4.6, 1.3), (3.6, 13.0, 3.6, 1.0), (12.0, 12.4, 4.2, 1.2),
         (1.9, 6.4, 3.0, 0.9))
# A sledge 1.5 m long, 0.6 m wide and 0.3 m high (a box with its nose
# bevelled up) pulled at 3 m/s, riding 0.12 m into the fresh snow.
SLEDGE_LENGTH, SLEDGE_WIDTH, SLEDGE_HEIGHT = 1.5, 0.6, 0.3
SLEDGE_SINK, SLEDGE_SPEED = 0.12, 3.0
# The pictures draw less snow than this (m) as bare ground: the lowest
# value of the plugin's Graupel Snow Depth map.
BARE = 0.005


def _closed(faces):
    """One convex solid from its faces [(points, triangles)]: the points kept
    per face (flat normals: a cap on a roof, none on its walls), every
    triangle wound counter-clockwise seen from outside (away from the
    solid's mean point). Returns a vtkPolyData."""
    from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData

    pts, tris, n = [], [], 0
    for p, t in faces:
        pts.append(np.asarray(p, dtype=float))
        tris.append(np.asarray(t, dtype=np.int64) + n)
        n += len(p)
    pts, tris = np.vstack(pts), np.vstack(tris)
    a, b, c = pts[tris[:, 0]], pts[tris[:, 1]], pts[tris[:, 2]]
    out = np.einsum("ij,ij->i", np.cross(b - a, c - a), (a + b + c) / 3.0 - pts.mean(axis=0)) < 0
    tris[out] = tris[out][:, [0, 2, 1]]
    points = vtkPoints()
    points.SetData(numpy_to_vtk(pts, deep=1))
    cells = vtkCellArray()
    cells.SetCells(len(tris), numpy_to_vtkIdTypeArray(
        np.column_stack([np.full(len(tris), 3), tris]).ravel().astype(np.int64), deep=1))
    poly = vtkPolyData()
    poly.SetPoints(points)
    poly.SetPolys(cells)
    return poly


def _quad(p0, p1, p3, step):
    """The parallelogram p0, p1, p1 + p3 - p0, p3 as a grid of about `step`
    metres: an object keeps its snow per point."""
    p0, e1, e2 = np.asarray(p0, float), np.subtract(p1, p0), np.subtract(p3, p0)
    nu = max(1, int(math.ceil(np.linalg.norm(e1) / step)))
    nv = max(1, int(math.ceil(np.linalg.norm(e2) / step)))
    v, u = np.mgrid[0:nv + 1, 0:nu + 1]
    pts = p0 + np.outer(u.ravel() / nu, e1) + np.outer(v.ravel() / nv, e2)
    k = (np.arange(nv)[:, None] * (nu + 1) + np.arange(nu)[None, :]).ravel()
    tris = np.vstack([np.column_stack([k, k + 1, k + nu + 2]),
                      np.column_stack([k, k + nu + 2, k + nu + 1])])
    return pts, tris


def _triangle(a, b, c, step):
    """The triangle a, b, c as a grid of about `step` metres."""
    a, e1, e2 = np.asarray(a, float), np.subtract(b, a), np.subtract(c, a)
    n = max(1, int(math.ceil(max(np.linalg.norm(e1), np.linalg.norm(e2)) / step)))
    ij = [(i, j) for j in range(n + 1) for i in range(n + 1 - j)]
    index = {q: k for k, q in enumerate(ij)}
    pts = np.array([a + i / n * e1 + j / n * e2 for i, j in ij])
    tris = [(index[i, j], index[i + 1, j], index[i, j + 1]) for i, j in ij if i + j < n]
    tris += [(index[i + 1, j], index[i + 1, j + 1], index[i, j + 1])
             for i, j in ij if i + j < n - 1]
    return pts, np.array(tris)


def _box(x0, x1, y0, y1, z0, z1, step=0.25):
    return _closed([_quad((x0, y0, z), (x1, y0, z), (x0, y1, z), step) for z in (z0, z1)]
                   + [_quad((x0, y, z0), (x1, y, z0), (x0, y, z1), step) for y in (y0, y1)]
                   + [_quad((x, y0, z0), (x, y1, z0), (x, y0, z1), step) for x in (x0, x1)])


def _cone(x, y, z0, z1, r0, r1, sides=24, rings=8):
    """A frustum (r1 = 0: a cone) about the vertical through x, y, from z0
    to z1, closed by flat disks."""
    a = np.linspace(0.0, 2.0 * math.pi, sides, endpoint=False)
    ring = np.column_stack([np.cos(a), np.sin(a)])
    side = [np.column_stack([x + r * ring[:, 0], y + r * ring[:, 1], np.full(sides, z)])
            for r, z in zip(np.linspace(r0, r1, rings + 1), np.linspace(z0, z1, rings + 1))]
    k = np.arange(sides)
    tris = []
    for m in range(rings):
        lo, hi = m * sides + k, (m + 1) * sides + k
        hi1 = (m + 1) * sides + (k + 1) % sides
        tris.append(np.column_stack([lo, m * sides + (k + 1) % sides, hi1]))
        if m + 1 < rings or r1 > 0:  # a cone's apex ring is one point
            tris.append(np.column_stack([lo, hi1, hi]))
    faces = [(np.vstack(side), np.vstack(tris))]
    for r, z in ((r0, z0), (r1, z1)):
        if r > 0:
            disk = np.vstack([[x, y, z], np.column_stack([x + r * ring[:, 0], y + r * ring[:, 1],
                                                          np.full(sides, z)])])
            fan = np.column_stack([np.zeros(sides, int), 1 + k, 1 + (k + 1) % sides])
            faces.append((disk, fan))
    return _closed(faces)


def _producer(data):
    """A pipeline source for a dataset built here (pvbatch runs builtin)."""
    source = pvs.TrivialProducer()
    source.GetClientSideObject().SetOutput(data)
    return source


def scene_objects(terrain):
    """The hut (walls, a roof with its porch, two posts) and the trees (a
    trunk and a crown each) on `terrain`, set 0.3 m into the ground below
    their lowest point: a vtkMultiBlockDataSet, one closed mesh a block."""
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonDataModel import vtkMultiBlockDataSet

    h = HUT
    x0, x1 = h["x"] - 0.5 * h["width"], h["x"] + 0.5 * h["width"]
    y0, y1 = h["y"] - 0.5 * h["length"], h["y"] + 0.5 * h["length"]
    o = h["overhang"]
    rx0, rx1, ry0, ry1 = x0 - o, x1 + o, y0 - h["porch"], y1 + o
    xs, ys = np.meshgrid(np.linspace(rx0, rx1, 9), np.linspace(ry0, ry1, 9))
    base = float(_elevation_at(terrain, xs.ravel(), ys.ravel()).min())
    eave, ridge = base + h["eave"], base + h["ridge"]
    # The roof: a closed prism, its slopes down to the eaves, its underside
    # flat at eave height over the walls and the porch.
    roof = _closed([
        _quad((rx0, ry0, eave), (rx0, ry1, eave), (h["x"], ry0, ridge), 0.25),
        _quad((rx1, ry0, eave), (rx1, ry1, eave), (h["x"], ry0, ridge), 0.25),
        _quad((rx0, ry0, eave), (rx1, ry0, eave), (rx0, ry1, eave), 0.25),
        _triangle((rx0, ry0, eave), (rx1, ry0, eave), (h["x"], ry0, ridge), 0.25),
        _triangle((rx0, ry1, eave), (rx1, ry1, eave), (h["x"], ry1, ridge), 0.25)])
    # With a cell array 'part' (0 wall, 1 roof, 2 trunk, 3 crown) for the
    # pictures' colours: Snow Accumulation passes the objects' arrays on.
    parts = [(_box(x0, x1, y0, y1, base - 0.3, eave), 0), (roof, 1)]
    parts += [(_box(px - 0.08, px + 0.08, ry0 + 0.1, ry0 + 0.26, base - 0.3, eave), 0)
              for px in (x0 + 0.1, x1 - 0.1)]
    for x, y, height, radius in TREES:
        z = float(_elevation_at(terrain, x, y))
        parts.append((_cone(x, y, z - 0.3, z + 0.25 * height, 0.14, 0.1, sides=10, rings=2), 2))
        parts.append((_cone(x, y, z + 0.2 * height, z + height, radius, 0.0), 3))
    blocks = vtkMultiBlockDataSet()
    for k, (part, kind) in enumerate(parts):
        tag = numpy_to_vtk(np.full(part.GetNumberOfCells(), kind, dtype=np.int32), deep=1)
        tag.SetName("part")
        part.GetCellData().AddArray(tag)
        blocks.SetBlock(k, part)
    return blocks


def _sledge():
    """The sledge, centred on its bounds' centre, its length along +x (a
    Path turns +x along its tangent), the front of its underside bevelled up
    so that it rides onto the snow rather than ploughing it."""
    L, W, H = SLEDGE_LENGTH, SLEDGE_WIDTH, SLEDGE_HEIGHT
    profile = [(-0.5 * L, -0.5 * H), (0.3 * L, -0.5 * H), (0.5 * L, 0.0), (0.5 * L, 0.5 * H),
               (-0.5 * L, 0.5 * H)]
    faces = []
    for (ax, az), (bx, bz) in zip(profile, profile[1:] + profile[:1]):
        faces.append(_quad((ax, -0.5 * W, az), (bx, -0.5 * W, bz), (ax, 0.5 * W, az), 10.0))
    for y in (-0.5 * W, 0.5 * W):
        pts = np.array([(px, y, pz) for px, pz in profile])
        faces.append((pts, np.array([(0, k, k + 1) for k in range(1, len(profile) - 1)])))
    # Snow Deformation wants a closed surface: its faces' corners merged.
    from vtkmodules.vtkFiltersCore import vtkCleanPolyData

    clean = vtkCleanPolyData()
    clean.SetInputData(_closed(faces))
    clean.Update()
    return clean.GetOutput()


def build_accumulation(cells=288, spacing=0.05, time_step=300.0, resolution=768,
                       sledge_step=0.02):
    """The pipeline: a cells x cells terrain of `spacing` metres (14.35 m at
    the defaults) with half a metre of relief, the hut and trees, HOURS of
    wind-driven snow in steps of `time_step` seconds, then the sledge along
    a curve south and east of the hut (Snow Deformation on Snow
    Accumulation's port 0 at the end of the snowfall). Returns
    (accumulation, deformation, the deformation's end time, the path's
    points)."""
    size = (cells - 1) * spacing
    terrain = _constructor("ProceduralTerrain")(
        Dimensions=[cells, cells], Spacing=spacing, Seed=11, NoiseType="fBm", Octaves=3,
        Frequency=50.0, HeightScale=0.6)
    terrain.UpdatePipeline()
    objects = _producer(scene_objects(terrain))
    end = HOURS * 3600.0
    acc = _constructor("SnowAccumulation")(Input=terrain, Objects=objects)
    acc.SnowDirection = [math.sin(math.radians(TILT)), 0.0, -math.cos(math.radians(TILT))]
    acc.Flutter = FLUTTER
    acc.SnowfallRate = RATE
    acc.MaxDepth = MAX_DEPTH
    acc.NoiseScale = 1.5
    acc.Seed = 3
    acc.ExposureResolution = resolution
    acc.TimeStep = time_step
    acc.EndTime = end
    acc.OutputInterval = end
    acc.UpdatePipeline(end)

    # From the west edge past the porch, then north-east through the lee of
    # the hut to the east edge: the sledge rides SLEDGE_SINK into the snow
    # as it lies (smoothed over half a metre), never closer than 3 cm to the
    # ground.
    u = np.linspace(0.0, 1.0, 201)
    x = size * (0.05 + 0.9 * u)
    y = size * (0.17 + 0.05 * np.sin(math.pi * u) + 0.45 * u ** 4)
    img = servermanager.Fetch(acc)
    surface = _sample(img, "snow_surface", x, y)
    ground = _sample(img, "elevation", x, y)
    width = max(1, int(round(0.25 / (size * 0.9 / 200))))
    kernel = np.ones(2 * width + 1) / (2 * width + 1)
    smooth = np.convolve(np.pad(surface, width, mode="edge"), kernel, mode="valid")
    z = np.maximum(smooth - SLEDGE_SINK, ground + 0.03) + 0.5 * SLEDGE_HEIGHT
    path = PolyLineSource(Points=np.column_stack([x, y, z]).ravel().tolist())
    length = float(np.sum(np.hypot(np.hypot(np.diff(x), np.diff(y)), np.diff(z))))

    crossing = round(0.95 * length / SLEDGE_SPEED, 2)
    # The sledge starts from the snow as it lies at the end of the snowfall
    # (a simulation reads another's output at its end: InputTime), whatever
    # time its own seconds ask for.
    snow = _constructor("SnowDeformation")(Input=acc, Objects=_producer(_sledge()), Path=path)
    snow.TimeStep = sledge_step
    snow.EndTime = crossing
    snow.OutputInterval = crossing
    snow.MaxSlope = MAX_SLOPE
    snow.ObjectVelocity = [SLEDGE_SPEED, 0.0, 0.0]
    return acc, snow, crossing, np.column_stack([x, y, z])


def _sample(img, name, x, y):
    """Bilinear samples of the point array `name` of a 2-D image at x, y."""
    nx, ny, _ = img.GetDimensions()
    ox, oy, _ = img.GetOrigin()
    sx, sy, _ = img.GetSpacing()
    z = vtk_to_numpy(img.GetPointData().GetArray(name)).reshape(ny, nx)
    fx = np.clip((np.asarray(x) - ox) / sx, 0, nx - 1.000001)
    fy = np.clip((np.asarray(y) - oy) / sy, 0, ny - 1.000001)
    i, j = fx.astype(int), fy.astype(int)
    u, v = fx - i, fy - j
    return ((1 - u) * (1 - v) * z[j, i] + u * (1 - v) * z[j, i + 1]
            + (1 - u) * v * z[j + 1, i] + u * v * z[j + 1, i + 1])


def show_accumulation(acc, end, snow=None, crossing=None, size=(1024, 768), bar=True,
                      label=True):
    """Renders the snowfall (Snow Accumulation `acc` at `end`) or, with
    `snow`, the sledge's crossing (Snow Deformation at `crossing`, the sledge
    at its pose): the snow surface coloured by snow_depth from bare ground
    (brown) through thin snow (blue) to deep (white), the hut and trees as
    they stand at `end` with their snow caps (Warp By Vector of snow_offset,
    coloured the same), and an arrow along the snow's direction. Returns
    the view."""
    view = GetActiveViewOrCreate("RenderView")
    view.ViewTime = end if snow is None else crossing
    view.ViewSize = list(size)
    view.OrientationAxesVisibility = 0
    view.Background = [0.32, 0.34, 0.43]
    if hasattr(view, "UseColorPaletteForBackground"):
        view.UseColorPaletteForBackground = 0
    surface = WarpByScalar(Input=acc if snow is None else snow,
                           Scalars=["POINTS", "snow_surface"], ScaleFactor=1.0)
    surface = GenerateSurfaceNormals(Input=ExtractSurface(Input=surface), Splitting=0)
    display = Show(surface, view)
    display.Representation = "Surface"
    ColorBy(display, ("POINTS", "snow_depth"))
    # The plugin's snow depth map on its own range: a 5 mm dusting grey-blue,
    # 30 cm and more white; bare ground (under 5 mm, below the range) brown.
    lut = GetColorTransferFunction("snow_depth")
    lut.ApplyPreset("Graupel Snow Depth", False)
    lut.AutomaticRescaleRangeMode = "Never"
    lut.UseBelowRangeColor = 1
    lut.BelowRangeColor = [0.42, 0.31, 0.21]
    display.SetScalarBarVisibility(view, bar)
    if bar:
        _legend(GetScalarBar(lut, view), "snow depth (m)", "%.3g", x=0.45, length=0.45)
        # What the bar's below-range swatch stands for.
        key = Show(Text(Text="brown: bare ground"), view)
        key.WindowLocation = "Lower Left Corner"
        key.FontSize = 14
        key.Color = [1.0, 0.84, 0.66]
        _readable(key)
    _note(view, 1.0)
    if label:
        words = ("Snow Accumulation: %g h of %g cm/h snow, driven by a west wind %g\u00b0 off "
                 "vertical" % (HOURS, RATE, TILT)) if snow is None else (
            "Snow Deformation on the accumulated snow: a sledge at %g m/s, t = %.1f s"
            % (SLEDGE_SPEED, crossing))
        text = Show(Text(Text=words), view)
        text.WindowLocation = "Upper Left Corner"
        text.FontSize = 16
        text.Color = [1.0, 1.0, 1.0]
        _readable(text)

    # The objects as they stand at the end of the snowfall, whatever the
    # view's time (the sledge's seconds are no time for the snowfall).
    objects = pvs.ForceTime(Input=OutputPort(acc, 1), IgnorePipelineTime=1, ForcedTime=end)
    plain = Show(objects, view)
    plain.Representation = "Surface"
    ColorBy(plain, ("CELLS", "part"))
    parts = GetColorTransferFunction("part")
    parts.InterpretValuesAsCategories = 1
    parts.Annotations = ["0", "wall", "1", "roof", "2", "trunk", "3", "crown"]
    parts.IndexedColors = [0.55, 0.33, 0.18, 0.30, 0.16, 0.12, 0.32, 0.22, 0.14,
                           0.10, 0.30, 0.14]
    plain.SetScalarBarVisibility(view, False)
    caps = pvs.Threshold(Input=pvs.WarpByVector(Input=objects, Vectors=["POINTS", "snow_offset"]),
                         Scalars=["POINTS", "snow_depth"], LowerThreshold=BARE,
                         UpperThreshold=100.0, AllScalars=1)
    cap = Show(caps, view)
    cap.Representation = "Surface"
    ColorBy(cap, ("POINTS", "snow_depth"))
    # The preset's own range (colouring the caps may have moved it).
    lut.RescaleTransferFunction(BARE, 0.3)
    if snow is not None:
        sledge = Show(OutputPort(snow, 1), view)
        sledge.Representation = "Surface"
        sledge.ColorArrayName = ["POINTS", ""]
        sledge.AmbientColor = sledge.DiffuseColor = [0.75, 0.12, 0.10]
        sledge.Specular = 0.3
    # The snow's direction: an arrow 2 m long over the west edge.
    b = surface.GetDataInformation().GetBounds()
    arrow = pvs.Transform(Input=pvs.Arrow(TipRadius=0.12, ShaftRadius=0.04))
    arrow.Transform.Scale = [2.5, 2.5, 2.5]
    arrow.Transform.Rotate = [0.0, 90.0 - TILT, 0.0]
    arrow.Transform.Translate = [b[0] + 0.6, HUT["y"], b[5] + 2.2]
    shown = Show(arrow, view)
    shown.ColorArrayName = ["POINTS", ""]
    shown.AmbientColor = shown.DiffuseColor = [1.0, 0.75, 0.1]

    view.UseLight = 0
    sun = AddLight(view=view)
    sun.Coords = "Scene"
    sun.Type = "Directional"
    sun.Position = [-0.8, -1.0, 0.9]
    sun.FocalPoint = [0.0, 0.0, 0.0]
    sun.Intensity = 0.9
    fill = AddLight(view=view)
    fill.Coords = "Camera"
    fill.Type = "Directional"
    fill.Position = [0.0, 0.0, 1.0]
    fill.FocalPoint = [0.0, 0.0, 0.0]
    fill.Intensity = 0.6

    # From the south-east, above: the porch, the lee (east) side of the hut
    # and, for the snowfall, close to the hut; for the sledge, the whole
    # patch with the band it crosses.
    Render(view)
    cx, cy = 0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3])
    span = b[1] - b[0]
    cam = view.GetActiveCamera()
    cam.SetViewUp(0, 0, 1)
    cam.SetViewAngle(30.0)
    if snow is None:
        focus = (HUT["x"] + 0.8, HUT["y"] - 0.6, b[4] + 1.2)
        cam.SetFocalPoint(*focus)
        cam.SetPosition(focus[0] + 11.0, focus[1] - 12.0, focus[2] + 10.5)
    else:
        cam.SetFocalPoint(cx, cy, b[4])
        cam.SetPosition(cx + 0.85 * span, cy - 0.75 * span, b[5] + 0.9 * span)
        view.ResetCamera(b[0], b[1], b[2], b[3], b[4], b[5] + 3.0, False)
        cam.Dolly(1.3)
    view.CenterOfRotation = cam.GetFocalPoint()
    Render(view)
    return view
