"""What the two landscape scenes (winter_scene.py, rain_scene.py) share: a
camera fixed by hand, a sky background ray-cast from Cloud Cover's image
through that camera, and distance fog. ParaView 5.11 has no fog (VTK's
OpenGL2 renderer dropped it, and no view property offers it), so the fog is
baked into the colours: every surface is coloured by a per-point RGB array,
already lit, blended towards the haze colour by its distance from the camera
as seed 004 does (mix(colour, fog, 1 - exp(-d / L))), and shown with scalar
mapping off and the renderer's lighting off. The sky behind is an image of
the same fog and the Cloud Cover layer seen from the same camera, shown as
the view's texture background, so sky and terrain meet in one haze."""
import math
import os

import numpy as np
import paraview.simple as pvs
from paraview.simple import (CreateTexture, GetActiveViewOrCreate, GetColorTransferFunction,
                             GetScalarBar, Show, Text, TrivialProducer)
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.vtkCommonDataModel import vtkImageData
from vtkmodules.vtkIOImage import vtkPNGWriter

VIEW_ANGLE = 30.0  # degrees, vertical: ParaView's default CameraViewAngle


def constructor(name):
    """paraview.simple's constructor for a Graupel proxy: LoadPlugin(..., ns=)
    adds them to the caller's namespace only, so add them here too."""
    if not hasattr(pvs, name):
        pvs._add_functions(vars(pvs))
    return getattr(pvs, name)


def load_plugin(path):
    if not hasattr(pvs, "ProceduralTerrain"):
        pvs.LoadPlugin(os.path.abspath(path), ns=vars(pvs))
        pvs._add_functions(vars(pvs))


def points_xyz(img, exaggeration, height):
    """World x, y and the drawn (exaggerated) z of a 2-D image's points, in
    point order, with z = exaggeration x the point array `height`."""
    nx, ny, _ = img.GetDimensions()
    ox, oy, _ = img.GetOrigin()
    sx, sy, _ = img.GetSpacing()
    j, i = np.mgrid[0:ny, 0:nx]
    z = vtk_to_numpy(img.GetPointData().GetArray(height)).astype(np.float64)
    return (ox + i * sx).ravel(), (oy + j * sy).ravel(), exaggeration * z


class Camera:
    """A pinhole camera from `position` to `focal` with z up, ParaView's
    vertical view angle and the picture's size in pixels."""

    def __init__(self, position, focal, size):
        self.position = np.asarray(position, float)
        self.focal = np.asarray(focal, float)
        self.size = tuple(size)
        f = self.focal - self.position
        self.forward = f / np.linalg.norm(f)
        r = np.cross(self.forward, [0.0, 0.0, 1.0])
        self.right = r / np.linalg.norm(r)
        self.up = np.cross(self.right, self.forward)

    def apply(self, view):
        view.CameraPosition = self.position.tolist()
        view.CameraFocalPoint = self.focal.tolist()
        view.CameraViewUp = self.up.tolist()
        view.CameraViewAngle = VIEW_ANGLE
        view.CameraParallelProjection = 0

    def distance(self, x, y, z):
        return np.sqrt((x - self.position[0]) ** 2 + (y - self.position[1]) ** 2
                       + (z - self.position[2]) ** 2)

    def rays(self):
        """Unit ray directions through the pixel centres, shape (h, w, 3),
        row 0 the bottom row (VTK's image order)."""
        w, h = self.size
        t = math.tan(math.radians(0.5 * VIEW_ANGLE))
        v = (np.arange(h) + 0.5 - 0.5 * h) / (0.5 * h) * t
        u = (np.arange(w) + 0.5 - 0.5 * w) / (0.5 * h) * t
        uu, vv = np.meshgrid(u, v)
        d = (self.forward[None, None, :] + uu[..., None] * self.right[None, None, :]
             + vv[..., None] * self.up[None, None, :])
        return d / np.linalg.norm(d, axis=2, keepdims=True)


def fog(rgb, distance, colour, length):
    """Seed 004's exponential distance fog: mix towards `colour` by
    1 - exp(-distance / length)."""
    f = (1.0 - np.exp(-np.asarray(distance) / length))[..., None]
    return rgb * (1.0 - f) + np.asarray(colour)[None, :] * f


def ramp(values, stops):
    """Colours of `values` on a piecewise-linear RGB ramp `stops` [(value, r,
    g, b), ...]: the same map a colour transfer function with these
    RGBPoints and ColorSpace RGB draws in its legend."""
    s = np.asarray(stops, float)
    return np.stack([np.interp(values, s[:, 0], s[:, c]) for c in (1, 2, 3)], axis=-1)


def sky_texture(path, camera, clouds, cloud_altitude, zenith, horizon, haze, length,
                below=None, storm=None):
    """Writes the sky behind `camera` to the PNG `path` and returns it: above
    the horizon a gradient from `horizon` to `zenith` colour, with Cloud
    Cover's `sky_rgb` (an image fetched from the source) where the ray meets
    the cloud layer at `cloud_altitude` (drawn height), fogged by the ray's
    distance to it as the terrain is; below the horizon, `below` (the haze
    colour by default), hidden by the terrain where it stands. With `storm`
    (two colours) the clouds are shaded from the first (thin) to the second
    (thickest) by their density instead of by sky_rgb."""
    d = camera.rays()
    elev = np.clip(d[..., 2], 0.0, 1.0)
    g = np.sqrt(elev)[..., None]
    rgb = np.asarray(horizon)[None, None, :] * (1.0 - g) + np.asarray(zenith)[None, None, :] * g
    nx, ny, _ = clouds.GetDimensions()
    ox, oy, _ = clouds.GetOrigin()
    sx, sy, _ = clouds.GetSpacing()
    sky = vtk_to_numpy(clouds.GetPointData().GetArray("sky_rgb")).reshape(ny, nx, 3) / 255.0
    cloud = vtk_to_numpy(clouds.GetPointData().GetArray("cloud")).reshape(ny, nx)
    up = d[..., 2] > 1e-4
    t = np.where(up, (cloud_altitude - camera.position[2]) / np.maximum(d[..., 2], 1e-4), 0.0)
    px = camera.position[0] + t * d[..., 0]
    py = camera.position[1] + t * d[..., 1]
    fi = (px - ox) / sx
    fj = (py - oy) / sy
    inside = up & (t > 0) & (fi >= 0) & (fi <= nx - 1) & (fj >= 0) & (fj <= ny - 1)
    i = np.clip(np.round(fi).astype(int), 0, nx - 1)
    j = np.clip(np.round(fj).astype(int), 0, ny - 1)
    # Clouds over the gradient by their density; the gaps keep the gradient.
    a = np.where(inside, cloud[j, i], 0.0)[..., None]
    if storm:
        c = cloud[j, i][..., None]
        shade = np.asarray(storm[0])[None, None, :] * (1 - c) + np.asarray(storm[1]) * c
    else:
        shade = sky[j, i]
    rgb = rgb * (1.0 - a) + shade * a
    rgb = np.where(inside[..., None], fog(rgb, t, haze, length), rgb)
    rgb = np.where(inside[..., None] | up[..., None], rgb, np.asarray(below or haze))
    img = vtkImageData()
    w, h = camera.size
    img.SetDimensions(w, h, 1)
    arr = numpy_to_vtk(np.clip(rgb * 255.0 + 0.5, 0, 255).astype(np.uint8).reshape(-1, 3),
                       deep=1)
    arr.SetName("rgb")
    img.GetPointData().SetScalars(arr)
    writer = vtkPNGWriter()
    writer.SetFileName(path)
    writer.SetInputData(img)
    writer.Write()
    return path


def producer(data):
    """A pipeline proxy that holds `data` (pvbatch's built-in session)."""
    p = TrivialProducer()
    p.GetClientSideObject().SetOutput(data)
    p.UpdatePipeline()
    return p


def surface_rgb(img, exaggeration, height, rgb):
    """`img` (a 2-D image) as a proxy of its warped surface: a structured
    grid with z = exaggeration x `height` and the RGB colours `rgb` (n x 3,
    0-1) as the uint8 point array `rgb`."""
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkStructuredGrid

    x, y, z = points_xyz(img, exaggeration, height)
    nx, ny, _ = img.GetDimensions()
    grid = vtkStructuredGrid()
    grid.SetDimensions(nx, ny, 1)
    pts = vtkPoints()
    pts.SetData(numpy_to_vtk(np.column_stack([x, y, z]).astype(np.float32), deep=1))
    grid.SetPoints(pts)
    for k in range(img.GetPointData().GetNumberOfArrays()):
        grid.GetPointData().AddArray(img.GetPointData().GetArray(k))
    c = numpy_to_vtk(np.clip(rgb * 255.0 + 0.5, 0, 255).astype(np.uint8), deep=1)
    c.SetName("rgb")
    grid.GetPointData().AddArray(c)
    return producer(grid)


def show_rgb(proxy, view, array="rgb"):
    """Shows `proxy` coloured by its own RGB array, unlit: its colours
    already hold the light, the shadows and the fog."""
    d = Show(proxy, view)
    d.Representation = "Surface"
    d.ColorArrayName = ["POINTS", array]
    d.MapScalars = 0
    d.Ambient, d.Diffuse, d.Specular = 1.0, 0.0, 0.0
    return d


def legend(view, array, stops, title, position, fmt="%.2g", length=0.3):
    """A horizontal colour legend for `stops` (the ramp the colours were
    made with) titled with the field and its unit."""
    lut = GetColorTransferFunction(array)
    lut.RGBPoints = [v for s in stops for v in s]
    lut.ColorSpace = "RGB"
    lut.AutomaticRescaleRangeMode = "Never"
    bar = GetScalarBar(lut, view)
    bar.Title = title
    bar.ComponentTitle = ""
    bar.TitleColor = bar.LabelColor = [1.0, 1.0, 1.0]
    bar.TitleFontSize = bar.LabelFontSize = 14
    bar.WindowLocation = "Any Location"
    bar.Orientation = "Horizontal"
    bar.Position = list(position)
    bar.ScalarBarLength = length
    bar.RangeLabelFormat = fmt
    bar.LabelFormat = fmt
    bar.DrawTickLabels = 0
    bar.Visibility = 1
    return bar


def label(view, text, location="Upper Left Corner", size=15):
    t = Show(Text(Text=text), view)
    t.WindowLocation = location
    t.FontSize = size
    t.Color = [1.0, 1.0, 1.0]
    t.Shadow = 1
    return t


def new_view(size, background_png):
    view = GetActiveViewOrCreate("RenderView")
    view.ViewSize = list(size)
    view.OrientationAxesVisibility = 0
    if hasattr(view, "UseColorPaletteForBackground"):
        view.UseColorPaletteForBackground = 0
    view.BackgroundColorMode = "Texture"
    view.BackgroundTexture = CreateTexture(background_png)
    return view


def fetch(proxy, time=None, port=0):
    """The output of `proxy` at `time` (pvbatch's built-in session: the
    filter's own output object, shallow-copied)."""
    if time is None:
        proxy.UpdatePipeline()
    else:
        proxy.UpdatePipeline(time)
    out = proxy.GetClientSideObject().GetOutputDataObject(port)
    copy = out.NewInstance()
    copy.ShallowCopy(out)
    return copy
