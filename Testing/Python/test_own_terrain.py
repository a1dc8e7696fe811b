"""README's "Run it on your own terrain" runs as written: its python block is
taken from README.md and run by pvbatch in a scratch folder where Data/ and
build/ lead to the source's data and this build (the block names them
relative to the source folder). Then what the README says it writes must be
there and hold what it says: flood.png a picture with water drawn,
flood_maps.tif four bands on the reader's grid in the DEM's UTM zone (read
with GDAL), NaN outside the DEM, hydrograph.csv a row every 300 s to 3600 s
with the rain's volume rate."""
import csv
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402


def extra(p):
    p.add_argument("--readme", required=True)
    p.add_argument("--build", required=True)
    p.add_argument("--pvbatch", required=True)


a = T.args(extra)
text = open(a.readme, encoding="utf-8").read()
section = text.split("## Run it on your own terrain", 1)
T.check(len(section) == 2, "README has the section")
block = re.search(r"```python\n(.*?)```", section[1], re.S) if len(section) == 2 else None
T.check(block is not None, "the section has a python block")
if block is None:
    T.finish()
folder = os.path.join(a.scratch, "own_terrain")
os.makedirs(folder, exist_ok=True)
for name in ("flood.png", "flood_maps.tif", "hydrograph.csv"):
    if os.path.exists(os.path.join(folder, name)):
        os.remove(os.path.join(folder, name))
for link, target in (("Data", a.data), ("build", a.build)):
    path = os.path.join(folder, link)
    if os.path.islink(path):
        os.remove(path)
    os.symlink(os.path.abspath(target), path)
script = os.path.join(folder, "own_terrain.py")
with open(script, "w") as f:
    f.write(block.group(1))
run = subprocess.run([a.pvbatch, script], cwd=folder, capture_output=True, text=True, timeout=280)
print(run.stdout[-3000:])
print(run.stderr[-3000:])
T.check(run.returncode == 0, "the block runs (exit %d)" % run.returncode)
ledger = dict(re.findall(r"^(\w+) (\S+) m3$", run.stdout, re.M))
T.check(set(ledger) == {"rain_volume", "outflow_volume", "stored_volume", "balance_error"},
        "it prints the ledger (%s)" % sorted(ledger))
import graupel  # noqa: E402

dem = graupel.vtkGISRasterReader()
dem.SetFileName(os.path.join(a.data, "jacksboro_fault_dem.tif"))
dem.Update()
grid = dem.GetOutput()
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402
import numpy as np  # noqa: E402

z = vtk_to_numpy(grid.GetPointData().GetArray("elevation"))
if "rain_volume" in ledger:
    rain = float(ledger["rain_volume"])
    # 50 mm/h for an hour on every point with data, each a cell of dx dy.
    want = 0.05 * np.count_nonzero(~np.isnan(z)) * grid.GetSpacing()[0] * grid.GetSpacing()[1]
    T.check(abs(rain - want) <= 1e-3 * want, "rain volume %.6g m3, %.6g expected" % (rain, want))
    T.check(abs(float(ledger["balance_error"])) <= 1e-6 * rain, "the ledger closes")

from vtkmodules.vtkIOImage import vtkPNGReader  # noqa: E402

png = os.path.join(folder, "flood.png")
T.check(os.path.exists(png), "flood.png written")
if os.path.exists(png):
    r = vtkPNGReader()
    r.SetFileName(png)
    r.Update()
    dims = r.GetOutput().GetDimensions()
    rgb = vtk_to_numpy(r.GetOutput().GetPointData().GetScalars())[:, :3].astype(int)
    rgb = rgb.reshape(dims[1], dims[0], 3)
    # The middle of the picture (the legend and the axes lie outside it):
    # the terrain covers it, and water (blue well above red) shows on it.
    mid = rgb[dims[1] // 5:4 * dims[1] // 5, dims[0] // 5:4 * dims[0] // 5].reshape(-1, 3)
    background = rgb[2, 2]
    drawn = float((np.abs(mid - background).sum(axis=1) > 30).mean())
    blue = float(((mid[:, 2] - mid[:, 0]) > 60).mean())
    T.check(dims[:2] == (900, 800), "flood.png is 900 x 800 (%s)" % (dims,))
    T.check(drawn > 0.9, "the terrain is drawn: %.3f of the middle is not background" % drawn)
    T.check(blue > 0.02, "water is drawn: %.4f of the middle is blue" % blue)

maps = os.path.join(folder, "flood_maps.tif")
T.check(os.path.exists(maps), "flood_maps.tif written")
if os.path.exists(maps):
    from osgeo import gdal, osr

    ds = gdal.Open(maps)
    names = [ds.GetRasterBand(k + 1).GetDescription() for k in range(ds.RasterCount)]
    T.check(names == ["max_depth", "max_speed", "arrival_time", "hazard_class"],
            "the four maps (%s)" % names)
    gt = ds.GetGeoTransform()
    T.check((ds.RasterXSize, ds.RasterYSize) == grid.GetDimensions()[:2]
            and abs(gt[1] - grid.GetSpacing()[0]) < 1e-9
            and abs(gt[0] + 0.5 * gt[1] - grid.GetOrigin()[0]) < 1e-6,
            "the reader's grid (%s, %s)" % ((ds.RasterXSize, ds.RasterYSize), gt))
    srs = osr.SpatialReference(wkt=ds.GetProjection())
    T.check(srs.IsProjected() == 1 and srs.GetUTMZone() == 16, "in UTM zone 16")
    depth = ds.GetRasterBand(1).ReadAsArray()[::-1].ravel()
    T.check(np.array_equal(np.isnan(depth), np.isnan(z)), "NaN outside the DEM, as read")
    T.check(np.nanmax(depth) > 1.0, "water deeper than 1 m somewhere (%.2f)" % np.nanmax(depth))

hyd = os.path.join(folder, "hydrograph.csv")
T.check(os.path.exists(hyd), "hydrograph.csv written")
if os.path.exists(hyd):
    rows = list(csv.DictReader(open(hyd)))
    times = [float(r["time"]) for r in rows]
    T.check(times == [300.0 * k for k in range(13)], "a row every 300 s to 3600 s (%s)" % times)
    if "rain_volume" in ledger and len(rows) > 1:
        rate = float(rows[-1]["rain_volume_rate"])
        T.check(abs(rate - float(ledger["rain_volume"]) / 3600.0) <= 1e-4 * rate,
                "rain_volume_rate %.6g m3/s is the rain over the hour" % rate)
T.finish()
