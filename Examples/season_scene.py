"""The season (winter to spring) on the real DEM in Data/ (the Jacksboro
Fault, Tennessee, read at every fourth point: 101 x 86 points of 298 x 368 m):
a winter snowfall on a west wind (Snow Accumulation, 36 h of 3 cm/h), then
24 days of March (Snow Melt, Hock's temperature index with the sun and the
terrain's cast shadows, forced by an hourly table: cold, a warm spell with
rain on snow, a cold snap, then a warming with a daily cycle), and the water
it releases running off (Rain Runoff, FollowInputTime with RainFrames 1:
each output's mean release rains over the interval before it).

    xvfb-run -a pvbatch Examples/season_scene.py --out out
        [--plugin build/lib/paraview-5.11/plugins/Graupel/Graupel.so]

writes to out/ (about 18 s on PoCL on two cores, 12 s of it the chain):
  season_1.png .. season_4.png  the terrain at four dates, coloured from bare
                 ground to snow by snow_depth, water where Rain Runoff has it
  season_scene.png   the four as one 2 x 2 picture
  season_forcing.csv the forcing table (time s, air_temperature degC,
                 precipitation mm/h)
  season_hydrograph.csv, season_hydrograph.png  Rain Runoff's hydrograph
                 (output port 1) and a plot of the release and the outflow
  season_ledger.csv, season_ledger.png  the chain's water ledger at every
                 output (m^3): snowfall_in + snowfall + rain = SWE stored +
                 liquid stored + infiltrated + surface water + outflow, with
                 its closure error (asserted within 1e-6 of the water in)

The reference-image test (Testing/Python/test_images.py --scene season)
draws the third date (19 March) at 400 x 300 pixels, without its caption.
"""
import argparse
import csv
import math
import os
import sys

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, here)
import landscape_scene as L  # noqa: E402

EXAGGERATION = 2.5
SAMPLE = 4  # every fourth point of the DEM
DAY, HOUR = 86400.0, 3600.0
# Winter: 36 h of 3 cm/h of snow of 150 kg/m^3 on a west wind 30 deg off
# vertical (compressed into 12 steps of 3 h).
SNOW_HOURS, SNOW_RATE, SNOW_DENSITY = 36.0, 3.0, 150.0
SNOW_DIRECTION = [0.58, 0.0, -1.0]
# Spring: 24 days from 1 March (day of year 60) at the DEM's latitude, the
# air temperature given at the lowest valley floor (236 m).
DAYS, START_DAY, LATITUDE, REFERENCE = 24, 60, 36.6, 236.0
OUTPUT = 6.0 * HOUR
PERMEABILITY = 1.5  # mm/h: what the thawed ground takes in
DATES = ((0.0, "1 March: the winter's snow"),
         (6.75 * DAY, "7 March, 18:00: rain on snow"),
         (18.0 * DAY, "19 March: the valleys and the south slopes melt first"),
         (24.0 * DAY, "25 March: snow left on the high ridge"))
# Colours: bare ground by elevation (late-winter grass to bare ridge),
# snow by depth (thin, the ground showing through, to full cover), water by
# depth; light from a mid-morning March sun from the south-east.
GROUND_STOPS = [(230.0, 0.30, 0.31, 0.19), (550.0, 0.38, 0.36, 0.24), (800.0, 0.47, 0.42, 0.32),
                (1080.0, 0.55, 0.51, 0.44)]
FULL_SNOW = 0.30  # m: snow this deep is drawn as full cover
SNOW_STOPS = [(0.0, 0.42, 0.39, 0.30), (0.05, 0.68, 0.68, 0.66), (0.15, 0.86, 0.88, 0.90),
              (FULL_SNOW, 0.97, 0.98, 1.0)]
WET = 0.05  # m: water shallower than this is not drawn
DEPTH_STOPS = [(WET, 0.45, 0.65, 0.85), (0.15, 0.22, 0.47, 0.78), (0.3, 0.10, 0.30, 0.62),
               (1.0, 0.03, 0.14, 0.40)]
SUN_AZIMUTH, SUN_ELEVATION = 150.0, 35.0
HAZE = [0.74, 0.79, 0.86]
ZENITH = [0.38, 0.52, 0.74]
FOG_LENGTH = 60000.0  # m


def forcing_rows():
    """The hourly forcing: (time s, air temperature degC at REFERENCE,
    precipitation mm/h)."""
    rows = []
    for h in range(0, DAYS * 24 + 1):
        d = h / 24.0
        cycle = math.sin(2.0 * math.pi * (h % 24 - 9) / 24.0)  # warmest at 15:00
        p = 0.0
        if d < 5.0:  # cold, a light snowfall on 3 March
            t = -6.0 + 3.0 * cycle
            p = 1.5 if 2.0 <= d < 2.5 else 0.0
        elif d < 8.0:  # a warm spell, 30 h of rain on the snow from 6 March, 12:00
            t = 5.5 + 1.5 * cycle
            p = 2.0 if 5.5 <= d < 6.75 else 0.0
        elif d < 11.0:  # a cold snap
            t = -4.0 + 3.0 * cycle
        else:  # warming with a daily cycle: mean -2 degC on 12 March to 5.8 on 25 March
            t = -2.0 + 0.6 * (d - 11.0) + 6.0 * cycle
        rows.append((h * HOUR, round(t, 3), p))
    return rows


def forcing_table(rows=None):
    from vtkmodules.vtkCommonCore import vtkDoubleArray
    from vtkmodules.vtkCommonDataModel import vtkTable

    table = vtkTable()
    for k, name in enumerate(("time", "air_temperature", "precipitation")):
        c = vtkDoubleArray()
        c.SetName(name)
        for r in rows or forcing_rows():
            c.InsertNextValue(r[k])
        table.AddColumn(c)
    return table


def table_producer(table):
    """The forcing table as a pipeline proxy; make_states.py swaps in a CSV
    file written next to the state."""
    return L.producer(table)


def fill_pits(z, step=0.1):
    """The DEM's pits filled (priority flood from the edges, Barnes et al.
    2014, with `step` m of rise per point across the filled flats so that
    they drain): read at every fourth point the valleys of the real terrain
    break into chains of closed hollows that would hold the melt water for
    ever; the rivers that drain them run between the samples."""
    import heapq
    ny, nx = z.shape
    out = z.astype(np.float64).copy()
    done = np.zeros(z.shape, bool)
    heap = []
    for j in range(ny):
        for i in range(nx):
            if j in (0, ny - 1) or i in (0, nx - 1):
                heapq.heappush(heap, (out[j, i], j, i))
                done[j, i] = True
    while heap:
        h, j, i = heapq.heappop(heap)
        for dj, di in ((-1, 0), (1, 0), (0, -1), (0, 1), (-1, -1), (-1, 1), (1, -1), (1, 1)):
            a, b = j + dj, i + di
            if 0 <= a < ny and 0 <= b < nx and not done[a, b]:
                done[a, b] = True
                out[a, b] = max(out[a, b], h + step)
                heapq.heappush(heap, (out[a, b], a, b))
    return out


def terrain_producer(image):
    """The conditioned terrain as a pipeline proxy; make_states.py swaps in a
    file written next to the state."""
    return L.producer(image)


def build(data, sample=SAMPLE, days=DAYS):
    """The chain on the DEM read at every `sample`-th point, its pits filled.
    Returns a dict of its proxies."""
    from paraview.simple import Delete, ExtractSubset, OpenDataFile
    from vtkmodules.vtkCommonDataModel import vtkImageData
    P = L.constructor
    dem = OpenDataFile(os.path.join(data, "jacksboro_fault_dem.exr"))  # spacing in the file
    dem.UpdatePipeline()
    sub = ExtractSubset(Input=dem, VOI=list(dem.GetDataInformation().GetExtent()),
                        SampleRateI=sample, SampleRateJ=sample)
    raw = L.fetch(sub)
    Delete(sub)
    Delete(dem)
    nx, ny, _ = raw.GetDimensions()
    z = vtk_to_numpy(raw.GetPointData().GetArray("elevation")).reshape(ny, nx)
    filled = fill_pits(z)
    img = vtkImageData()
    img.SetDimensions(nx, ny, 1)
    img.SetSpacing(raw.GetSpacing())
    img.SetOrigin(raw.GetOrigin())
    arr = numpy_to_vtk(filled.reshape(-1).astype(np.float32), deep=1)
    arr.SetName("elevation")
    img.GetPointData().SetScalars(arr)
    terrain = terrain_producer(img)
    spacing = 3.0 * HOUR
    acc = P("SnowAccumulation")(Input=terrain, TimeStep=spacing, EndTime=SNOW_HOURS * HOUR,
                                OutputInterval=SNOW_HOURS * HOUR, SnowDirection=SNOW_DIRECTION,
                                SnowfallRate=SNOW_RATE, SnowDensity=SNOW_DENSITY, MaxDepth=1.2,
                                NoiseScale=2000.0, NoiseAmplitude=0.25, BlurRadius=1,
                                ExposureResolution=512, Seed=7)
    forcing = table_producer(forcing_table())
    end = days * DAY
    melt = P("SnowMelt")(Input=acc, Forcing=forcing, EndTime=end, OutputInterval=OUTPUT,
                         TimeStep=HOUR, Latitude=LATITUDE, StartDayOfYear=START_DAY,
                         StartHour=0.0, ReferenceElevation=REFERENCE, LapseRate=-6.5,
                         MeltFactor=1.2, RadiationFactor=0.0009, CastShadows=1,
                         HorizonSectors=32)
    runoff = P("RainRunoff")(Input=melt, FollowInputTime=1, RainFrames=1, RainRate=0.0,
                             Permeability=PERMEABILITY, EndTime=end, OutputInterval=OUTPUT,
                             FlowModel="Local inertial", ManningN=0.035)
    analysis = P("TerrainAnalysis")(Input=terrain, SunAzimuth=SUN_AZIMUTH,
                                    SunElevation=SUN_ELEVATION)
    dx, dy, _ = raw.GetSpacing()
    return dict(terrain=terrain, acc=acc, forcing=forcing, melt=melt, runoff=runoff,
                analysis=analysis, end=end, filled=float(np.sum(filled - z)) * dx * dy,
                filled_points=int(np.sum(filled > z)), points=int(z.size))


FIELDS_MELT = ("snowfall_in", "snowfall_volume", "rain_volume", "released_volume",
               "stored_swe_volume", "stored_liquid_volume", "balance_error")
FIELDS_RUNOFF = ("rain_volume", "infiltrated_volume", "stored_volume", "outflow_volume",
                 "balance_error")


def _field(data, name):
    return float(data.GetFieldData().GetArray(name).GetValue(0))


def run(parts, dates=DATES):
    """Steps the chain forward through every output time, Snow Melt and Rain
    Runoff side by side. Returns (ledger rows, {date: (melt, runoff)}
    snapshots at `dates`, the hydrograph table at the end)."""
    end = parts["end"]
    times = np.arange(0.0, end + 0.5 * OUTPUT, OUTPUT)
    wanted = [t for t, _ in dates]
    rows, shots = [], {}
    for t in times:
        melt = L.fetch(parts["melt"], t)
        water = L.fetch(parts["runoff"], t)
        m = {k: _field(melt, k) for k in FIELDS_MELT}
        r = {k: _field(water, k) for k in FIELDS_RUNOFF}
        water_in = m["snowfall_in"] + m["snowfall_volume"] + m["rain_volume"]
        kept = (m["stored_swe_volume"] + m["stored_liquid_volume"] + r["infiltrated_volume"]
                + r["stored_volume"] + r["outflow_volume"])
        rows.append(dict(time_s=t, day=t / DAY, snowfall_in=m["snowfall_in"],
                         snowfall=m["snowfall_volume"], rain=m["rain_volume"], water_in=water_in,
                         swe_stored=m["stored_swe_volume"],
                         liquid_stored=m["stored_liquid_volume"],
                         infiltrated=r["infiltrated_volume"], surface_water=r["stored_volume"],
                         outflow=r["outflow_volume"], released=m["released_volume"],
                         runoff_rain=r["rain_volume"], closure_error=water_in - kept))
        if any(abs(t - w) < 1.0 for w in wanted):
            shots[min(wanted, key=lambda w: abs(t - w))] = (melt, water)
    hydro = L.fetch(parts["runoff"], end, port=1)
    return rows, shots, hydro


def check_ledger(rows):
    """The closure at every output within 1e-6 of the water in, and Rain
    Runoff's rain equal to Snow Melt's release."""
    for r in rows:
        assert abs(r["closure_error"]) <= 1e-6 * max(r["water_in"], 1.0), \
            "ledger at day %.2f: closure error %.6g m^3 of %.6g m^3 in" % (
                r["day"], r["closure_error"], r["water_in"])
        assert abs(r["runoff_rain"] - r["released"]) <= 1e-6 * max(r["water_in"], 1.0), \
            "day %.2f: Rain Runoff rained %.6g m^3, Snow Melt released %.6g m^3" % (
                r["day"], r["runoff_rain"], r["released"])


def camera(bounds, size):
    x0, x1, y0, y1 = bounds
    w, h = x1 - x0, y1 - y0
    top = EXAGGERATION * 1076.0
    return L.Camera(position=[x0 + 0.56 * w, y0 - 0.42 * h, top + 0.42 * h],
                    focal=[x0 + 0.50 * w, y0 + 0.47 * h, 0.25 * top], size=size)


def colours(ground, melt, water, cam):
    """Per-point RGB of the ground under the snow and of the water, lit by
    the hillshade and fogged; returns (ground rgb, water rgb, depth)."""
    pd = ground.GetPointData()
    x, y, z = L.points_xyz(ground, EXAGGERATION, "elevation")
    elev = vtk_to_numpy(pd.GetArray("elevation")).astype(np.float64)
    shade = vtk_to_numpy(pd.GetArray("hillshade")).astype(np.float64)
    snow = vtk_to_numpy(melt.GetPointData().GetArray("snow_depth")).astype(np.float64)
    bare = L.ramp(elev, GROUND_STOPS)
    cover = L.ramp(snow, SNOW_STOPS)
    # Snow over a metre's blend: under 5 cm the ground shows through.
    a = np.clip(snow / 0.05, 0.0, 1.0)[:, None]
    base = bare * (1.0 - a) + cover * a
    light = (0.50 + 0.70 * shade)[:, None]
    rgb = L.fog(np.clip(base * light, 0, 1), cam.distance(x, y, z), HAZE, FOG_LENGTH)
    depth = vtk_to_numpy(water.GetPointData().GetArray("water_depth")).astype(np.float64)
    wrgb = L.ramp(depth, DEPTH_STOPS) * (0.75 + 0.35 * shade)[:, None]
    wrgb = L.fog(np.clip(wrgb, 0, 1), cam.distance(x, y, z), HAZE, FOG_LENGTH)
    return rgb, wrgb, depth, snow


def sky_png(path, cam):
    """A clear spring sky behind the camera: horizon haze to blue."""
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkIOImage import vtkPNGWriter

    d = cam.rays()
    g = np.sqrt(np.clip(d[..., 2], 0.0, 1.0))[..., None]
    rgb = np.asarray(HAZE)[None, None, :] * (1.0 - g) + np.asarray(ZENITH)[None, None, :] * g
    img = vtkImageData()
    w, h = cam.size
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


def show(parts, shot, caption, size=(800, 500), scratch=".", view=None, title=True):
    """Renders one date: the ground coloured by snow, the water over it.
    Returns (view, numbers)."""
    from paraview.simple import Clip, Hide, Render
    melt, water = shot
    ground = L.fetch(parts["analysis"])
    b = ground.GetBounds()
    cam = camera(b[:4], size)
    rgb, wrgb, depth, snow = colours(ground, melt, water, cam)
    if view is None:
        view = L.new_view(size, sky_png(os.path.join(scratch, "season_sky.png"), cam))
    view.ViewSize = list(size)
    for proxy in parts.pop("shown", []):  # the last date's pieces
        Hide(proxy, view)
    shown = [L.surface_rgb(ground, EXAGGERATION, "elevation", rgb)]
    L.show_rgb(shown[0], view)
    # The water at its surface (pools level, not draped), lifted 1 m (drawn)
    # over the ground and cut along the WET contour.
    img = ground.NewInstance()
    img.ShallowCopy(ground)
    elev = vtk_to_numpy(ground.GetPointData().GetArray("elevation")).astype(np.float64)
    for name, values in (("water_depth", depth), ("water_level", elev + depth)):
        arr = numpy_to_vtk(values.astype(np.float32), deep=1)
        arr.SetName(name)
        img.GetPointData().AddArray(arr)
    lifted = L.surface_rgb(img, EXAGGERATION, "water_level", wrgb)
    lift = L.constructor("Transform")(Input=lifted)
    lift.Transform.Translate = [0.0, 0.0, 1.0]
    wet = Clip(Input=lift, ClipType="Scalar", Scalars=["POINTS", "water_depth"], Value=WET,
               Invert=0)
    L.show_rgb(wet, view)
    shown += [lifted, lift, wet]
    L.legend(view, "snow_depth", SNOW_STOPS, "snow depth (m)", position=(0.03, 0.03),
             fmt="%.2g", length=0.28)
    L.legend(view, "water_depth", DEPTH_STOPS, "water depth (m)", position=(0.36, 0.03),
             fmt="%.2g", length=0.28)
    texts = [("vertical exaggeration %g\u00d7" % EXAGGERATION, "Lower Right Corner", 12)]
    if title:
        texts.append((caption, "Upper Left Corner", 16))
    for text, where, font in texts:
        t = L.label(view, text, where, font)
        shown.append(t.Input)
    parts["shown"] = shown
    Render(view)
    cam.apply(view)
    Render(view)
    swe = vtk_to_numpy(melt.GetPointData().GetArray("swe")).astype(np.float64)
    # South- and north-facing: slopes over 5 degrees turned within 45
    # degrees of south or north.
    n = vtk_to_numpy(ground.GetPointData().GetArray("normal")).astype(np.float64)
    tilted = n[:, 2] < math.cos(math.radians(5.0))
    horiz = np.maximum(np.hypot(n[:, 0], n[:, 1]), 1e-9)
    south = tilted & (-n[:, 1] / horiz > math.cos(math.radians(45.0)))
    north = tilted & (n[:, 1] / horiz > math.cos(math.radians(45.0)))
    numbers = dict(snow_cover=float(np.mean(snow > 0.05)), mean_swe_mm=1000.0 * float(swe.mean()),
                   swe_south_mm=1000.0 * float(swe[south].mean()),
                   swe_north_mm=1000.0 * float(swe[north].mean()),
                   wet_fraction=float(np.mean(depth > WET)), max_depth=float(depth.max()))
    return view, numbers


def write_csv(path, rows, columns):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(columns)
        for r in rows:
            w.writerow([("%.10g" % r[c]) if isinstance(r[c], float) else r[c] for c in columns])


def table_rows(table):
    cols = [table.GetColumnName(k) for k in range(table.GetNumberOfColumns())]
    arrays = [vtk_to_numpy(table.GetColumn(k)) for k in range(len(cols))]
    return cols, [{c: float(a[i]) for c, a in zip(cols, arrays)}
                  for i in range(table.GetNumberOfRows())]


def chart(path, rows, x, series, title, left, size=(900, 420)):
    """A line chart (ParaView's XY chart view) of `series` [(column, label,
    colour)] of `rows` against the column `x`, saved as `path`."""
    from paraview.simple import CreateView, Delete, Render, SaveScreenshot, Show
    from vtkmodules.vtkCommonCore import vtkDoubleArray
    from vtkmodules.vtkCommonDataModel import vtkTable

    table = vtkTable()
    for name in [x] + [s[0] for s in series]:
        c = vtkDoubleArray()
        c.SetName(name)
        for r in rows:
            v = r[name]
            c.InsertNextValue(float("nan") if v is None else v)
        table.AddColumn(c)
    view = CreateView("XYChartView")
    view.ViewSize = list(size)
    d = Show(L.producer(table), view)
    d.UseIndexForXAxis = 0
    d.XArrayName = x
    d.SeriesVisibility = [s[0] for s in series]
    d.SeriesLabel = [v for s in series for v in (s[0], s[1])]
    d.SeriesColor = [v for s in series for v in (s[0],) + tuple("%g" % c for c in s[2])]
    d.SeriesLineThickness = [v for s in series for v in (s[0], "2")]
    view.ChartTitle = title
    view.LeftAxisTitle = left
    view.BottomAxisTitle = "day of March"
    view.LegendLocation = "TopLeft"
    view.BottomAxisUseCustomRange = 1
    view.BottomAxisRangeMinimum = rows[0][x]
    view.BottomAxisRangeMaximum = rows[-1][x]
    Render(view)
    SaveScreenshot(path, view, ImageResolution=list(size))
    Delete(view)


def compose(paths, out, columns=2):
    """The pictures `paths` tiled `columns` wide into one PNG."""
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkIOImage import vtkPNGReader, vtkPNGWriter

    tiles = []
    for p in paths:
        r = vtkPNGReader()
        r.SetFileName(p)
        r.Update()
        o = r.GetOutput()
        w, h, _ = o.GetDimensions()
        c = o.GetPointData().GetScalars().GetNumberOfComponents()
        tiles.append(vtk_to_numpy(o.GetPointData().GetScalars()).reshape(h, w, c)[..., :3])
    h, w, _ = tiles[0].shape
    rows = (len(tiles) + columns - 1) // columns
    gap = 4
    canvas = np.full((rows * h + (rows - 1) * gap, columns * w + (columns - 1) * gap, 3), 255,
                     np.uint8)
    for k, t in enumerate(tiles):
        # VTK's images start at the bottom row: the first tile goes on top.
        row, col = rows - 1 - k // columns, k % columns
        canvas[row * (h + gap):row * (h + gap) + h, col * (w + gap):col * (w + gap) + w] = t
    img = vtkImageData()
    img.SetDimensions(canvas.shape[1], canvas.shape[0], 1)
    arr = numpy_to_vtk(canvas.reshape(-1, 3), deep=1)
    img.GetPointData().SetScalars(arr)
    writer = vtkPNGWriter()
    writer.SetFileName(out)
    writer.SetInputData(img)
    writer.Write()


LEDGER_COLUMNS = ("time_s", "day", "snowfall_in", "snowfall", "rain", "water_in", "swe_stored",
                  "liquid_stored", "infiltrated", "surface_water", "outflow", "closure_error",
                  "released")


def main():
    import time
    p = argparse.ArgumentParser()
    p.add_argument("--out", default="out")
    p.add_argument("--sample", type=int, default=SAMPLE)
    p.add_argument("--width", type=int, default=800)
    p.add_argument("--height", type=int, default=500)
    p.add_argument("--plugin", default=os.path.join(
        here, "..", "build", "lib", "paraview-5.11", "plugins", "Graupel", "Graupel.so"))
    a, _ = p.parse_known_args()
    os.makedirs(a.out, exist_ok=True)
    L.load_plugin(a.plugin)
    t0 = time.time()
    parts = build(os.path.join(here, "..", "Data"), sample=a.sample)
    write_csv(os.path.join(a.out, "season_forcing.csv"),
              [dict(time=r[0], air_temperature=r[1], precipitation=r[2]) for r in forcing_rows()],
              ("time", "air_temperature", "precipitation"))
    rows, shots, hydro = run(parts)
    wall = time.time() - t0
    check_ledger(rows)
    write_csv(os.path.join(a.out, "season_ledger.csv"), rows, LEDGER_COLUMNS)
    cols, hrows = table_rows(hydro)
    write_csv(os.path.join(a.out, "season_hydrograph.csv"), hrows, cols)
    for r in hrows:
        r["day"] = 1.0 + r["time"] / DAY
        r["release"] = r["rain_volume_rate"]
    chart(os.path.join(a.out, "season_hydrograph.png"), hrows[1:], "day",
          [("release", "melt and rain released by the snow", (0.55, 0.70, 0.95)),
           ("outflow_rate", "outflow over the DEM's edges", (0.05, 0.20, 0.60)),
           ("infiltration_rate", "infiltration", (0.55, 0.42, 0.25))],
          "Snowmelt runoff, Jacksboro Fault DEM, March (means over 6 h)", "m\u00b3/s")
    mm = 1e-6
    for r in rows:
        r["day1"] = 1.0 + r["day"]
        for k in ("water_in", "swe_stored", "liquid_stored", "infiltrated", "surface_water",
                  "outflow"):
            r[k + "_M"] = r[k] * mm
    chart(os.path.join(a.out, "season_ledger.png"), rows, "day1",
          [("water_in_M", "water in (snow, snowfall, rain)", (0.0, 0.0, 0.0)),
           ("swe_stored_M", "SWE in the snow", (0.55, 0.62, 0.75)),
           ("liquid_stored_M", "liquid water in the snow", (0.35, 0.75, 0.85)),
           ("infiltrated_M", "infiltrated", (0.55, 0.42, 0.25)),
           ("surface_water_M", "surface water", (0.20, 0.45, 0.85)),
           ("outflow_M", "outflow", (0.05, 0.15, 0.45))],
          "The chain's water ledger (closes to %.1g of the water in)"
          % max(abs(r["closure_error"]) / r["water_in"] for r in rows),
          "million m\u00b3")
    size = (a.width, a.height)
    view, pictures, numbers = None, [], []
    for k, (t, caption) in enumerate(DATES, 1):
        view, n = show(parts, shots[t], caption, size, scratch=a.out, view=view)
        from paraview.simple import SaveScreenshot
        path = os.path.join(a.out, "season_%d.png" % k)
        SaveScreenshot(path, view, ImageResolution=list(size))
        pictures.append(path)
        numbers.append(n)
    compose(pictures, os.path.join(a.out, "season_scene.png"))
    last = rows[-1]
    print("season: pits filled on %d of %d points (%.4g m3)" % (
        parts["filled_points"], parts["points"], parts["filled"]))
    print("season: %.1f s for the chain; in %.4g m3 (snow %.4g, snowfall %.4g, rain %.4g), "
          "released %.4g, outflow %.4g, infiltrated %.4g, surface %.4g, SWE left %.4g, "
          "closure %.3g m3 (%.2g of the water in)"
          % (wall, last["water_in"], last["snowfall_in"], last["snowfall"], last["rain"],
             last["released"], last["outflow"], last["infiltrated"], last["surface_water"],
             last["swe_stored"], last["closure_error"], last["closure_error"] / last["water_in"]))
    for (t, caption), n in zip(DATES, numbers):
        print("  %s: %s" % (caption, ", ".join("%s %.3g" % kv for kv in sorted(n.items()))))


if __name__ == "__main__":
    main()
