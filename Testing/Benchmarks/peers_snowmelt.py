#!/usr/bin/env python3
"""A peer for Snow Melt: one melt season of openAMUNDSEN on the real DEM.

openAMUNDSEN (PyPI `openamundsen`, pinned below) is installed into a virtual
environment of its own (default build/peers-snowmelt-venv, not committed) and
run on Data/jacksboro_fault_dem.tif warped by GDAL (`gdalwarp`) to NAD83 / UTM
zone 16N (EPSG:26916) at --res metres, cropped to the largest rectangle with
no no-data cells, with a synthetic station at the grid's centre.

The scenario (local standard time, UTC-5; 2025-03-01 00:00 to 2025-05-31 23:00,
hourly; the station's temperature T_ref moved to each cell by a fixed lapse
rate, precipitation the same everywhere):

- 1-12 March, a cold spell (T_ref -7 °C, +-3 K a day): two snowfalls, 90 mm
  (1-3 March) and 36 mm (7-8 March), the season's first snow (the run starts
  snow-free);
- 14-17 March, a warm spell (+2 °C, +-2 K) with 36 mm of rain on the snow
  (15-16 March), the rain-snow band (0-1 °C) crossing the terrain by the hour:
  rain below, snow on the high ground at night;
- 19-31 March, cold again (-5 °C) with 60 mm of snow (24-26 March);
- 1 April on, spring warming (-5 to +10 °C by 31 May, a diurnal cycle of
  +-5 K peaking at 15:00) with a rain shower on 1 May (12 mm, rain on the
  last snow).

openAMUNDSEN's set-up: the "cryolayers" snow model (its temperature-index
models exist only there), no wind or snow redistribution, no canopy, no
evapotranspiration, no glaciers; temperature, humidity, wind and precipitation
interpolated with fixed gradients (one station: no regression); cloudiness
prescribed from the station's `cloud_fraction`. --melt picks the melt model:

- `eti` (default): openAMUNDSEN's own `enhanced_temperature_index`, which is
  Pellicciotti et al. (2005), not Hock (1999):
      M = DDF * (T - T0) * dt + SRF * (1 - albedo) * G * dt   for T > T0,
  G its global radiation on the slope: Corripio's (2002) clear-sky direct
  (with cast shadows, sweep algorithm) plus diffuse, times the cloud factor.
  Parameters after Pellicciotti et al. (2005): TF 0.05 mm/h/K, SRF 0.0094
  mm m2 W-1 h-1 (given to openAMUNDSEN per day).
- `hock`: Hock's (1999) formula put in place of the cryolayer model's
  temperature_index method, with openAMUNDSEN's own potential clear-sky
  direct radiation on the slope with cast shadows (`meteo.dir_in_clearsky`,
  Corripio's transmittances, the sun at the step's time stamp):
      M = (MF / 24 + a * I) * (T - T0)   mm/h for T > T0,
  MF 1.8 mm/d/K and a 0.6e-3 mm h-1 K-1 (W m-2)-1, values of the order of
  Hock's (1999). The formula Graupel's Snow Melt implements.
- `ti`: the classical degree-day model, DDF 4 mm/d/K.

All three partition precipitation by air temperature, linearly between 0
and 1 °C (threshold 0.5 °C, range 1 K); liquid water is held up to 10 % of the
ice mass ("mass_fraction"), the excess runs off. Refreezing: none. In
openAMUNDSEN's cryolayer model only the energy balance refreezes (cold content
after Braun 1984); with the temperature-index models held water stays liquid.

Outputs in --out DIR:
  dem_utm_<res>m.tif   the warped, cropped DEM as GeoTIFF (EPSG:26916) for Graupel
  forcing_graupel.csv  time_s (since 2025-03-01 00:00), T_ref_C (at the station's
                       elevation, in the JSON), precip_mm_h
  peer_openamundsen.npz, the keys (2-D float arrays on the DEM's grid, row 0
  NORTH as in the GeoTIFF; a Graupel npz may say `north_up` = False to be
  flipped by compare()):
      swe_2025-03-15, swe_2025-04-01, swe_2025-04-15, swe_2025-05-01
                       SWE (mm: ice and held liquid water) after the step at
                       00:00 of that date
      meltout_doy      day of the year (1 January = 1, fractional at the hour)
                       of the first hour from which SWE stays below 1 mm to
                       the end; NaN where never snow-covered or still covered
                       at the end
      dem              elevation (m);  x, y  cell centres (m, EPSG:26916)
      north_up         True
  swe_<date>.tif, meltout_doy.tif   the same as GeoTIFFs
  peer_openamundsen.json  the parameters actually used (melt model and
                       factors, thresholds, lapse rate, holding capacity), the
                       station, the grid, openAMUNDSEN's version, the times
  openamundsen/        openAMUNDSEN's inputs (grids/dem_jacksboro_<res>.asc,
                       meteo/stations.csv and the station's CSV)

    python3 Testing/Benchmarks/peers_snowmelt.py --out /tmp/snowmelt [--res 200]
    python3 Testing/Benchmarks/peers_snowmelt.py --compare PEER.npz GRAUPEL.npz

The first run installs openAMUNDSEN (pip). The driver needs only the standard
library and GDAL's `gdalwarp` (gdal-bin); the model runs in the venv under
`nice`. compare() needs numpy (--compare takes the venv's python where the
running one has none). Not part of the test command.
"""
import argparse
import importlib.util
import json
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
DEM = os.path.join(ROOT, "Data", "jacksboro_fault_dem.tif")
OA_VERSION = "1.2.1"
CRS = "EPSG:26916"  # NAD83 / UTM zone 16N: the DEM's datum, the zone of its centre (84.25° W)
DOMAIN = "jacksboro"
YEAR = 2025
START, END = "%d-03-01 00:00" % YEAR, "%d-05-31 23:00" % YEAR
DATES = ["%d-03-15" % YEAR, "%d-04-01" % YEAR, "%d-04-15" % YEAR, "%d-05-01" % YEAR]
TIMEZONE = -5  # local standard time of the DEM (Tennessee, Eastern)
SNOW_MM = 1.0  # snow-covered: SWE >= 1 mm (melt-out date)

# The parameters, one place: written to the JSON for the Graupel run.
PARAMS = {
    "melt_threshold_C": 0.0,  # T0
    "lapse_rate_K_per_m": -0.0065,  # temperature, every month
    "precip_lapse_rate": 0.0,  # precipitation the same at every elevation
    "phase_method": "air temperature, linear between threshold -+ range/2",
    "phase_threshold_C": 0.5,  # 50 % snow
    "phase_range_K": 1.0,  # all snow below 0 °C, all rain above 1 °C
    "liquid_water_method": "mass_fraction",
    "liquid_water_max_fraction": 0.10,  # of the ice mass
    "refreezing": "none (openAMUNDSEN refreezes only in its energy balance)",
    "eti": {"formula": "DDF*(T-T0)*dt + SRF*(1-albedo)*G*dt, T > T0 (Pellicciotti 2005)",
            "DDF_mm_per_day_K": 1.2, "SRF_mm_m2_per_W_day": round(0.0094 * 24, 6)},
    "hock": {"formula": "(MF/24 + a*I)*(T-T0) mm/h, T > T0, I potential clear-sky direct "
                        "radiation on the slope with cast shadows (Hock 1999)",
             "MF_mm_per_day_K": 1.8, "a_mm_m2_per_W_h_K": 0.6e-3},
    "ti": {"formula": "DDF*(T-T0)*dt, T > T0", "DDF_mm_per_day_K": 4.0},
}


def log(*a):
    print(*a, file=sys.stderr, flush=True)


# ---------------------------------------------------------------- driver

def ensure_venv(venv):
    """openAMUNDSEN in a venv of its own (it pulls numpy 2, pandas, numba,
    rasterio with its own GDAL, none of which the system's VTK should see)."""
    py = os.path.join(venv, "bin", "python3")
    if not os.path.exists(py):
        log("creating %s" % venv)
        subprocess.check_call([sys.executable, "-m", "venv", venv])
    have = subprocess.run([py, "-c", "import importlib.metadata as m; "
                           "print(m.version('openamundsen'))"], capture_output=True, text=True)
    if have.returncode != 0 or have.stdout.strip() != OA_VERSION:
        log("installing openamundsen==%s into %s" % (OA_VERSION, venv))
        subprocess.check_call(["nice", "-n", "10", py, "-m", "pip", "install", "-q",
                               "openamundsen==" + OA_VERSION])
    return py


def warp(res, out):
    """The geographic DEM to UTM 16N at res metres (bilinear, aligned to
    multiples of res), no-data outside the source; the worker crops it."""
    dst = os.path.join(out, "dem_utm_%dm_full.tif" % res)
    subprocess.check_call(["nice", "-n", "10", "gdalwarp", "-q", "-overwrite", "-t_srs", CRS,
                           "-tr", str(res), str(res), "-tap", "-r", "bilinear", "-ot", "Float32",
                           "-dstnodata", "-9999", DEM, dst])
    return dst


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", help="output folder")
    ap.add_argument("--res", type=int, default=100, help="cell size, m (default 100)")
    ap.add_argument("--melt", choices=("eti", "hock", "ti"), default="eti",
                    help="openAMUNDSEN's enhanced temperature index (Pellicciotti), Hock's "
                    "formula on its radiation, or plain degree-days")
    ap.add_argument("--venv", help="the venv for openAMUNDSEN (default "
                    "build/peers-snowmelt-venv in the source tree)")
    ap.add_argument("--threads", type=int, default=os.cpu_count(),
                    help="numba threads for openAMUNDSEN")
    ap.add_argument("--compare", nargs=2, metavar=("PEER_NPZ", "GRAUPEL_NPZ"),
                    help="only compare two npz files (see compare())")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--full", help=argparse.SUPPRESS)
    a = ap.parse_args()

    venv = a.venv or os.path.join(ROOT, "build", "peers-snowmelt-venv")
    if a.compare:
        if importlib.util.find_spec("numpy") is None:  # a python3 without numpy: the venv's
            sys.exit(subprocess.call([os.path.join(venv, "bin", "python3"),
                                      os.path.abspath(__file__), "--compare"] + a.compare))
        compare(*a.compare)
        return
    if not a.out:
        ap.error("--out DIR is needed")
    a.out = os.path.abspath(a.out)
    if a.worker:
        worker(a)
        return

    t0 = time.perf_counter()
    os.makedirs(a.out, exist_ok=True)
    py = ensure_venv(venv)
    t_install = time.perf_counter() - t0
    t1 = time.perf_counter()
    full = warp(a.res, a.out)
    cmd = ["nice", "-n", "10", py, os.path.abspath(__file__), "--worker", "--out", a.out,
           "--res", str(a.res), "--melt", a.melt, "--threads", str(a.threads), "--full", full]
    t2 = time.perf_counter()
    if subprocess.call(cmd) != 0:
        sys.exit("the openAMUNDSEN run failed (see above)")
    t3 = time.perf_counter()
    os.remove(full)
    with open(os.path.join(a.out, "peer_openamundsen.json")) as fp:
        res = json.load(fp)
    res["times"].update(warp_s=t2 - t1, worker_process_s=t3 - t2, total_s=t3 - t1,
                        install_check_s=t_install)
    with open(os.path.join(a.out, "peer_openamundsen.json"), "w") as fp:
        json.dump(res, fp, indent=1)
    summary(res)


def summary(res):
    g, t = res["grid"], res["times"]
    print("\nopenAMUNDSEN %s, melt model `%s`, %d x %d cells of %d m (%.1f x %.1f km), "
          "station %.0f m, DEM %.0f..%.0f m"
          % (res["openamundsen_version"], res["melt"], g["cols"], g["rows"], g["res"],
             g["cols"] * g["res"] / 1e3, g["rows"] * g["res"] / 1e3,
             res["station"]["alt"], g["dem_min"], g["dem_max"]))
    print("wall: %.1f s in all (gdalwarp %.1f s, the worker process %.1f s: openAMUNDSEN's "
          "set-up %.1f s, %d steps %.1f s, %.1f ms a step)"
          % (t["total_s"], t["warp_s"], t["worker_process_s"], t["initialize_s"], t["steps"],
             t["run_s"], 1e3 * t["run_s"] / t["steps"]))
    print("| date | SWE mean mm | SWE max mm | snow-covered % |")
    print("|---|---|---|---|")
    for d, s in res["swe_stats"].items():
        print("| %s | %.1f | %.1f | %.1f |" % (d, s["mean"], s["max"], s["covered_pct"]))
    m = res["meltout_stats"]
    print("melt-out day of year %.2f..%.2f (median %.2f); never covered %d cells, still "
          "covered at the end %d" % (m["min"], m["max"], m["median"], m["never_covered"],
                                     m["covered_at_end"]))


# ---------------------------------------------------------------- worker (the venv)

def crop_valid(z, valid):
    """The rectangle with no no-data cells: drops the edge row or column with
    the most no-data until none is left (the UTM grid is turned 1.6° against
    the geographic box, so only thin wedges go)."""
    r0, r1, c0, c1 = 0, z.shape[0], 0, z.shape[1]
    while True:
        bad = ~valid[r0:r1, c0:c1]
        if not bad.any():
            return r0, r1, c0, c1
        edges = [bad[0].sum(), bad[-1].sum(), bad[:, 0].sum(), bad[:, -1].sum()]
        k = max(range(4), key=lambda i: edges[i])
        if k == 0:
            r0 += 1
        elif k == 1:
            r1 -= 1
        elif k == 2:
            c0 += 1
        else:
            c1 -= 1


def forcing(dates, sun):
    """The synthetic station, hourly: a DataFrame in openAMUNDSEN's CSV units
    (temp K, precip kg m-2 per step, rel_hum %, sw_in W m-2, wind_speed m/s,
    cloud_fraction %). sun(date) gives the cosine of the sun's zenith."""
    import numpy as np
    import pandas as pd
    d = np.asarray((dates - dates[0]) / pd.Timedelta(days=1), dtype=float)  # days since start
    hour = np.asarray(dates.hour, dtype=float)
    # Daily mean T_ref (°C) through control points (days since 1 March).
    days = [0, 12, 13.5, 17, 18.5, 31, 92]
    tmean = [-7, -7, 2, 2, -5, -5, 10]
    tm = np.interp(d, days, tmean)
    # Diurnal amplitude: small in the cloudy spells, large in spring.
    amp = np.interp(d, [0, 30, 32, 92], [3, 3, 5, 5])
    amp = np.where((d >= 13.5) & (d < 17), 2.0, amp)
    temp_c = tm + amp * np.cos(2 * np.pi * (hour - 15) / 24)
    # Precipitation events: (first day, last day, mm/h).
    events = [(0.5, 3.0, 1.5),     # 90 mm of snow
              (6.0, 7.5, 1.0),     # 36 mm of snow
              (14.5, 16.0, 1.0),   # 36 mm of rain on the snow
              (23.0, 25.5, 1.0),   # 60 mm of snow
              (61.5, 61.75, 2.0)]  # 1 May 12:00-18:00, 12 mm of rain everywhere
    precip = np.zeros_like(d)
    for a, b, rate in events:
        precip[(d >= a - 1e-9) & (d < b - 1e-9)] = rate
    wet = precip > 0
    cloud = np.where(wet, 90.0, 20.0)
    # Global radiation for the record (openAMUNDSEN takes its cloud factor
    # from cloud_fraction): a simple clear sky, 1361 cos z 0.75^(1/cos z),
    # times Kasten and Czeplak's cloud reduction.
    cz = np.array([sun(t) for t in dates])
    sw = np.where(cz > 0.01, 1361.0 * cz * 0.75 ** (1.0 / np.maximum(cz, 0.01)), 0.0)
    sw *= 1.0 - 0.75 * (cloud / 100.0) ** 3.4
    return pd.DataFrame({
        "temp": temp_c + 273.15,
        "precip": precip,  # mm/h = kg m-2 per hourly step
        "rel_hum": np.where(wet, 95.0, 70.0),
        "sw_in": sw,
        "wind_speed": np.where(wet, 4.0, 2.0),
        "cloud_fraction": cloud,
    }, index=pd.DatetimeIndex(dates, name="date"))


def config(a, work, station):
    melt = {"threshold_temp": 273.15 + PARAMS["melt_threshold_C"]}
    if a.melt == "eti":
        melt.update(method="enhanced_temperature_index",
                    degree_day_factor=PARAMS["eti"]["DDF_mm_per_day_K"],
                    albedo_factor=PARAMS["eti"]["SRF_mm_m2_per_W_day"])
    elif a.melt == "hock":  # temperature_index, its method replaced after initialize()
        melt.update(method="temperature_index",
                    degree_day_factor=PARAMS["hock"]["MF_mm_per_day_K"])
    else:
        melt.update(method="temperature_index",
                    degree_day_factor=PARAMS["ti"]["DDF_mm_per_day_K"])
    fixed = lambda v: {"trend_method": "fixed", "lapse_rate": [v] * 12}  # noqa: E731
    return {
        "domain": DOMAIN, "start_date": START, "end_date": END, "resolution": a.res,
        "timestep": "h", "crs": CRS, "timezone": TIMEZONE, "results_dir": work,
        "log_level": "WARNING", "numba_threads": a.threads,
        "input_data": {
            "grids": {"dir": os.path.join(work, "grids")},
            "meteo": {"dir": os.path.join(work, "meteo"), "format": "csv", "crs": CRS},
        },
        "output_data": {"timeseries": {"format": "memory", "add_default_points": False,
                                       "add_default_variables": False},
                        "grids": {"format": "memory", "variables": []}},
        "meteo": {
            "interpolation": {
                "temperature": fixed(PARAMS["lapse_rate_K_per_m"]),
                # adjustment factor (1 + g dz) / (1 - g dz): 1 with g = 0
                "precipitation": {"trend_method": "adjustment_factor",
                                  "lapse_rate": [PARAMS["precip_lapse_rate"]] * 12},
                "humidity": fixed(-0.0046),  # dew point, openAMUNDSEN's April value
                "wind": {"trend_method": "fixed", "lapse_rate": [0.0] * 12},
                "cloudiness": {"method": "prescribed"},
            },
            "precipitation_phase": {"method": "temp",
                                    "threshold_temp": 273.15 + PARAMS["phase_threshold_C"],
                                    "temp_range": PARAMS["phase_range_K"]},
        },
        "snow": {
            "model": "cryolayers",
            "melt": melt,
            "liquid_water_content": {"method": PARAMS["liquid_water_method"],
                                     "max": PARAMS["liquid_water_max_fraction"]},
        },
    }


def hock_melt(model):
    """Hock (1999) in place of CryoLayerSnowModel.temperature_index: the same
    bookkeeping (melt limited to the ice), the radiation openAMUNDSEN has
    just computed for the step (potential clear-sky direct, shadows)."""
    import numpy as np
    p = PARAMS["hock"]
    mf_h, a_rad = p["MF_mm_per_day_K"] / 24.0, p["a_mm_m2_per_W_h_K"]
    t0 = 273.15 + PARAMS["melt_threshold_C"]

    def temperature_index():
        s = model.state
        dt_h = model.timestep / 3600.0
        snowies = s.snow.thickness.sum(axis=0) > 0.0
        dT = s.meteo.temp[snowies] - t0
        melt = (mf_h + a_rad * s.meteo.dir_in_clearsky[snowies]) * dT * dt_h
        melt[dT <= 0.0] = 0.0
        s.snow.melt[model.grid.roi] = 0.0
        s.snow.melt[snowies] = np.minimum(melt.clip(min=0),
                                          s.snow.ice_content[:, snowies].sum(axis=0))
    return temperature_index


def make_grid(a, work):
    """The warped DEM cropped to its valid rectangle, written as the GeoTIFF
    for Graupel and as openAMUNDSEN's dem_<domain>_<res>.asc."""
    import numpy as np
    import rasterio
    from openamundsen import fileio
    with rasterio.open(a.full) as ds:
        z = ds.read(1)
        tr = ds.transform
        valid = ds.read_masks(1) > 0
    r0, r1, c0, c1 = crop_valid(z, valid)
    z = np.ascontiguousarray(z[r0:r1, c0:c1], dtype=np.float32)
    tr = tr * rasterio.Affine.translation(c0, r0)
    ny, nx = z.shape
    xs = tr.c + a.res * (np.arange(nx) + 0.5)
    ys = tr.f - a.res * (np.arange(ny) + 0.5)
    dem_tif = os.path.join(a.out, "dem_utm_%dm.tif" % a.res)
    write_tif(dem_tif, z, tr)
    fileio.write_raster_file(os.path.join(work, "grids", "dem_%s_%d.asc" % (DOMAIN, a.res)),
                             z, tr, decimal_precision=2)
    log("grid: %d x %d cells of %d m, %.0f..%.0f m; Graupel's DEM: %s"
        % (nx, ny, a.res, z.min(), z.max(), dem_tif))
    return z, tr, xs, ys, dem_tif


def write_forcing(a, work, z, xs, ys):
    """The station at the grid's centre cell: openAMUNDSEN's stations.csv and
    <id>.csv, and Graupel's forcing_graupel.csv. Returns the station."""
    import numpy as np
    import pandas as pd
    import openamundsen as oa
    from openamundsen.modules.radiation import sun_parameters
    sr, sc = z.shape[0] // 2, z.shape[1] // 2
    station = {"id": "synth", "name": "synthetic", "x": float(xs[sc]), "y": float(ys[sr]),
               "alt": float(z[sr, sc]), "row": sr, "col": sc}
    lon, lat = oa.util.transform_coords(station["x"], station["y"], CRS, "EPSG:4326")
    lon, lat = float(np.squeeze(lon)), float(np.squeeze(lat))
    station.update(lon=lon, lat=lat)
    dates = pd.date_range(START, END, freq="h")

    def cos_zenith(t):
        return float(sun_parameters(t, lon, lat, TIMEZONE)["sun_vector"][2])

    met = forcing(dates, cos_zenith)
    pd.DataFrame({"name": [station["name"]], "x": [station["x"]], "y": [station["y"]],
                  "alt": [station["alt"]]}, index=pd.Index([station["id"]], name="id")) \
        .to_csv(os.path.join(work, "meteo", "stations.csv"))
    met.to_csv(os.path.join(work, "meteo", station["id"] + ".csv"), float_format="%.4f")
    pd.DataFrame({"time_s": np.arange(len(dates)) * 3600,
                  "T_ref_C": met["temp"].values - 273.15,
                  "precip_mm_h": met["precip"].values}) \
        .to_csv(os.path.join(a.out, "forcing_graupel.csv"), index=False, float_format="%.4f")
    return station


def run_model(a, work, station, shape):
    """Initializes and steps openAMUNDSEN; keeps SWE at DATES and, per cell,
    the last step with SWE >= SNOW_MM."""
    import numpy as np
    import pandas as pd
    import openamundsen as oa
    t0 = time.perf_counter()
    model = oa.OpenAmundsen(config(a, work, station))
    model.initialize()
    if a.melt == "hock":
        model.snow.temperature_index = hock_melt(model)
    t_init = time.perf_counter() - t0

    want = {pd.Timestamp(d): d for d in DATES}
    swe = {}
    last_snow = np.full(shape, -1)
    t0 = time.perf_counter()
    for i in range(len(model.dates)):
        model.run_single()
        cur = model.state.snow.swe
        last_snow[cur >= SNOW_MM] = i
        if model.date in want:
            swe[want[model.date]] = cur.astype(np.float64).copy()
        if i % 240 == 0:
            log("  %s  mean SWE %.1f mm, %.0f s" % (model.date, np.nanmean(cur),
                                                    time.perf_counter() - t0))
    t_run = time.perf_counter() - t0
    return model, swe, last_snow, t_init, t_run


def worker(a):
    import numpy as np
    import openamundsen as oa

    work = os.path.join(a.out, "openamundsen")
    for sub in ("grids", "meteo"):
        os.makedirs(os.path.join(work, sub), exist_ok=True)
    svf = os.path.join(work, "grids", "svf_%s_%d.asc" % (DOMAIN, a.res))
    if os.path.exists(svf):  # openAMUNDSEN's cached sky view factor: made anew, and timed
        os.remove(svf)
    z, tr, xs, ys, dem_tif = make_grid(a, work)
    station = write_forcing(a, work, z, xs, ys)
    model, swe, last_snow, t_init, t_run = run_model(a, work, station, z.shape)

    # Melt-out: the first hour after the last snow-covered one.
    steps = len(model.dates)
    end_covered, never = last_snow == steps - 1, last_snow < 0
    step_doy = np.asarray(model.dates.day_of_year + model.dates.hour / 24.0, dtype=np.float64)
    doy = step_doy[np.clip(last_snow + 1, 0, steps - 1)]
    doy[never | end_covered] = np.nan

    out = {"swe_" + d: swe[d] for d in DATES}
    out.update(meltout_doy=doy, dem=z.astype(np.float64), x=xs, y=ys, north_up=True)
    np.savez_compressed(os.path.join(a.out, "peer_openamundsen.npz"), **out)
    for d in DATES:
        write_tif(os.path.join(a.out, "swe_%s.tif" % d), swe[d].astype(np.float32), tr)
    write_tif(os.path.join(a.out, "meltout_doy.tif"), doy.astype(np.float32), tr)

    stats = {d: {"mean": float(swe[d].mean()), "max": float(swe[d].max()),
                 "covered_pct": float(100.0 * (swe[d] >= SNOW_MM).mean())} for d in DATES}
    fin = doy[np.isfinite(doy)] if np.isfinite(doy).any() else np.array([np.nan])
    res = {
        "openamundsen_version": oa.__version__, "melt": a.melt, "params": PARAMS,
        "melt_params": PARAMS[a.melt], "snow_covered_mm": SNOW_MM,
        "openamundsen_config": {k: v for k, v in model.config.items()
                                if k in ("meteo", "snow")},
        "station": station, "start": START, "end": END, "timezone_utc": TIMEZONE,
        "dates": DATES,
        "grid": {"crs": CRS, "res": a.res, "rows": z.shape[0], "cols": z.shape[1],
                 "x_min": float(tr.c), "y_max": float(tr.f),
                 "dem_min": float(z.min()), "dem_max": float(z.max()), "dem_tif": dem_tif},
        "swe_stats": stats,
        "meltout_stats": {"min": float(fin.min()), "max": float(fin.max()),
                          "median": float(np.median(fin)), "never_covered": int(never.sum()),
                          "covered_at_end": int(end_covered.sum())},
        "times": {"initialize_s": t_init, "run_s": t_run, "steps": steps,
                  "numba_threads": a.threads},
    }
    with open(os.path.join(a.out, "peer_openamundsen.json"), "w") as fp:
        json.dump(res, fp, indent=1, default=str)


def write_tif(path, data, transform):
    import numpy as np
    import rasterio
    with rasterio.open(path, "w", driver="GTiff", width=data.shape[1], height=data.shape[0],
                       count=1, dtype=data.dtype, crs=CRS, transform=transform,
                       nodata=np.nan if data.dtype.kind == "f" else None,
                       compress="deflate") as ds:
        ds.write(data, 1)


# ---------------------------------------------------------------- comparison

def compare(peer_npz, graupel_npz, tol_days=3.0):
    """Per date: Pearson's r of the SWE maps, the bias (mean of Graupel -
    peer, mm, and relative to the peer's mean); the melt-out day difference
    (Graupel - peer) over the cells melted out in both: mean, median and %
    within +-tol_days. Prints a markdown table and returns the rows."""
    import numpy as np
    p, g = np.load(peer_npz), np.load(graupel_npz)

    def grid(f, key):
        v = np.asarray(f[key], dtype=np.float64)
        up = bool(f["north_up"]) if "north_up" in f.files else True
        return v if up else v[::-1]

    rows = []
    print("| date | r | bias mm | bias % | peer mean mm | Graupel mean mm |")
    print("|---|---|---|---|---|---|")
    for key in sorted(k for k in p.files if k.startswith("swe_")):
        if key not in g.files:
            print("| %s | (not in %s) | | | | |" % (key[4:], os.path.basename(graupel_npz)))
            continue
        a, b = grid(p, key), grid(g, key)
        if a.shape != b.shape:
            raise SystemExit("%s: shapes differ, %s and %s" % (key, a.shape, b.shape))
        m = np.isfinite(a) & np.isfinite(b)
        x, y = a[m], b[m]
        r = float(np.corrcoef(x, y)[0, 1]) if x.std() > 0 and y.std() > 0 else float("nan")
        bias = float((y - x).mean())
        rel = 100.0 * bias / x.mean() if x.mean() != 0 else float("nan")
        rows.append({"date": key[4:], "r": r, "bias_mm": bias, "bias_pct": rel,
                     "peer_mean": float(x.mean()), "graupel_mean": float(y.mean())})
        print("| %s | %.4f | %.2f | %.1f | %.2f | %.2f |"
              % (key[4:], r, bias, rel, x.mean(), y.mean()))
    a, b = grid(p, "meltout_doy"), grid(g, "meltout_doy")
    both = np.isfinite(a) & np.isfinite(b)
    dd = b[both] - a[both]
    mo = {"cells": int(both.sum()), "peer_only": int((np.isfinite(a) & ~np.isfinite(b)).sum()),
          "graupel_only": int((~np.isfinite(a) & np.isfinite(b)).sum())}
    if dd.size:
        mo.update(mean_days=float(dd.mean()), median_days=float(np.median(dd)),
                  within_pct=float(100.0 * (np.abs(dd) <= tol_days).mean()))
        print("\n| melt-out (Graupel - peer) | mean d | median d | within ±%g d | cells | "
              "melted out in the peer only | in Graupel only |" % tol_days)
        print("|---|---|---|---|---|---|---|")
        print("| day of year | %.2f | %.2f | %.1f %% | %d | %d | %d |"
              % (mo["mean_days"], mo["median_days"], mo["within_pct"], mo["cells"],
                 mo["peer_only"], mo["graupel_only"]))
    else:
        print("\nmelt-out: no cell melted out in both")
    rows.append({"meltout": mo})
    return rows


if __name__ == "__main__":
    main()
