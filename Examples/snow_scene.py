"""The snow deformation scene shared by the demo (demo_snow_deformation.py)
and the reference-image test (Testing/Python/test_images.py --scene snow): a
wheel rolling through snow along an S-shaped path over a small patch of
procedural terrain, rendered with the snow surface warped, coloured by
density, and the wheel at its pose."""
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
    lut = GetColorTransferFunction("snow_density")
    # Untouched snow white, pressed snow through pale blue to deep blue at
    # 400 kg/m^3 (the default top of the density range).
    lut.RGBPoints = [DENSITY, 0.97, 0.97, 0.97, 250.0, 0.62, 0.78, 0.95,
                     320.0, 0.20, 0.45, 0.85, 400.0, 0.05, 0.15, 0.50]
    lut.ColorSpace = "RGB"
    lut.AutomaticRescaleRangeMode = "Never"
    lut.RescaleTransferFunction(DENSITY, 400.0)
    display.SetScalarBarVisibility(view, bar)
    if bar:
        sb = GetScalarBar(lut, view)
        sb.Title = "snow density (kg/m\u00b3)"
        sb.ComponentTitle = ""
        sb.TitleColor = sb.LabelColor = [1.0, 1.0, 1.0]
        sb.WindowLocation = "Any Location"
        sb.Orientation = "Horizontal"
        sb.Position = [0.33, 0.04]
        sb.ScalarBarLength = 0.34
        sb.RangeLabelFormat = "%.0f"
        sb.LabelFormat = "%.0f"
    if label:
        text = Show(Text(Text="Snow Deformation: a wheel (radius %.2f m) at %.1f m/s through "
                              "%.1f m of snow, t = %.1f s" % (RADIUS, SPEED, DEPTH, time)), view)
        text.WindowLocation = "Upper Left Corner"
        text.FontSize = 16
        text.Color = [1.0, 1.0, 1.0]
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
