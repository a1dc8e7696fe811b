#!/usr/bin/env python3
"""Graupel's side of the Snow Melt peer comparison: the season that
peers_snowmelt.py gave openAMUNDSEN, run with Snow Melt on the same grid and
forcing, written as the npz that peers_snowmelt.compare() reads.

    pvpython Testing/Benchmarks/graupel_snowmelt_season.py PEER_DIR [--step 3600]
        (or python3 with Graupel's VTK module on PYTHONPATH)

PEER_DIR is peers_snowmelt.py's --out folder: dem_utm_<res>m.tif (the grid),
forcing_graupel.csv (T_ref at the station, precipitation) and
peer_openamundsen.json (the station's elevation, the melt parameters, the
dates). Snow Melt gets the same model where the two agree: Hock's formula with
the JSON's MF and a, T0, the lapse rate from the station, the rain/snow band,
liquid water held up to 10 % and no refreezing (openAMUNDSEN's temperature-index
models have none); its own clear-sky radiation and horizons. Written: PEER_DIR/
graupel_snowmelt.npz (swe_<date> in mm at 00:00 of each date, meltout_doy as the
peer defines it, north_up False) and the wall time, then the comparison table.
"""
import argparse
import csv
import datetime as dt
import json
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy  # noqa: E402
from vtkmodules.vtkCommonCore import vtkDoubleArray  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkTable  # noqa: E402
from vtkmodules.vtkCommonExecutionModel import vtkTrivialProducer  # noqa: E402

import graupel  # noqa: E402

ap = argparse.ArgumentParser()
ap.add_argument("peer_dir")
ap.add_argument("--step", type=float, default=3600.0, help="output interval, s")
a = ap.parse_args()

meta = json.load(open(os.path.join(a.peer_dir, "peer_openamundsen.json")))
res = meta["grid"]["res"]
params, hock = meta["params"], meta["params"]["hock"]
start = dt.datetime.fromisoformat(meta["start"])
rows = list(csv.DictReader(open(os.path.join(a.peer_dir, "forcing_graupel.csv"))))
end = float(rows[-1]["time_s"]) + 3600.0

# The terrain in metres (GIS Raster Reader), with no snow yet.
reader = graupel.vtkGISRasterReader()
reader.SetFileName(os.path.join(a.peer_dir, "dem_utm_%dm.tif" % res))
reader.Update()
terrain = vtkImageData()
terrain.DeepCopy(reader.GetOutput())
n = terrain.GetNumberOfPoints()
for name, value in (("snow_depth", 0.0), ("snow_density", 100.0)):
    arr = numpy_to_vtk(np.full(n, value, np.float32), deep=1)
    arr.SetName(name)
    terrain.GetPointData().AddArray(arr)
src = vtkTrivialProducer()
src.SetOutput(terrain)

forcing = vtkTable()
for column, key in (("time", "time_s"), ("air_temperature", "T_ref_C"),
                    ("precipitation", "precip_mm_h")):
    c = vtkDoubleArray()
    c.SetName(column)
    for r in rows:
        c.InsertNextValue(float(r[key]))
    forcing.AddColumn(c)
table = vtkTrivialProducer()
table.SetOutput(forcing)

melt = graupel.vtkSnowMeltFilter()
melt.SetInputConnection(0, src.GetOutputPort())
melt.SetInputConnection(1, table.GetOutputPort())
melt.SetEndTime(end)
melt.SetOutputInterval(a.step)
melt.SetTimeStep(3600.0)
melt.SetLatitude(meta["station"]["lat"])
# Snow Melt's clock is local solar time: the start's standard time (UTC
# timezone_utc) moved by the longitude's offset from the zone's meridian
# (the equation of time, within a quarter of an hour, left out).
solar = start + dt.timedelta(hours=(meta["station"]["lon"] - 15.0 * meta["timezone_utc"]) / 15.0)
melt.SetStartDayOfYear(solar.timetuple().tm_yday)
melt.SetStartHour(solar.hour + solar.minute / 60.0 + solar.second / 3600.0)
melt.SetReferenceElevation(meta["station"]["alt"])
melt.SetLapseRate(1000.0 * params["lapse_rate_K_per_m"])
melt.SetThresholdTemperature(params["melt_threshold_C"])
melt.SetMeltFactor(hock["MF_mm_per_day_K"])
melt.SetRadiationFactor(hock["a_mm_m2_per_W_h_K"])
melt.SetRainSnowThreshold(params["phase_threshold_C"])
melt.SetRainSnowBand(params["phase_range_K"])
melt.SetLiquidWaterCapacity(params["liquid_water_max_fraction"])
melt.SetRefreezeFactor(0.0)

dates = {d: (dt.datetime.fromisoformat(d) - start).total_seconds() for d in meta["dates"]}
nx, ny, _ = terrain.GetDimensions()
covered = meta.get("snow_covered_mm", 1.0)
last_covered = np.full((ny, nx), np.nan)
ever = np.zeros((ny, nx), bool)
out = {"north_up": False}
t0 = time.time()
steps = int(round(end / a.step))
for k in range(steps + 1):
    t = k * a.step
    melt.UpdateTimeStep(t)
    o = melt.GetOutput()
    swe = 1000.0 * vtk_to_numpy(o.GetPointData().GetArray("swe")).reshape(ny, nx)
    now = swe >= covered
    ever |= now
    last_covered[now] = t
    for d, td in dates.items():
        if abs(t - td) < 0.5:
            out["swe_" + d] = swe.astype(np.float64)
wall = time.time() - t0
# Melt-out: the first time from which SWE stays below the threshold to the
# end (the output after the last covered one); NaN if never covered or still
# covered at the end.
meltout = np.where(ever & (last_covered < steps * a.step), last_covered + a.step, np.nan)
doy0 = start.timetuple().tm_yday + start.hour / 24.0
out["meltout_doy"] = doy0 + meltout / 86400.0
path = os.path.join(a.peer_dir, "graupel_snowmelt.npz")
np.savez(path, **out)
fd = o.GetFieldData()
print("Snow Melt: %d x %d points, %d outputs of %g s, %.1f s wall (%s); balance_error %g m3"
      % (nx, ny, steps + 1, a.step, wall, fd.GetAbstractArray("graupel_device").GetValue(0),
         fd.GetArray("balance_error").GetValue(0)))
import peers_snowmelt  # noqa: E402

peers_snowmelt.compare(os.path.join(a.peer_dir, "peer_openamundsen.npz"), path)
