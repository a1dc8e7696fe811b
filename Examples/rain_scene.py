"""A rain scene (seed 004) on the real DEM in Data/ (the Jacksboro Fault,
Tennessee; 74.5 x 92.1 m cells, read at every second point): an hour of
heavy rain runs off (Rain Runoff, local inertial) and gathers in the
valleys; the water carries raindrop ripples (Water Surface on the runoff's
water_depth) and is drawn with ParaView's physically based shading (PBR,
low roughness: the sky's reflection grows towards grazing angles, the
Fresnel look of seeds 003 and 004) lit by the view's environment; rain falls
as streaks (Rain Particles' `streak` drawn as lines); and everything fades
into distance fog (ParaView 5.11 has none: see landscape_scene.py).

    xvfb-run -a pvbatch Examples/rain_scene.py --out out
        [--plugin build/lib/paraview-5.11/plugins/Graupel/Graupel.so]

writes out/rain_scene.png (about 11 s on PoCL on two cores). The
reference-image test (Testing/Python/test_images.py --scene rain_scene) draws
the same scene at 400 x 300 pixels.
"""
import argparse
import os
import sys

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, here)
import landscape_scene as L  # noqa: E402

EXAGGERATION = 2.0
RAIN_RATE, HOURS = 80.0, 1.0  # mm/h, h
WET = 0.03  # m: water shallower than this is drawn as wet ground, not water
# Colours: the ground by elevation (wet grass to bare ridge), the water by
# depth (shallow grey-green to deep blue-black), haze and sky.
GROUND_STOPS = [(230.0, 0.20, 0.29, 0.16), (550.0, 0.29, 0.34, 0.20), (800.0, 0.42, 0.40, 0.30),
                (1080.0, 0.52, 0.49, 0.42)]
DEPTH_STOPS = [(WET, 0.40, 0.58, 0.76), (0.3, 0.22, 0.44, 0.70), (1.0, 0.10, 0.28, 0.56),
               (4.0, 0.03, 0.12, 0.32)]
HAZE = [0.62, 0.65, 0.68]
ZENITH = [0.40, 0.43, 0.48]
STORM = ([0.66, 0.68, 0.71], [0.30, 0.31, 0.34])
FOG_LENGTH = 40000.0  # m
SUN_AZIMUTH, SUN_ELEVATION = 200.0, 35.0  # deg: diffuse light through the cloud


def build(data, sample=2, seconds=3600.0 * HOURS, drops=20000):
    """The pipeline on the DEM read at every `sample`-th point. Returns a dict
    of its proxies."""
    from paraview.simple import ExtractSubset, OpenDataFile
    P = L.constructor
    dem = OpenDataFile(os.path.join(data, "jacksboro_fault_dem.exr"))  # spacing in the file
    dem.UpdatePipeline()
    ext = dem.GetDataInformation().GetExtent()
    terrain = ExtractSubset(Input=dem, VOI=list(ext),
                            SampleRateI=sample, SampleRateJ=sample)
    rain = P("RainRunoff")(Input=terrain, RainRate=RAIN_RATE, EndTime=seconds,
                           OutputInterval=seconds, FlowModel="Local inertial",
                           MaxTimeStep=20.0, ManningN=0.05)
    analysis = P("TerrainAnalysis")(Input=terrain, SunAzimuth=SUN_AZIMUTH,
                                    SunElevation=SUN_ELEVATION)
    clouds = P("CloudCover")(Cover=0.85, Scale=8000.0, Sharpness=0.97, Resolution=256,
                             Size=200000.0, Seed=4, WindSpeed=12.0)
    return dict(dem=dem, terrain=terrain, rain=rain, analysis=analysis, clouds=clouds,
                seconds=seconds, drops=drops)


def camera(bounds, size):
    x0, x1, y0, y1 = bounds
    w, h = x1 - x0, y1 - y0
    top = EXAGGERATION * 1076.0
    return L.Camera(position=[x0 + 0.45 * w, y0 - 0.22 * h, top + 0.3 * h],
                    focal=[x0 + 0.52 * w, y0 + 0.50 * h, 0.3 * top], size=size)


def show(parts, size=(1024, 640), scratch=".", title=True):
    """Renders the scene; returns (view, numbers) with the numbers the test
    checks."""
    from paraview.simple import Clip, Glyph, Render, SetActiveSource, Show
    P = L.constructor
    end = parts["seconds"]
    water = L.fetch(parts["rain"], end)
    ground = L.fetch(parts["analysis"])
    b = ground.GetBounds()
    cam = camera(b[:4], size)

    # The ground: elevation colours lit by the hillshade and the grey sky,
    # fogged.
    x, y, z = L.points_xyz(ground, EXAGGERATION, "elevation")
    pd = ground.GetPointData()
    elev = vtk_to_numpy(pd.GetArray("elevation")).astype(np.float64)
    shade = vtk_to_numpy(pd.GetArray("hillshade"))
    rgb = L.ramp(elev, GROUND_STOPS) * (0.45 + 0.75 * shade)[:, None]
    rgb = L.fog(np.clip(rgb, 0, 1), cam.distance(x, y, z), HAZE, FOG_LENGTH)

    clouds = L.fetch(parts["clouds"], 0.0)
    png = L.sky_texture(os.path.join(scratch, "rain_sky.png"), cam, clouds,
                        cloud_altitude=EXAGGERATION * 1076.0 + 2500.0, zenith=ZENITH,
                        horizon=HAZE, haze=HAZE, length=2.0 * FOG_LENGTH, storm=STORM)
    view = L.new_view(size, png)
    view.UseEnvironmentLighting = 1
    L.show_rgb(L.surface_rgb(ground, EXAGGERATION, "elevation", rgb), view)

    # The water: ripples on the runoff's last state (a snapshot without time,
    # so Water Surface starts from the gathered water), 60 s of drops.
    still = L.producer(water)
    waves = P("WaterSurface")(Input=still, WetDepth=WET, WaveSpeed=25.0, Damping=0.05,
                              DropRate=2e-5, DropAmplitude=0.05, DropRadius=150.0, Seed=7,
                              EndTime=60.0, OutputInterval=60.0)
    surface = L.fetch(waves, 60.0)
    wx, wy, wz = L.points_xyz(surface, EXAGGERATION, "water_surface")
    spd = surface.GetPointData()
    depth = vtk_to_numpy(spd.GetArray("water_depth")).astype(np.float64)
    wrgb = L.fog(L.ramp(depth, DEPTH_STOPS), cam.distance(wx, wy, wz), HAZE, FOG_LENGTH)
    # Lifted 2 m (drawn) over the ground so that films never flicker through it.
    lifted = L.surface_rgb(surface, EXAGGERATION, "water_surface", wrgb)
    # The ripples' normals light the water (tilts drawn with the exaggeration).
    n = vtk_to_numpy(spd.GetArray("normal")).astype(np.float64) * [EXAGGERATION, EXAGGERATION, 1]
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    grid = lifted.GetClientSideObject().GetOutputDataObject(0)
    na = numpy_to_vtk(n.astype(np.float32), deep=1)
    na.SetName("ripple_normal")
    grid.GetPointData().SetNormals(na)
    lift = P("Transform")(Input=lifted)
    lift.Transform.Translate = [0.0, 0.0, 2.0]
    # Cut along the WET contour (not by whole cells): smooth shores.
    wet = Clip(Input=lift, ClipType="Scalar", Scalars=["POINTS", "water_depth"], Value=WET,
               Invert=0)
    d = Show(wet, view)
    d.Representation = "Surface"
    d.ColorArrayName = ["POINTS", "rgb"]
    d.MapScalars = 0
    d.Interpolation = "PBR"
    d.Roughness = 0.06
    d.Metallic = 0.0

    # Rain: drops in a box before the camera, their streaks over a long
    # exposure (4 s) so that they show at this scale.
    c = cam.position
    box = [c[0] - 3000.0, c[0] + 3000.0, c[1] + 1500.0, c[1] + 7000.0, 0.0, c[2] + 300.0]
    SetActiveSource(None)  # no Input: the Region box, not the terrain's bounds
    rainfall = P("RainParticles")(Count=parts["drops"], RainRate=RAIN_RATE, Seed=3,
                                  Wind=[3.0, 2.0, 0.0], ExposureTime=4.0, Region=box)
    drops = L.fetch(rainfall, 30.0)
    streaks = Glyph(Input=L.producer(drops), GlyphType="Line", OrientationArray=["POINTS", "streak"],
                    ScaleArray=["POINTS", "streak"], ScaleFactor=1.0, GlyphMode="All Points")
    streaks.ScaleFactor = 1.0  # after ScaleArray, which resets it from the bounds
    s = Show(streaks, view)
    s.ColorArrayName = ["POINTS", ""]
    s.AmbientColor = s.DiffuseColor = [0.85, 0.87, 0.9]
    s.Ambient, s.Diffuse = 1.0, 0.0
    s.LineWidth = 1.0

    L.legend(view, "water_depth", DEPTH_STOPS, "water depth (m)", position=(0.04, 0.03),
             fmt="%.2g", length=0.26)
    L.legend(view, "elevation", GROUND_STOPS, "elevation (m)", position=(0.36, 0.03),
             fmt="%.0f", length=0.26)
    L.label(view, "vertical exaggeration %g\u00d7" % EXAGGERATION, "Lower Right Corner", 13)
    if title:
        L.label(view, "Rain: %g h of %g mm/h on the Jacksboro Fault DEM (USGS)"
                % (end / 3600.0, RAIN_RATE), "Upper Left Corner", 15)
    Render(view)
    cam.apply(view)
    Render(view)

    fd = water.GetFieldData()
    numbers = dict(max_depth=float(depth.max()), wet_points=int(np.sum(depth > WET)),
                   points=int(depth.size), drops=drops.GetNumberOfPoints(),
                   max_wave=float(surface.GetFieldData().GetArray("max_wave").GetValue(0)),
                   rain_volume=float(fd.GetArray("rain_volume").GetValue(0)),
                   stored_volume=float(fd.GetArray("stored_volume").GetValue(0)),
                   balance_error=float(fd.GetArray("balance_error").GetValue(0)))
    return view, numbers


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--out", default="out")
    p.add_argument("--sample", type=int, default=2)
    p.add_argument("--width", type=int, default=1024)
    p.add_argument("--height", type=int, default=640)
    p.add_argument("--plugin", default=os.path.join(
        here, "..", "build", "lib", "paraview-5.11", "plugins", "Graupel", "Graupel.so"))
    a, _ = p.parse_known_args()
    os.makedirs(a.out, exist_ok=True)
    L.load_plugin(a.plugin)
    parts = build(os.path.join(here, "..", "Data"), sample=a.sample)
    size = (a.width, a.height)
    view, numbers = show(parts, size, scratch=a.out)
    from paraview.simple import SaveScreenshot
    SaveScreenshot(os.path.join(a.out, "rain_scene.png"), view, ImageResolution=list(size))
    print("rain scene:", ", ".join("%s %s" % kv for kv in sorted(numbers.items())))


if __name__ == "__main__":
    main()
