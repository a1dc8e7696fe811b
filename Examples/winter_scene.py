"""A winter scene (seed 001's landscape): a procedural terrain after half a
day of wind-driven snowfall (Snow Accumulation: the snow lies where the wind
reaches and the slope holds it, rock shows on the steep and sheltered
faces), its snow surface analysed (Terrain Analysis on snow_surface), lit by a low
sun with the terrain's cast shadows (Terrain Shadow), snow falling (Snowfall
Particles), a cloud sky (Cloud Cover) and a lightning bolt striking the
terrain (Lightning), in distance haze.

    xvfb-run -a pvbatch Examples/winter_scene.py --out out [--cells 256]
        [--plugin build/lib/paraview-5.11/plugins/Graupel/Graupel.so]

writes out/winter_scene.png (about 15 s on PoCL on two cores). The
reference-image test (Testing/Python/test_images.py --scene winter) draws
the same scene at 400 x 300 pixels.
"""
import argparse
import os
import sys

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, here)
import landscape_scene as L  # noqa: E402

EXAGGERATION = 1.5
HEIGHT = 200.0  # m: the terrain's relief
SUN_AZIMUTH, SUN_ELEVATION, PENUMBRA = 250.0, 14.0, 1.5  # deg: a low winter sun, WSW
SNOW_EXPONENT, ROCK_SLOPE = 4.0, 40.0
TIME = 20.0  # s: the moment shown (flakes, clouds, bolt)
# The snowfall: 12 h of 4 cm/h on a west-south-west wind, 54 deg off vertical.
SNOW_HOURS, SNOW_RATE = 12.0, 4.0
SNOW_DIRECTION = [1.3, 0.5, -1.0]
FULL_DEPTH = 0.4  # m: snow this deep is drawn white
# Colours (linear 0-1): rock to snow by snow depth over FULL_DEPTH; sunlight warm, the
# shadows lit by the blue sky; the haze and the sky.
COVER_STOPS = [(0.0, 0.26, 0.23, 0.21), (0.35, 0.45, 0.43, 0.43), (0.65, 0.86, 0.88, 0.92),
               (1.0, 0.98, 0.99, 1.0)]
SUN = np.array([1.0, 0.96, 0.88])
SKYLIGHT = np.array([0.46, 0.55, 0.74])
HAZE = [0.72, 0.76, 0.83]
ZENITH = [0.36, 0.45, 0.62]
STORM = ([0.80, 0.82, 0.86], [0.38, 0.40, 0.46])  # cloud colour, thin to thick
FOG_LENGTH = 4000.0  # m: 1 - 1/e of the haze at this distance


def build(cells=192, spacing=8.0, seed=2026, flakes=12000):
    """The pipeline, on a cells x cells terrain of `spacing` metres. Returns
    a dict of its proxies."""
    P = L.constructor
    terrain = P("ProceduralTerrain")(Dimensions=[cells, cells], Spacing=spacing, Seed=seed,
                                     Frequency=1.5, HeightScale=HEIGHT, Octaves=5)
    end = SNOW_HOURS * 3600.0
    acc = P("SnowAccumulation")(Input=terrain, TimeStep=1800.0, EndTime=end, OutputInterval=end,
                                SnowDirection=SNOW_DIRECTION, SnowfallRate=SNOW_RATE,
                                MaxDepth=0.5, NoiseScale=60.0, NoiseAmplitude=0.3,
                                BlurRadius=2, ExposureResolution=2 * cells, Seed=4)
    shadow = P("TerrainShadow")(Input=acc, HeightArray="snow_surface", SunAzimuth=SUN_AZIMUTH,
                                SunElevation=SUN_ELEVATION, PenumbraWidth=PENUMBRA)
    analysis = P("TerrainAnalysis")(Input=shadow, HeightArray="snow_surface",
                                    SunAzimuth=SUN_AZIMUTH, SunElevation=SUN_ELEVATION,
                                    SnowExponent=SNOW_EXPONENT, RockSlope=ROCK_SLOPE)
    size = (cells - 1) * spacing
    snow = P("SnowfallParticles")(Input=terrain, Count=flakes, Wind=[2.0, 1.0, 0.0],
                                  FlutterAmplitude=0.5, Seed=5,
                                  Region=[0.0, size, 0.0, size, 0.0, 120.0])
    clouds = P("CloudCover")(Cover=0.65, Scale=3000.0, Sharpness=0.95, Resolution=256,
                             Size=24000.0, Seed=3, WindSpeed=8.0)
    return dict(terrain=terrain, acc=acc, shadow=shadow, analysis=analysis, snow=snow,
                clouds=clouds,
                size=size, spacing=spacing, cells=cells)


def camera(parts, size):
    s = parts["size"]
    top = EXAGGERATION * HEIGHT
    return L.Camera(position=[0.62 * s, -0.50 * s, top + 0.06 * s],
                    focal=[0.45 * s, 0.70 * s, 0.75 * top], size=size)


def show(parts, size=(1024, 640), scratch=".", title=True):
    """Renders the scene; returns (view, numbers) with the numbers the test
    checks."""
    P = L.constructor
    cam = camera(parts, size)
    ground = L.fetch(parts["analysis"])
    x, y, z = L.points_xyz(ground, EXAGGERATION, "snow_surface")
    pd = ground.GetPointData()
    depth = vtk_to_numpy(pd.GetArray("snow_depth")).astype(np.float64)
    cover = np.clip(depth / FULL_DEPTH, 0.0, 1.0)
    sun = vtk_to_numpy(pd.GetArray("hillshade")) * vtk_to_numpy(pd.GetArray("shadow"))
    nz = vtk_to_numpy(pd.GetArray("normal"))[:, 2]
    base = L.ramp(cover, COVER_STOPS)
    # Sun (hillshade x cast shadow) plus the sky's blue light, which reaches
    # flat ground more than steep walls.
    light = sun[:, None] * SUN[None, :] + (0.55 + 0.25 * nz)[:, None] * SKYLIGHT[None, :]
    rgb = L.fog(np.clip(base * light, 0.0, 1.0), cam.distance(x, y, z), HAZE, FOG_LENGTH)

    clouds = L.fetch(parts["clouds"], TIME)
    top = EXAGGERATION * HEIGHT
    png = L.sky_texture(os.path.join(scratch, "winter_sky.png"), cam, clouds,
                        cloud_altitude=top + 900.0, zenith=ZENITH, horizon=HAZE, haze=HAZE,
                        length=3.0 * FOG_LENGTH, storm=STORM)
    view = L.new_view(size, png)
    view.ViewTime = TIME
    L.show_rgb(L.surface_rgb(ground, EXAGGERATION, "snow_surface", rgb), view)

    # Flakes: the source's points, lifted by the exaggeration with the
    # terrain they fall on.
    snow = L.fetch(parts["snow"], TIME)
    flakes = P("Transform")(Input=L.producer(snow))
    flakes.Transform.Scale = [1.0, 1.0, EXAGGERATION]
    f = pvs_show(flakes, view)
    f.SetRepresentationType("Points")
    f.ColorArrayName = ["POINTS", ""]
    f.AmbientColor = f.DiffuseColor = [1.0, 1.0, 1.0]
    f.Ambient, f.Diffuse = 1.0, 0.0
    f.PointSize = 1.5
    f.Opacity = 0.85

    # The bolt strikes the drawn (warped) surface.
    warped = L.surface_rgb(ground, EXAGGERATION, "snow_surface", rgb)
    bolt = P("Lightning")(Input=warped, Seed=11, Strands=6, Jitter=0.12)
    # A wide faint line under the bolt for the seed's blurred glow (a second
    # proxy: a view has one representation per proxy).
    glow = P("Transform")(Input=bolt)
    for proxy, width, opacity, colour in ((glow, 10.0, 0.3, [0.6, 0.7, 1.0]),
                                          (bolt, 2.5, 1.0, [1.0, 1.0, 1.0])):
        b = pvs_show(proxy, view)
        b.ColorArrayName = ["POINTS", ""]
        b.AmbientColor = b.DiffuseColor = colour
        b.Ambient, b.Diffuse = 1.0, 0.0
        b.LineWidth = width
        b.Opacity = opacity

    L.legend(view, "snow_depth", [(FULL_DEPTH * v,) + tuple(c) for v, *c in COVER_STOPS],
             "snow depth (m)", position=(0.04, 0.03), fmt="%.1f")
    L.label(view, "vertical exaggeration %g\u00d7" % EXAGGERATION, "Lower Right Corner", 13)
    if title:
        L.label(view, "Winter: %g h of %g cm/h snow on a west wind, sun %g\u00b0 high from %g\u00b0"
                % (SNOW_HOURS, SNOW_RATE, SUN_ELEVATION, SUN_AZIMUTH), "Upper Left Corner", 15)
    pvs_render(view)  # the first render resets the camera: set it after
    cam.apply(view)
    pvs_render(view)

    bolt_out = L.fetch(bolt, TIME)
    numbers = dict(snow_fraction=float(np.mean(depth > 0.5 * FULL_DEPTH)),
                   rock_fraction=float(np.mean(depth < 0.1 * FULL_DEPTH)),
                   acc_balance=float(L.fetch(parts["acc"]).GetFieldData().GetArray(
                       "balance_error").GetTuple1(0)),
                   shadow_fraction=float(np.mean(vtk_to_numpy(pd.GetArray("shadow")) < 0.5)),
                   flakes=snow.GetNumberOfPoints(), bolt_points=bolt_out.GetNumberOfPoints(),
                   cloud_fraction=float(np.mean(vtk_to_numpy(
                       clouds.GetPointData().GetArray("cloud")) > 0)))
    return view, numbers


def pvs_show(proxy, view):
    from paraview.simple import Show
    return Show(proxy, view)


def pvs_render(view):
    from paraview.simple import Render
    Render(view)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--out", default="out")
    p.add_argument("--cells", type=int, default=256)
    p.add_argument("--width", type=int, default=1024)
    p.add_argument("--height", type=int, default=640)
    p.add_argument("--plugin", default=os.path.join(
        here, "..", "build", "lib", "paraview-5.11", "plugins", "Graupel", "Graupel.so"))
    a, _ = p.parse_known_args()
    os.makedirs(a.out, exist_ok=True)
    L.load_plugin(a.plugin)
    parts = build(cells=a.cells, spacing=1528.0 / (a.cells - 1))
    size = (a.width, a.height)
    view, numbers = show(parts, size, scratch=a.out)
    from paraview.simple import SaveScreenshot
    SaveScreenshot(os.path.join(a.out, "winter_scene.png"), view, ImageResolution=list(size))
    print("winter scene:", ", ".join("%s %s" % kv for kv in sorted(numbers.items())))


if __name__ == "__main__":
    main()
