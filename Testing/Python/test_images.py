"""pvbatch under xvfb-run: a scene rendered and compared with its baseline in
Testing/Baseline/ by VTK's image comparison.
  --scene terrain  the procedural terrain as Apply shows it (Terrain Surface:
                   warped by elevation x2, coloured by the Graupel Terrain
                   map, walls at the edges), with legend and exaggeration
  --scene rain     half an hour of 100 mm/h on a procedural terrain (Rain
                   Runoff), warped by the water surface, coloured by depth
                   (log from 1 cm, dry ground sand)
  --scene analysis Terrain Analysis's cover classes (ground, snow, rock, ice
                   below a water level) as Apply shows them
  --scene water    Water Surface on a lake filled to 14 m, 10 s of raindrop ripples,
                   as Apply shows it (coloured by water depth)
  --scene snow     a wheel rolled along an S through snow (Snow Deformation,
                   Examples/snow_scene.py on a 160 x 160 grid), seen whole,
                   coloured by the Graupel Snow Density map, with legend and
                   exaggeration
  --scene accumulation  4 h of wind-driven snow on a hut and trees (Snow
                   Accumulation), then a sledge across it (Snow Deformation):
                   snow_scene.build_accumulation on a 128 x 128 grid, seen whole,
                   coloured by the Graupel Snow Depth map, with legend and
                   exaggeration
  --scene winter   Examples/winter_scene.py on a 128 x 128 terrain: snow by
                   slope, cast shadows, snowfall, cloud sky, lightning
  --scene rain_scene  Examples/rain_scene.py: an hour of rain on the DEM in
                   Data/ (every second point), rippled water, rain streaks, fog
  --scene season   Examples/season_scene.py: winter snow on the DEM (every
                   fourth point), 24 days of March melt (Snow Melt) running
                   off (Rain Runoff), drawn on 19 March; the chain's ledger
Regenerate a baseline only on purpose (--generate-baseline, or
GRAUPEL_GENERATE_BASELINE=1 in ctest's environment), and look at it."""
import os
import shutil
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args(lambda p: p.add_argument("--scene", choices=("terrain", "rain", "snow",
                                                          "accumulation", "analysis",
                                                          "water", "winter", "rain_scene",
                                                          "season"),
                                    default="terrain"))

from paraview.simple import *  # noqa: E402,F401,F403
from vtkmodules.vtkTestingRendering import vtkTesting  # noqa: E402

LoadPlugin(a.plugin, ns=globals())
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "Examples"))
import graupel_scene  # noqa: E402


def apply_look(source, array):
    """The picture is Apply's look: Terrain Surface's defaults colour by
    `array`, whose colour map is the plugin's preset."""
    view, display, surface = graupel_scene.show_surface(source, size=(400, 300))
    T.check(display.ColorArrayName[1] == array, "Apply colours by %s (%r)"
            % (array, display.ColorArrayName[1]))
    T.check(display.Representation == "Surface", "a surface (%s)" % display.Representation)
    lut = GetColorTransferFunction(array)
    T.check(lut.UseLogScale == (1 if array == "water_depth_display" else 0),
            "%s's map log scale %d" % (array, lut.UseLogScale))
    n = surface.GetDataInformation().GetNumberOfCells()
    T.check(n > 0, "the surface has %d cells" % n)
    return view


if a.scene == "terrain":
    terrain = ProceduralTerrain(Dimensions=[192, 192], Spacing=4.0, Seed=2026)
    view = apply_look(terrain, "elevation")
    lut = GetColorTransferFunction("elevation")
    # A sequential map: lightness rises from the lowest ground to the peaks.
    rgb = lut.RGBPoints
    light = [0.3 * rgb[k + 1] + 0.59 * rgb[k + 2] + 0.11 * rgb[k + 3] for k in range(0, len(rgb), 4)]
    T.check(light[0] < light[len(light) // 2] < light[-1], "elevation map lightness %s" % light)
elif a.scene == "analysis":
    terrain = ProceduralTerrain(Dimensions=[192, 192], Spacing=4.0, Seed=2026)
    analysis = TerrainAnalysis(Input=terrain, WaterLevel=12.0)
    view = apply_look(analysis, "cover_class")
elif a.scene == "water":
    terrain = ProceduralTerrain(Dimensions=[128, 128], Spacing=4.0, Seed=2026, HeightScale=40.0)
    water = WaterSurface(Input=terrain, UseLakeLevel=1, LakeLevel=14.0, EndTime=10.0)
    water.UpdatePipeline(water.EndTime)
    GetActiveViewOrCreate("RenderView").ViewTime = water.EndTime
    view = apply_look(water, "water_depth_display")
elif a.scene == "snow":
    import snow_scene  # noqa: E402

    # The demo's 12.8 m patch at 8 cm, one cell per step.
    snow, times = snow_scene.build(cells=160, spacing=0.08, time_step=0.032, frames=1)
    snow.UpdatePipeline(times[-1])
    # What the picture claims: a trench down to the wheel's underside, rims
    # above the untouched snow, pressed snow denser, and the mass kept.
    from paraview import servermanager  # noqa: E402

    out = servermanager.Fetch(snow)
    depth = out.GetPointData().GetArray("snow_depth").GetRange()
    rho = out.GetPointData().GetArray("snow_density").GetRange()
    floor = snow_scene.DEPTH - snow_scene.SINK
    T.check(floor - 0.02 < depth[0] < floor + 0.02,
            "the trench floor %.3f m is the wheel's underside, %.3f m" % (depth[0], floor))
    T.check(depth[1] > snow_scene.DEPTH + 0.05, "rims %.3f m above the snow's %.2f m" % (
        depth[1], snow_scene.DEPTH))
    T.check(rho[0] == snow_scene.DENSITY and 300.0 < rho[1] <= 400.0,
            "densities %.1f..%.1f kg/m^3" % rho)
    fd = out.GetFieldData()
    mass = fd.GetArray("snow_mass").GetValue(0)
    T.check(abs(fd.GetArray("balance_error").GetValue(0)) < 1e-6 * mass, "snow mass kept")
    view = snow_scene.show(snow, times[-1], size=(400, 300), label=False)
elif a.scene == "accumulation":
    import numpy as np  # noqa: E402
    import snow_scene as S  # noqa: E402
    from paraview import servermanager  # noqa: E402
    from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402

    # The demo's 14.35 m patch at 11 cm, 12 steps of 20 min, then the
    # sledge in steps of 0.04 s.
    acc, sledge, crossing, path = S.build_accumulation(cells=128, spacing=0.05 * 287 / 127,
                                                       time_step=1200.0, resolution=256,
                                                       sledge_step=0.04)
    end = acc.EndTime
    out = servermanager.Fetch(acc)
    nx = out.GetDimensions()[0]
    dx = out.GetSpacing()[0]
    j, i = np.mgrid[0:nx, 0:nx]
    X, Y = i * dx, j * dx
    depth = vtk_to_numpy(out.GetPointData().GetArray("snow_depth")).reshape(nx, nx)
    field = lambda data, name: data.GetFieldData().GetArray(name).GetValue(0)  # noqa: E731
    fall = field(out, "snowfall_volume")
    stored, shed = field(out, "stored_volume"), field(out, "shed_volume")
    T.check(field(out, "time") == end and fall > 0, "the snowfall's %g m^3 at %g s" % (fall, end))
    T.check(abs(field(out, "balance_error")) <= 1e-6 * fall
            and abs(fall - stored - shed) <= 1e-6 * fall,
            "ledger: snowfall %r = stored %r + shed %r" % (fall, stored, shed))
    # Under the roof: the walls, and the porch but for the strips the
    # slanting snow reaches from its eaves (eave height x tan(tilt +
    # flutter) from the west, x tan(flutter) from the south), two cells in
    # from every edge for the blur.
    H = S.HUT
    x0, x1 = H["x"] - 0.5 * H["width"], H["x"] + 0.5 * H["width"]
    y0, y1 = H["y"] - 0.5 * H["length"], H["y"] + 0.5 * H["length"]
    rx0, rx1, ry0 = x0 - H["overhang"], x1 + H["overhang"], y0 - H["porch"]
    reach = H["eave"] * np.tan(np.radians(S.TILT + S.FLUTTER)) + 2 * dx
    front = H["eave"] * np.tan(np.radians(S.FLUTTER)) + 2 * dx
    roofed = (((X > x0 + 2 * dx) & (X < x1 - 2 * dx) & (Y > y0 + 2 * dx) & (Y < y1 - 2 * dx))
              | ((X > rx0 + reach) & (X < x1 - 2 * dx) & (Y > ry0 + front)
                 & (Y <= y0 + 2 * dx)))
    T.check(roofed.sum() > 300 and np.all(depth[roofed] == 0.0),
            "exactly no snow on the %d points under the roof (max %g m)"
            % (roofed.sum(), depth[roofed].max()))
    # The wind's lee: 0.2-0.8 m east of the east eave against as far west
    # of the west eave, along the walls.
    side = (Y > y0) & (Y < y1)
    lee = depth[side & (X > rx1 + 0.2) & (X < rx1 + 0.8)].mean()
    windward = depth[side & (X > rx0 - 0.8) & (X < rx0 - 0.2)].mean()
    full = S.RATE * 0.01 * S.HOURS
    T.check(windward > 0.7 * full * np.cos(np.radians(S.TILT)) and lee < 0.25 * windward,
            "lee %.3f m, windward %.3f m of snow beside the hut" % (lee, windward))
    # The caps: the roof's slopes, 30 degrees, catch cos(30 - tilt) and
    # cos(30 + tilt) of the snow: the lee slope half the windward's.
    roof = servermanager.Fetch(acc, idx=1).GetBlock(1)
    cap = vtk_to_numpy(roof.GetPointData().GetArray("snow_depth"))
    normal_x = vtk_to_numpy(roof.GetPointData().GetArray("snow_offset"))[:, 0]
    west, east = cap[normal_x < -1e-6].mean(), cap[normal_x > 1e-6].mean()
    pitch = np.arctan2(H["ridge"] - H["eave"], 0.5 * H["width"] + H["overhang"])
    want = np.cos(pitch + np.radians(S.TILT)) / np.cos(pitch - np.radians(S.TILT))
    T.check(abs(east / west - want) < 0.1,
            "roof caps: windward %.3f m, lee %.3f m, ratio %.3f (cosines %.3f)"
            % (west, east, east / west, want))
    # The sledge: its trail below the snow it crossed, the snow's mass kept
    # from what fell.
    sledge.UpdatePipeline(crossing)
    after = servermanager.Fetch(sledge)
    mass = float(np.sum(depth.astype(np.float64) * vtk_to_numpy(
        out.GetPointData().GetArray("snow_density")).reshape(nx, nx)) * dx * dx)
    T.check(abs(field(after, "initial_mass") - mass) <= 1e-5 * mass
            and abs(field(after, "balance_error")) <= 1e-6 * mass,
            "the sledge's snow starts at the accumulated %.6g kg (%r) and keeps it (error %g)"
            % (mass, field(after, "initial_mass"), field(after, "balance_error")))
    u = len(path)
    x, y = path[u // 5:4 * u // 5, 0], path[u // 5:4 * u // 5, 1]
    sunk = S._sample(out, "snow_surface", x, y) - S._sample(after, "snow_surface", x, y)
    T.check(np.median(sunk) > 0.5 * S.SLEDGE_SINK and sunk.min() > 0.0,
            "the trail lies %.3f m (median; least %.3f m) below the accumulated snow"
            % (np.median(sunk), sunk.min()))
    view = S.show_accumulation(acc, end, sledge, crossing, size=(400, 300), label=False)
elif a.scene == "winter":
    import winter_scene as W  # noqa: E402

    parts = W.build(cells=128, spacing=1528.0 / 127, flakes=6000)
    view, n = W.show(parts, size=(400, 300), scratch=a.scratch, title=False)
    print("winter scene:", n)
    # What the picture claims: mostly snow (Snow Accumulation's, its ledger
    # closed), bare rock where the wind did not reach, the low sun's shadows
    # on part of it, every flake and bolt point drawn.
    T.check(n["snow_fraction"] > 0.4 and 0.02 < n["rock_fraction"] < 0.4,
            "snow over 20 cm on %.0f%% of the terrain, under 4 cm on %.0f%%"
            % (100 * n["snow_fraction"], 100 * n["rock_fraction"]))
    T.check(abs(n["acc_balance"]) < 1e-3, "the snowfall's ledger closes (%.3g m^3)"
            % n["acc_balance"])
    T.check(0.05 < n["shadow_fraction"] < 0.9,
            "%.0f%% of the terrain in cast shadow" % (100 * n["shadow_fraction"]))
    T.check(n["flakes"] == 6000, "6000 flakes (%d)" % n["flakes"])
    T.check(n["bolt_points"] == 50 + 6 * 25, "the bolt's 200 points (%d)" % n["bolt_points"])
    T.check(abs(n["cloud_fraction"] - 0.65) < 0.05,
            "clouds on %.2f of the sky (Cover 0.65)" % n["cloud_fraction"])
elif a.scene == "rain_scene":
    import rain_scene as R  # noqa: E402

    parts = R.build(a.data, sample=2, drops=8000)
    view, n = R.show(parts, size=(400, 300), scratch=a.scratch, title=False)
    print("rain scene:", n)
    wet = n["wet_points"] / float(n["points"])
    T.check(n["max_depth"] > 0.5 and 0.05 < wet < 0.6,
            "water up to %.2f m deep, on %.0f%% of the DEM" % (n["max_depth"], 100 * wet))
    T.check(abs(n["balance_error"]) < 1e-6 * n["rain_volume"]
            and n["stored_volume"] > 0.5 * n["rain_volume"],
            "ledger: %.4g m^3 rained, %.4g m^3 stored, error %.3g m^3"
            % (n["rain_volume"], n["stored_volume"], n["balance_error"]))
    T.check(0.0 < n["max_wave"] < 0.5, "ripples up to %.3f m" % n["max_wave"])
    T.check(n["drops"] == 8000, "8000 rain drops (%d)" % n["drops"])
elif a.scene == "season":
    import season_scene as S  # noqa: E402

    parts = S.build(a.data)
    rows, shots, hydro = S.run(parts)
    t, caption = S.DATES[2]
    view, n = S.show(parts, shots[t], caption, size=(400, 300), scratch=a.scratch, title=False)
    print("season scene:", n)
    # What the picture and the plots claim: one ledger over the chain closes
    # at every output and Rain Runoff rains what Snow Melt releases (both to
    # 1e-6 of the water in); on 19 March part of the snow is gone, more of
    # it on the south slopes than on the north; the release peaks in the rain
    # on snow, and water leaves the DEM.
    worst = max(abs(r["closure_error"]) / r["water_in"] for r in rows)
    T.check(worst <= 1e-6, "the chain's ledger closes at all %d outputs (worst %.2g of the "
            "water in)" % (len(rows), worst))
    gap = max(abs(r["runoff_rain"] - r["released"]) / r["water_in"] for r in rows)
    T.check(gap <= 1e-6, "Rain Runoff rains Snow Melt's release (worst %.2g)" % gap)
    T.check(0.3 < n["snow_cover"] < 0.9 and n["swe_south_mm"] < 0.8 * n["swe_north_mm"],
            "19 March: snow on %.0f%% of the DEM, SWE south %.0f mm, north %.0f mm"
            % (100 * n["snow_cover"], n["swe_south_mm"], n["swe_north_mm"]))
    _, h = S.table_rows(hydro)
    peak = max(h[1:], key=lambda r: r["rain_volume_rate"])
    T.check(len(h) == len(rows) and 5.5 < peak["time"] / S.DAY < 8.0
            and h[-1]["outflow_volume"] > 0.0,
            "%d hydrograph rows, the release peaks on day %.2f, %.3g m^3 out"
            % (len(h), peak["time"] / S.DAY, h[-1]["outflow_volume"]))
else:
    terrain = ProceduralTerrain(Dimensions=[128, 128], Spacing=4.0, Seed=2026, HeightScale=40.0)
    # Half an hour: 5 cm of rain, enough to fill the hollows past the 1 cm
    # wetting depth (ten minutes left films under it: dry in the picture).
    rain = RainRunoff(Input=terrain, RainRate=100.0, EndTime=1800.0, OutputInterval=1800.0,
                      MaxTimeStep=2.0)
    rain.UpdatePipeline(1800.0)
    view = graupel_scene.show_water(rain, 1800.0, size=(400, 300), deep=0.5)
shot = os.path.join(a.scratch, a.scene + ".png")
SaveScreenshot(shot, view, ImageResolution=[400, 300])

# The threshold is VTK's image difference (summed per-pixel error after its
# tolerance for shifted pixels); 10 is VTK's usual default for its own tests.
THRESHOLD = 10.0
if a.generate_baseline or os.environ.get("GRAUPEL_GENERATE_BASELINE") == "1":
    shutil.copyfile(shot, a.baseline)
    print("baseline written to %s: look at it before committing" % a.baseline)
else:
    testing = vtkTesting()
    testing.AddArgument("-T")
    testing.AddArgument(a.scratch)
    testing.AddArgument("-V")
    testing.AddArgument(a.baseline)
    result = testing.RegressionTest(shot, THRESHOLD)
    T.check(result == vtkTesting.PASSED, "image matches %s (threshold %g)" % (a.baseline, THRESHOLD))
T.finish()
