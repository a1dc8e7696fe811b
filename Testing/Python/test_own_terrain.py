"""README's "Run it on your own terrain" runs as written: its python block is
taken from README.md and run by pvbatch in a scratch folder where Data/ and
build/ lead to the source's data and this build (the block names them
relative to the source folder). Then what the README says it writes must be
there and hold what it says: flood.png a picture with water drawn,
flood_maps.exr the four maps at the DEM's real size with the run's ledger,
hydrograph.csv a row every 300 s to 3600 s with the rain's volume rate."""
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
for name in ("flood.png", "flood_maps.exr", "hydrograph.csv"):
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
if "rain_volume" in ledger:
    rain = float(ledger["rain_volume"])
    # 50 mm/h for an hour on 403 x 344 points of 74.5 x 92.1 m (each point a cell).
    want = 0.05 * 403 * 344 * 74.5 * 92.1
    T.check(abs(rain - want) <= 1e-3 * want, "rain volume %.6g m3, %.6g expected" % (rain, want))
    T.check(abs(float(ledger["balance_error"])) <= 1e-6 * rain, "the ledger closes")

from vtkmodules.vtkIOImage import vtkPNGReader  # noqa: E402
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402

png = os.path.join(folder, "flood.png")
T.check(os.path.exists(png), "flood.png written")
if os.path.exists(png):
    r = vtkPNGReader()
    r.SetFileName(png)
    r.Update()
    dims = r.GetOutput().GetDimensions()
    rgb = vtk_to_numpy(r.GetOutput().GetPointData().GetScalars())[:, :3].astype(int)
    # Water on the default map is blue: blue well above red.
    blue = float(((rgb[:, 2] - rgb[:, 0]) > 60).mean())
    T.check(dims[:2] == (900, 800), "flood.png is 900 x 800 (%s)" % (dims,))
    T.check(blue > 0.005, "water is drawn: %.4f of the picture blue" % blue)

import graupel  # noqa: E402

maps = os.path.join(folder, "flood_maps.exr")
T.check(os.path.exists(maps), "flood_maps.exr written")
if os.path.exists(maps):
    rd = graupel.vtkEXRHeightFieldReader()
    rd.SetFileName(maps)
    rd.Update()
    img = rd.GetOutput()
    pd = img.GetPointData()
    names = sorted(pd.GetArrayName(i) for i in range(pd.GetNumberOfArrays()))
    T.check(names == ["arrival_time", "hazard_class", "max_depth", "max_speed"],
            "the four maps (%s)" % names)
    T.check(img.GetDimensions() == (403, 344, 1) and img.GetSpacing()[:2] == (74.5, 92.1),
            "the DEM's grid and real spacing (%s, %s)" % (img.GetDimensions(), img.GetSpacing()))
    fd = img.GetFieldData().GetArray("rain_volume")
    T.check(fd is not None and "rain_volume" in ledger
            and abs(fd.GetValue(0) - float(ledger["rain_volume"])) <= 1e-9 * fd.GetValue(0),
            "the ledger travels with the maps")
    if pd.GetArray("max_depth") is not None:
        T.check(pd.GetArray("max_depth").GetRange()[1] > 1.0, "water deeper than 1 m somewhere")

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
