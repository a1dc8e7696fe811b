"""vtkRainRunoffFilter in a pipeline (pvpython in the plugin build, plain
python3 on Debian's VTK): advertised times, results independent of the order
in which times are requested (a request going backwards restarts), the water
ledger in field data, the permeability map, pieces, an aborted update
(between intervals and inside one), checkpoints, progress text, clamped
properties, and error paths with one sentence and an empty output."""
import os
import re
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args()

from vtkmodules.util.numpy_support import vtk_to_numpy, numpy_to_vtk  # noqa: E402
from vtkmodules.vtkCommonCore import vtkPoints  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkPolyData  # noqa: E402
from vtkmodules.vtkCommonExecutionModel import (  # noqa: E402
    vtkStreamingDemandDrivenPipeline as SDDP,
    vtkTrivialProducer,
)

from graupel import vtkRainRunoffFilter  # noqa: E402

NX, NY, DX = 40, 32, 2.0
MM_PER_H = 1.0 / 3.6e6


def image(arrays, dims=(NX, NY), spacing=DX):
    img = vtkImageData()
    img.SetDimensions(dims[0], dims[1], 1)
    img.SetSpacing(spacing, spacing, 1.0)
    img.SetOrigin(100.0, -50.0, 0.0)
    for name, values in arrays.items():
        arr = numpy_to_vtk(np.ascontiguousarray(values, dtype=np.float32).reshape(-1), deep=1)
        arr.SetName(name)
        img.GetPointData().AddArray(arr)
    return img


_producers = []  # a vtkAlgorithmOutput does not keep its producer alive


def producer(img):
    p = vtkTrivialProducer()
    p.SetOutput(img)
    _producers.append(p)
    return p


j, i = np.mgrid[0:NY, 0:NX]
x = (i - (NX - 1) / 2.0) * DX
y = (j - (NY - 1) / 2.0) * DX
bowl = 0.004 * (x * x + y * y)  # metres; deepest in the middle
slope = 0.05 * i * DX           # rising to the east


def rain(terrain, **kw):
    f = vtkRainRunoffFilter()
    f.SetInputConnection(producer(image({"elevation": terrain})).GetOutputPort())
    f.SetEndTime(kw.pop("EndTime", 60.0))
    f.SetOutputInterval(kw.pop("OutputInterval", 10.0))
    # 10 mm/h unless a test says otherwise: the rain these tests were written
    # with (the default before it became 100), not whatever the default is.
    f.SetRainRate(kw.pop("RainRate", 10.0))
    for k, v in kw.items():
        getattr(f, "Set" + k)(v)
    return f


def at(f, t):
    f.UpdateTimeStep(t)
    out = f.GetOutput()
    if out.GetNumberOfPoints() == 0:
        return None, out
    nx, ny, _ = out.GetDimensions()
    d = vtk_to_numpy(out.GetPointData().GetArray("water_depth")).reshape(ny, nx).copy()
    return d, out


def field(out, name):
    return out.GetFieldData().GetArray(name).GetValue(0)


# ---- defaults and advertised times ---------------------------------------------
f = vtkRainRunoffFilter()
T.check(f.GetRainRate() == 100.0 and f.GetPermeability() == 0.0 and f.GetManningN() == 0.03,
        "defaults RainRate 100 mm/h, Permeability 0, ManningN 0.03")
T.check(f.GetBoundary() == 0 and f.GetEndTime() == 600.0 and f.GetOutputInterval() == 10.0,
        "defaults Boundary open, EndTime 600 s, OutputInterval 10 s")
T.check(f.GetFlowModel() == 0, "default FlowModel 0 (shallow water)")

f = rain(bowl, EndTime=65.0, Boundary=1, RainRate=36.0)
f.UpdateInformation()
info = f.GetOutputInformation(0)
steps = [info.Get(SDDP.TIME_STEPS(), k) for k in range(info.Length(SDDP.TIME_STEPS()))]
T.check(steps == [0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 65.0],
        "TIME_STEPS every 10 s up to EndTime 65: %r" % steps)
T.check([info.Get(SDDP.TIME_RANGE(), k) for k in range(2)] == [0.0, 65.0], "TIME_RANGE")

# ---- ledger: rain in, nothing out through a closed edge ------------------------
d0, out = at(f, 0.0)
T.check(d0 is not None and float(np.abs(d0).max()) == 0.0, "dry at t = 0")
d65, out = at(f, 65.0)
area = NX * NY * DX * DX  # one point, one cell of DX x DX
rain_expected = 36.0 * MM_PER_H * 65.0 * area
T.near(field(out, "time"), 65.0, 1e-9, "field data time")
# The device adds the rate as a float32, and the ledger counts what it adds.
T.near(field(out, "rain_volume"), rain_expected, 1e-7 * rain_expected, "rain_volume = rate t area")
T.check(field(out, "outflow_volume") == 0.0, "closed edge: no outflow")
T.near(field(out, "stored_volume"), rain_expected, 1e-5 * rain_expected,
       "stored = rain (closed, sealed ground)")
T.check(abs(field(out, "balance_error")) <= 1e-5 * rain_expected,
        "balance_error %g within 1e-5 of the rain" % field(out, "balance_error"))
T.check(out.GetInformation().Get(out.DATA_TIME_STEP()) == 65.0, "DATA_TIME_STEP 65")
T.check(d65[NY // 2, NX // 2] > d65[0, 0], "water pools in the middle of the bowl")
T.check(float(d65.min()) >= 0.0, "no negative depth")
names = [out.GetPointData().GetArrayName(k) for k in range(out.GetPointData().GetNumberOfArrays())]
for n in ("water_depth", "water_surface", "velocity", "discharge", "infiltrated", "elevation"):
    T.check(n in names, "output array %s" % n)
surf = vtk_to_numpy(out.GetPointData().GetArray("water_surface")).reshape(NY, NX)
T.check(np.allclose(surf, bowl + d65, atol=1e-5), "water_surface = elevation + depth")
T.check(out.GetPointData().GetArray("velocity").GetNumberOfComponents() == 3, "velocity 3-D")

# ---- order of requests: backwards restarts, results identical -------------------
fwd = rain(slope + bowl, RainRate=50.0)
ref = {t: at(fwd, t)[0] for t in (0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0)}
T.check(fwd.GetRestartCount() == 1, "forward requests set up once, never restart")
mixed = rain(slope + bowl, RainRate=50.0)
order = (50.0, 20.0, 60.0, 0.0, 30.0, 30.0, 10.0, 40.0)
same = True
for t in order:
    d, _ = at(mixed, t)
    same = same and d is not None and np.array_equal(d, ref[t])
T.check(same, "every time equals the forward run bit for bit, whatever the order %r" % (order,))
# 20 after 50, 0 after 60 and 10 after 30 go back: three restarts after the set-up.
T.check(mixed.GetRestartCount() == 4,
        "each request for an earlier time restarts once (1 + 3), got %d" % mixed.GetRestartCount())
d, _ = at(mixed, 34.9)
T.check(np.array_equal(d, ref[30.0]), "a time between outputs gives the output before it")
d, _ = at(mixed, 1e9)
T.check(np.array_equal(d, ref[60.0]), "a time after EndTime gives the last output")
T.check(not np.array_equal(ref[60.0], ref[30.0]), "the field does change in time")

# A changed property sets the simulation up again.
mixed.SetRainRate(5.0)
d, out = at(mixed, 60.0)
T.check(mixed.GetRestartCount() == 6 and d.sum() < ref[60.0].sum(),
        "less rain after RainRate changed: %g < %g" % (d.sum(), ref[60.0].sum()))

# ---- open edge on a slope: water leaves at the low (west) edge -----------------
op = rain(slope, RainRate=100.0, EndTime=120.0, OutputInterval=60.0)
d, out = at(op, 120.0)
T.check(field(out, "outflow_volume") > 0.0, "open edge: outflow > 0")
T.check(d[:, 0].mean() > d[:, -1].mean(), "deeper at the low edge than at the high edge")
stored, rin, outf = (field(out, k) for k in ("stored_volume", "rain_volume", "outflow_volume"))
T.check(abs(rin - outf - stored) <= 1e-5 * rin, "stored = rain - outflow (%g %g %g)"
        % (stored, rin, outf))

# ---- permeability map ------------------------------------------------------------
k = np.where(i < NX // 2, 0.0, 20.0 * MM_PER_H)  # the east half drinks 20 mm/h
pm = rain(np.zeros((NY, NX)), RainRate=10.0, Boundary=1, EndTime=30.0)
pm.SetPermeabilityMapConnection(producer(image({"permeability": k})).GetOutputPort())
d, out = at(pm, 30.0)
inf = vtk_to_numpy(out.GetPointData().GetArray("infiltrated")).reshape(NY, NX)
T.check(float(inf[:, : NX // 2].max()) == 0.0, "sealed half infiltrates nothing")
T.near(float(inf[:, NX // 2 + 2:].mean()), 10.0 * MM_PER_H * 30.0, 1e-3 * 10.0 * MM_PER_H * 30.0,
       "permeable half takes all the rain (capacity 20 > rain 10 mm/h)")
T.check(field(out, "infiltrated_volume") > 0.0, "infiltrated_volume > 0")
wrong = rain(np.zeros((NY, NX)))
wrong.SetPermeabilityMapConnection(
    producer(image({"permeability": np.zeros((NY - 1, NX))}, dims=(NX, NY - 1))).GetOutputPort())
errs = T.ErrorCatcher(wrong)
d, out = at(wrong, 10.0)
T.check(d is None and "PermeabilityMap" in errs.text() and "resample" in errs.text(),
        "mismatched map refused with a sentence: %r" % errs.text()[:200])

# ---- pieces: a requested sub-extent is that part of the whole ------------------
pc = rain(slope + bowl, RainRate=50.0)
pc.UpdateInformation()
pc.GetOutputInformation(0).Set(SDDP.UPDATE_TIME_STEP(), 40.0)
pc.UpdateExtent((5, 20, 3, 30, 0, 0))
piece = pc.GetOutput()
T.check(tuple(piece.GetExtent()) == (5, 20, 3, 30, 0, 0), "piece extent %r" % (piece.GetExtent(),))
pd = vtk_to_numpy(piece.GetPointData().GetArray("water_depth")).reshape(28, 16)
T.check(np.array_equal(pd, ref[40.0][3:31, 5:21]), "the piece equals that part of the whole")
# A piece asked for by number (as MPI ranks do): the terrain must still be
# read whole, or the simulation would run on the piece alone.
pn = rain(slope + bowl, RainRate=50.0)
pn.UpdateInformation()
pn.GetOutputInformation(0).Set(SDDP.UPDATE_TIME_STEP(), 40.0)
pn.UpdatePiece(1, 2, 0)
e = pn.GetOutput().GetExtent()
# (Pieces are strips along y, the split an MPI run simulates.)
T.check(e[3] - e[2] + 1 < NY and e[1] - e[0] + 1 == NX, "piece 1 of 2 is a strip: %r" % (e,))
pd = vtk_to_numpy(pn.GetOutput().GetPointData().GetArray("water_depth")).reshape(
    e[3] - e[2] + 1, e[1] - e[0] + 1)
T.check(np.array_equal(pd, ref[40.0][e[2]:e[3] + 1, e[0]:e[1] + 1]),
        "piece 1 of 2 equals that part of the whole")

# ---- an aborted update: empty output, then it goes on from where it stopped ----
ab = rain(slope + bowl, RainRate=50.0)
abort = T.AbortOnce(ab)
warns = T.ErrorCatcher(ab, event="WarningEvent")
d, out = at(ab, 60.0)
T.check(abort.hits == 1 and d is None, "an aborted update leaves an empty output")
T.check("aborted" in warns.text(), "abort warning: %r" % warns.text())
reached = ab.GetStateIndex()
T.check(0 < reached < 6, "the state reached (%d) is kept" % reached)
abort.remove()
d, out = at(ab, 60.0)
T.check(d is not None and np.array_equal(d, ref[60.0]), "the next update finishes, equal to a full run")
T.check(ab.GetRestartCount() == 1, "going on after an abort needs no restart")

# ---- progress names the simulated time ---------------------------------------
pr = rain(slope + bowl, RainRate=50.0, EndTime=120.0)
texts = []
pr.AddObserver("ProgressEvent", lambda o, e: texts.append(o.GetProgressText()))
at(pr, 60.0)
T.check("Rain Runoff: t = 30 s of 60 s" in texts,
        "progress text names the time: %r" % texts[:8])
# The bar agrees with the text, also when the update resumes from the state
# kept at 60 s (before, a resumed update's bar counted from 0 % again).
bars = []
pr.AddObserver("ProgressEvent", lambda o, e: bars.append((o.GetProgressText(), o.GetProgress())))
at(pr, 120.0)
inside = [(t, p) for t, p in bars if " s of " in t and 0.0 < p < 1.0]
agree = [abs(p - float(t.split("t = ")[1].split(" s")[0]) / 120.0) < 0.02 for t, p in inside]
T.check(len(inside) > 0 and all(agree) and min(p for _, p in inside) >= 0.45,
        "progress from 60 to 120 s is t/120: %r" % inside[:4])

# ---- checkpoints: going back restores the nearest one, same bits --------------
ck = rain(slope + bowl, RainRate=50.0, CheckpointInterval=2)
d60, _ = at(ck, 60.0)
T.check(ck.GetNumberOfCheckpoints() == 3, "checkpoints at 20, 40, 60 s: %d"
        % ck.GetNumberOfCheckpoints())
d30, _ = at(ck, 30.0)
T.check(np.array_equal(d60, ref[60.0]) and np.array_equal(d30, ref[30.0]),
        "checkpointed results equal the forward run bit for bit")
T.check(ck.GetRestoreCount() == 1 and ck.GetRestartCount() == 1,
        "back to 30 s restored the 20 s checkpoint (restores %d, restarts %d)"
        % (ck.GetRestoreCount(), ck.GetRestartCount()))

# ---- an abort inside one output interval, then the same bits ---------------------
# Small steps make one 10 s interval take long enough (> 0.1 s of wall time)
# for the core to report progress inside it.
def slow():
    return rain(slope + bowl, RainRate=50.0, EndTime=20.0, MaxTimeStep=0.002,
                CheckpointInterval=1)


full = slow()
at(full, 10.0)
t0 = time.perf_counter()
ref_slow = at(full, 20.0)[0]
interval_s = time.perf_counter() - t0  # wall time of the 10 -> 20 s interval
ai = slow()
at(ai, 10.0)  # kept as a checkpoint
inside = []


# The abort ParaView's GUI sends (ParaView 6.1, and the plugin's
# pqGraupelAbortStarter on 5.11) is SetAbortExecuteAndUpdateTime on the
# running algorithm, from a progress event: the same here, on the first
# progress inside the interval.
def abort_inside(obj, event):
    if 0.0 < obj.GetProgress() < 1.0 and not inside:
        inside.append((obj.GetProgressText(), obj.GetProgress(), time.perf_counter()))
        if hasattr(obj, "SetAbortExecuteAndUpdateTime"):  # VTK >= 9.2
            obj.SetAbortExecuteAndUpdateTime()
        else:
            obj.SetAbortExecute(1)


tag = ai.AddObserver("ProgressEvent", abort_inside)
warns = T.ErrorCatcher(ai, event="WarningEvent")
d, _ = at(ai, 20.0)
stop_s = time.perf_counter() - inside[0][2] if inside else float("inf")
ai.RemoveObserver(tag)
T.check(len(inside) == 1 and d is None, "aborted inside the interval at %r: empty output"
        % (inside[:1],))
remaining_s = interval_s * (1.0 - inside[0][1]) if inside else 0.0
T.check(stop_s < 0.5, "the abort stopped the update within 0.5 s: %.3f s (the rest of the "
        "interval would have taken %.2f s)" % (stop_s, remaining_s))
T.check(bool(inside) and re.fullmatch(r"Rain Runoff: t = \d+(\.\d)? s of 20 s", inside[0][0]),
        "progress text rounded to a thousandth of the requested time: %r" % (inside[:1],))
T.check("checkpoint" in warns.text(), "abort warning names the checkpoint: %r" % warns.text())
d, _ = at(ai, 20.0)
T.check(d is not None and np.array_equal(d, ref_slow),
        "after an abort inside an interval the next update gives the same bits")
T.check(ai.GetRestoreCount() == 1 and ai.GetRestartCount() == 1,
        "it restored the 10 s checkpoint (restores %d, restarts %d)"
        % (ai.GetRestoreCount(), ai.GetRestartCount()))

# ---- FlowModel: the two models, and the shallow-water model's inputs ------------
sw, _ = at(rain(slope + bowl, RainRate=50.0), 30.0)
li, _ = at(rain(slope + bowl, RainRate=50.0, FlowModel=1), 30.0)
T.check(sw is not None and li is not None and not np.array_equal(sw, li)
        and abs(float(sw.sum()) - float(li.sum())) < 0.05 * float(sw.sum()),
        "the two models differ, with much the same water (%g, %g)"
        % (float(sw.sum()), float(li.sum())))
g = rain(bowl, FlowModel=1, ManningN=0.0)
errs = T.ErrorCatcher(g)
d, _ = at(g, 10.0)
T.check(d is None and "ManningN" in errs.text() and "FlowModel" in errs.text(),
        "frictionless local inertial refused with a sentence: %r" % errs.text()[:200])
d, _ = at(rain(bowl, ManningN=0.0), 10.0)
T.check(d is not None and float(d.min()) >= 0.0, "frictionless shallow water runs")


def started(arrays, **kw):
    g = vtkRainRunoffFilter()
    g.SetInputConnection(producer(image(arrays)).GetOutputPort())
    g.SetEndTime(20.0)
    g.SetRainRate(kw.pop("RainRate", 10.0))  # as rain(): 10 mm/h unless said
    for k, v in kw.items():
        getattr(g, "Set" + k)(v)
    return g


surface = np.full((NY, NX), 1.0)
depth = np.maximum(0.0, surface.astype(np.float32) - bowl.astype(np.float32))
by_depth, _ = at(started({"elevation": bowl, "water_depth": depth}), 20.0)
by_surface, _ = at(started({"elevation": bowl, "water_surface": surface}), 20.0)
T.check(by_depth is not None and np.array_equal(by_depth, by_surface),
        "water_surface sets the depth max(0, surface - elevation), bit for bit")
vel = np.zeros((NY * NX, 3))
vel[:, 0] = 0.5
moving = started({"elevation": bowl, "water_depth": depth}, RainRate=0.0)
arr = numpy_to_vtk(vel.astype(np.float32), deep=1)
arr.SetName("velocity")
moving.GetInputConnection(0, 0).GetProducer().GetOutputDataObject(0).GetPointData().AddArray(arr)
m0, out0 = at(moving, 0.0)
v0 = vtk_to_numpy(out0.GetPointData().GetArray("velocity")).reshape(NY, NX, 3)
wet = depth > 1e-3
T.check(np.allclose(v0[wet, 0], 0.5, atol=1e-5) and np.all(v0[..., 1] == 0.0),
        "the velocity array sets the initial velocity (x 0.5 m/s)")
m20, _ = at(moving, 20.0)
still, _ = at(started({"elevation": bowl, "water_depth": depth}, RainRate=0.0), 20.0)
T.check(m20 is not None and not np.array_equal(m20, still), "moving water moves")

# ---- flood maps and the hydrograph: the same whatever the request order ----------
MAPS = ("max_depth", "max_speed", "arrival_time", "wet_duration", "hazard_rating", "hazard_class")


def maps_of(out):
    nx, ny, _ = out.GetDimensions()
    return {m: vtk_to_numpy(out.GetPointData().GetArray(m)).reshape(ny, nx).copy() for m in MAPS}


def hydrograph(f):
    t = f.GetOutputDataObject(1)
    return {t.GetColumnName(k): vtk_to_numpy(t.GetColumn(k)).copy()
            for k in range(t.GetNumberOfColumns())}


TIMES = (0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0)
fm = rain(slope + bowl, RainRate=80.0, CheckpointInterval=2, DebrisFactor=0.5)
fwd_maps, fwd_depth, fwd_hydro, fwd_out = {}, {}, {}, {}
for t in TIMES:
    d, out = at(fm, t)
    fwd_depth[t], fwd_maps[t], fwd_hydro[t] = d, maps_of(out), hydrograph(fm)
    fwd_out[t] = field(out, "outflow_volume")
T.check(all(np.all(fwd_maps[t]["max_depth"] >= fwd_depth[t]) for t in TIMES),
        "max_depth >= the depth at every output time")
T.check(all(np.all(fwd_maps[b]["max_depth"] >= fwd_maps[a]["max_depth"])
            for a, b in zip(TIMES, TIMES[1:])), "max_depth never falls")
m60 = fwd_maps[60.0]
wet60 = ~np.isnan(m60["arrival_time"])
T.check(wet60.any() and (~wet60).any() and np.all(m60["arrival_time"][wet60] <= 60.0)
        and np.all(m60["wet_duration"][~wet60] == 0.0),
        "arrival_time: NaN where never wet (%d of %d points wet at 60 s)" % (wet60.sum(), wet60.size))
T.check(np.all(m60["wet_duration"] <= 60.0 + 1.0) and float(m60["wet_duration"].max()) > 0.0,
        "wet_duration within the run: up to %g s" % float(m60["wet_duration"].max()))
cls = np.select([m60["hazard_rating"] > 2.0, m60["hazard_rating"] >= 1.25,
                 m60["hazard_rating"] >= 0.75], [3, 2, 1], 0)
T.check(np.array_equal(cls, m60["hazard_class"]), "hazard_class is FD2321's class of hazard_rating")
T.check(np.all(m60["hazard_rating"] >= m60["max_depth"] * 0.5 - 1e-6),
        "hazard_rating >= h 0.5 at the deepest (v >= 0)")
T.check(len(fwd_hydro[60.0]["time"]) == 7 and len(fwd_hydro[20.0]["time"]) == 3
        and list(fwd_hydro[60.0]["time"]) == list(TIMES), "one hydrograph row per output time so far")
mm = rain(slope + bowl, RainRate=80.0, CheckpointInterval=2, DebrisFactor=0.5)
order = (60.0, 20.0, 50.0, 0.0, 30.0, 10.0, 40.0, 40.0)
same_maps, same_rows = True, True
for t in order:
    d, out = at(mm, t)
    got, rows = maps_of(out), hydrograph(mm)
    same_maps = same_maps and all(np.array_equal(got[m], fwd_maps[t][m], equal_nan=True)
                                  for m in MAPS)
    same_rows = same_rows and rows.keys() == fwd_hydro[t].keys() and all(
        np.array_equal(rows[c], fwd_hydro[t][c], equal_nan=True) for c in rows)
T.check(same_maps, "the six maps equal the forward run's bit for bit for requests %r" % (order,))
T.check(same_rows, "the hydrograph equals the forward run's bit for bit for requests %r" % (order,))
T.check(mm.GetRestoreCount() > 0, "going back restored checkpoints (%d)" % mm.GetRestoreCount())

# The hydrograph: outflow_rate is each interval's mean, so it integrates to
# the ledger's outflow_volume; the rain likewise.
h = fwd_hydro[60.0]
dt_rows = np.diff(h["time"])
out_int = float(np.sum(h["outflow_rate"][1:] * dt_rows))
T.check(fwd_out[60.0] > 0.0 and abs(out_int - fwd_out[60.0]) <= 1e-6 * fwd_out[60.0],
        "outflow_rate integrates to outflow_volume: %.9g vs %.9g m^3" % (out_int, fwd_out[60.0]))
rain_int = float(np.sum(h["rain_volume_rate"][1:] * dt_rows))
rain_q = 80.0 * MM_PER_H * NX * NY * DX * DX
T.check(abs(rain_int - rain_q * 60.0) <= 1e-6 * rain_q * 60.0 and
        np.allclose(h["rain_volume_rate"][1:], rain_q, rtol=1e-6),
        "rain_volume_rate %g m^3/s = rate x area, integrating to the rain (%g m^3)" % (h["rain_volume_rate"][1], rain_int))
T.check(all(np.isnan(h[c][0]) for c in ("rain_volume_rate", "inflow_rate", "infiltration_rate",
                                          "outflow_rate")) and np.all(h["inflow_rate"][1:] == 0.0),
        "row 0 ends no interval: its rates are NaN; no inflow through open edges")
T.check(np.all(np.abs(h["balance_error"]) <= 1e-5 * rain_q * 60.0)
        and np.all(np.diff(h["outflow_volume"]) >= 0.0), "balance_error small, outflow_volume grows")
T.check(abs(h["stored_volume"][-1] - (rain_int - fwd_out[60.0] - h["balance_error"][-1]))
        <= 1e-6 * rain_int, "stored = rain - outflow - balance error")
# Asking the hydrograph's port for a time runs the simulation to it.
hp = rain(slope + bowl, RainRate=80.0, DebrisFactor=0.5)
hp.UpdateInformation()
hp.GetOutputInformation(1).Set(SDDP.UPDATE_TIME_STEP(), 40.0)
hp.Update(1)
rows = hydrograph(hp)
T.check(len(rows.get("time", [])) == 5 and np.array_equal(
    rows["outflow_rate"], fwd_hydro[40.0]["outflow_rate"], equal_nan=True),
        "the Hydrograph port at 40 s: 5 rows, those of the forward run")
tab = hp.GetOutputDataObject(1)
T.check(tab.GetInformation().Get(tab.DATA_TIME_STEP()) == 40.0,
        "the table carries its time")
# The local inertial model keeps maps too, and in any order.
li1 = rain(slope + bowl, RainRate=80.0, FlowModel=1)
li2 = rain(slope + bowl, RainRate=80.0, FlowModel=1)
a40 = maps_of(at(li1, 40.0)[1])
at(li2, 60.0)
b40 = maps_of(at(li2, 40.0)[1])
T.check(all(np.array_equal(a40[m], b40[m], equal_nan=True) for m in MAPS)
        and float(a40["max_depth"].max()) > 0.0, "local inertial: the maps at 40 s, forward = backward")

# WettingDepth and DebrisFactor: the defaults, a clamp, a sentence.
g = vtkRainRunoffFilter()
T.check(g.GetWettingDepth() == 0.01 and g.GetDebrisFactor() == 0.0,
        "defaults WettingDepth 0.01 m, DebrisFactor 0")
g.SetDebrisFactor(-1.0)
T.check(g.GetDebrisFactor() == 0.0, "DebrisFactor -1 clamps to 0")
for props, text in (({"WettingDepth": 0.0}, "WettingDepth must be above 0 m and up to 10 m; it is 0 m"),
                    ({"WettingDepth": -0.5}, "WettingDepth must be above 0 m"),
                    ({"DebrisFactor": float("nan")}, "DebrisFactor must be from 0 to 1")):
    g = rain(bowl, **props)
    errs = T.ErrorCatcher(g)
    d, out = at(g, 10.0)
    T.check(d is None and len(errs.messages) == 1 and text in errs.text()
            and hydrograph(g) == {}, "%r refused with one sentence, empty outputs: %r"
            % (props, errs.text()[:200]))

# Boundaries per edge: the defaults, the clamps, SetBoundary for all four, a
# level edge's inflow in the ledger and the hydrograph, a bad level refused.
g = vtkRainRunoffFilter()
T.check([g.GetBoundaryWest(), g.GetBoundaryEast(), g.GetBoundarySouth(), g.GetBoundaryNorth()]
        == [0, 0, 0, 0] and [g.GetLevelWest(), g.GetLevelEast(), g.GetLevelSouth(),
                             g.GetLevelNorth()] == [0.0] * 4, "defaults: every edge open, levels 0 m")
g.SetBoundary(1)
T.check([g.GetBoundaryWest(), g.GetBoundaryEast(), g.GetBoundarySouth(), g.GetBoundaryNorth()]
        == [1] * 4 and g.GetBoundary() == 1, "SetBoundary(1) makes all four edges walls")
g.SetBoundaryWest(7)
g.SetLevelWest(-5e6)
T.check(g.GetBoundaryWest() == 3 and g.GetBoundary() == -1 and g.GetLevelWest() == -1e6,
        "BoundaryWest 7 clamps to 3 (Level), LevelWest -5e6 to -1e6 m; GetBoundary -1 when "
        "the edges differ")
lv = rain(np.zeros((NY, NX)), RainRate=0.0, Boundary=1, BoundaryWest=3, LevelWest=0.3,
          EndTime=60.0, OutputInterval=20.0)
d, out = at(lv, 60.0)
h = hydrograph(lv)
inflow = field(out, "inflow_volume") if d is not None else 0.0
in_int = float(np.sum(h["inflow_rate"][1:] * np.diff(h["time"]))) if h else 0.0
T.check(d is not None and inflow > 0.0 and abs(field(out, "stored_volume") - (
    inflow - field(out, "outflow_volume"))) <= 1e-6 * inflow and d[:, 0].min() > 0.1
    and d[:, -1].max() < d[:, 0].min(),
    "a level edge (0.3 m, west) fills a flat, walled terrain from the west: inflow %g m^3 = "
    "stored + outflow" % inflow)
T.check(abs(in_int - inflow) <= 1e-6 * inflow,
        "inflow_rate integrates to inflow_volume: %.9g vs %.9g m^3" % (in_int, inflow))
for props, text in (({"BoundaryWest": 3, "LevelWest": float("nan")},
                     "LevelWest must be from -1e+06 m to 1e+06 m; it is nan m"),):
    g = rain(bowl, **props)
    errs = T.ErrorCatcher(g)
    d, out = at(g, 10.0)
    T.check(d is None and len(errs.messages) == 1 and text in errs.text()
            and hydrograph(g) == {}, "%r refused with one sentence, empty outputs: %r"
            % (props, errs.text()[:200]))

# Inflows: a hydrograph along the west edge and point inflows, on a flat,
# walled terrain: the ledger's inflow is the table's integral plus Q t, and
# all of it is stored; bad tables and points are refused with a sentence.
def inflow_points(xy, q, name="discharge"):
    pts = vtkPoints()
    for px, py in xy:
        pts.InsertNextPoint(px, py, 0.0)
    poly = vtkPolyData()
    poly.SetPoints(pts)
    if name:
        arr = numpy_to_vtk(np.asarray(q, dtype=np.float64), deep=1)
        arr.SetName(name)
        poly.GetPointData().AddArray(arr)
    return poly


fl = rain(np.zeros((NY, NX)), RainRate=0.0, Boundary=1, EndTime=60.0, OutputInterval=20.0)
for t_q in ((0.0, 0.0), (30.0, 1.0), (45.0, 1.0)):
    fl.AddInflowWest(*t_q)
fl.SetInflowsConnection(producer(inflow_points(
    [(100.0 + 10 * DX, -50.0 + 5 * DX), (100.0 + 10 * DX + 0.3, -50.0 + 5 * DX),
     (100.0 + 30 * DX, -50.0 + 20 * DX)], [0.1, 0.05, 0.2])).GetOutputPort())
d, out = at(fl, 60.0)
expect = 0.5 * 30.0 * 1.0 + 30.0 * 1.0 + 0.35 * 60.0  # the table's integral, held after 45 s
T.check(fl.GetNumberOfInflowRows(0) == 3 and d is not None
        and abs(field(out, "inflow_volume") - expect) <= 1e-6 * expect
        and abs(field(out, "stored_volume") - expect) <= 1e-6 * expect
        and field(out, "outflow_volume") == 0.0,
        "hydrograph and point inflows: inflow %.7f m^3, stored %.7f m^3 (expected %g)"
        % (field(out, "inflow_volume") if d is not None else -1,
           field(out, "stored_volume") if d is not None else -1, expect))
bad_tables = (
    ("InflowWest", ((0.0, 1.0), (10.0, 2.0), (10.0, 3.0)), "InflowWest: The west edge's inflow "
     "hydrograph's times must increase from row to row, but row 2 has 10 s after 10 s"),
    ("InflowNorth", ((0.0, 1.0), (10.0, -2.0)), "InflowNorth: The north edge's inflow hydrograph "
     "has the discharge -2 m^3/s in row 1"),
)
for prop, rows, text in bad_tables:
    g = rain(bowl)
    for row in rows:
        getattr(g, "Add" + prop)(*row)
    errs = T.ErrorCatcher(g)
    d, out = at(g, 10.0)
    T.check(d is None and len(errs.messages) == 1 and text in errs.text() and hydrograph(g) == {},
            "%s %r refused with one sentence, empty outputs: %r" % (prop, rows, errs.text()[:240]))
    getattr(g, "RemoveAll" + prop)()
    d, out = at(g, 10.0)
    T.check(d is not None, "%s cleared: the filter works again" % prop)
for xy, q, name, text in (
        ([(100.0, -50.0)], [-1.0], "discharge", "Inflows: Point inflow 0 has the discharge -1 m^3/s"),
        ([(100.0, -50.0)], [float("nan")], "discharge", "Inflows: Point inflow 0 has the discharge nan"),
        ([(100.0, -50.0)], [1.0], "flow", "Inflows need the point array 'discharge'"),
        ([(0.0, 0.0)], [1.0], "discharge", "Inflows point 0 at (0, 0) lies off the terrain")):
    g = rain(bowl)
    g.SetInflowsConnection(producer(inflow_points(xy, q, name)).GetOutputPort())
    errs = T.ErrorCatcher(g)
    d, out = at(g, 10.0)
    T.check(d is None and len(errs.messages) == 1 and text in errs.text(),
            "bad point inflows refused with one sentence: %r" % errs.text()[:200])

# Inflows with time steps (a river gauged every 20 s): each step's points and
# discharges hold until the next, so the inflow is sum Q_k (t_k+1 - t_k) (the
# point also walks east each step). Going back in time and
# forward again gives the same bits (the inflows are set again from the input
# after a restart), and every time step is read.
from gr_timed import TimedSource  # noqa: E402


class River(TimedSource):
    TIMES = [0.0, 20.0, 40.0]
    FLOW = [0.2, 0.5, 0.0]  # m^3/s from each time step on

    def __init__(self):
        TimedSource.__init__(self, "vtkPolyData")

    def RequestData(self, request, inInfo, outInfo):
        t = self.requested_time(outInfo)
        k = max(i for i, tk in enumerate(self.TIMES) if tk <= t + 1e-9)
        # the point walks east by 5 cells per time step
        out = vtkPolyData.GetData(outInfo)
        out.ShallowCopy(inflow_points([(100.0 + (8 + 5 * k) * DX, -50.0 + 16 * DX)],
                                      [self.FLOW[k]]))
        out.GetInformation().Set(out.DATA_TIME_STEP(), self.TIMES[k])
        return 1


river = River()
tr = rain(np.zeros((NY, NX)), RainRate=0.0, Boundary=1, EndTime=60.0, OutputInterval=10.0)
tr.SetInflowsConnection(river.GetOutputPort())
d60, out = at(tr, 60.0)
expect = 0.2 * 20.0 + 0.5 * 20.0 + 0.0 * 20.0
T.check(d60 is not None and tr.IsInputTemporal(3)
        and abs(field(out, "inflow_volume") - expect) <= 1e-6 * expect
        and abs(field(out, "stored_volume") - expect) <= 1e-6 * expect,
        "temporal inflows: inflow %.7f m^3, stored %.7f m^3 (expected %g: 0.2 m^3/s for 20 s, "
        "0.5 for 20 s, then none)" % (field(out, "inflow_volume") if d60 is not None else -1,
                                      field(out, "stored_volume") if d60 is not None else -1,
                                      expect))
T.check(sorted(set(river.requested)) == [0.0, 20.0, 40.0],
        "each inflow time step read: %r" % sorted(set(river.requested)))
h30 = hydrograph(tr)
rate = dict(zip(h30["time"], h30["inflow_rate"])) if h30 else {}
T.check(abs(rate.get(10.0, -1) - 0.2) <= 1e-6 and abs(rate.get(30.0, -1) - 0.5) <= 1e-6
        and abs(rate.get(50.0, -1)) <= 1e-12,
        "the hydrograph's inflow_rate follows the input: %r" % sorted(rate.items()))
d10, _ = at(tr, 10.0)   # back (a checkpoint or time 0), then forward again
d60b, outb = at(tr, 60.0)
T.check(d10 is not None and d60b is not None and np.array_equal(d60, d60b)
        and field(outb, "inflow_volume") == field(out, "inflow_volume"),
        "back to 10 s and forward to 60 s again: the same bits")

# The hyetograph rains its table's integral; a manning_n array of ManningN
# everywhere (in double) is the uniform run bit for bit; bad ones are refused.
hy = rain(np.zeros((NY, NX)), RainRate=5.0, Boundary=1, EndTime=60.0, OutputInterval=20.0)
for row in ((0.0, 0.0), (30.0, 72.0), (50.0, 0.0)):
    hy.AddHyetograph(*row)
d, out = at(hy, 60.0)
area = NX * NY * DX * DX
expect = 0.5 * 50.0 * 72.0 * MM_PER_H * area
h = hydrograph(hy)
T.check(hy.GetNumberOfHyetographRows() == 3 and d is not None
        and abs(field(out, "rain_volume") - expect) <= 1e-6 * expect
        and abs(float(np.sum(h["rain_volume_rate"][1:] * np.diff(h["time"]))) - expect) <= 1e-6 * expect
        and np.allclose(d, expect / area, rtol=1e-5),
        "the hyetograph rains its integral: %.9g m^3 (expected %.9g), every point %.6g m deep"
        % (field(out, "rain_volume") if d is not None else -1, expect, expect / area))
g = rain(bowl)
for row in ((0.0, 10.0), (20.0, 5.0), (20.0, 1.0)):
    g.AddHyetograph(*row)
errs = T.ErrorCatcher(g)
d, out = at(g, 10.0)
T.check(d is None and len(errs.messages) == 1 and "Rain Runoff's Hyetograph: The hyetograph's "
        "times must increase from row to row, but row 2 has 20 s after 20 s" in errs.text(),
        "a hyetograph with a repeated time refused with one sentence: %r" % errs.text()[:200])


def with_manning(terrain, n):
    img = image({"elevation": terrain})
    arr = numpy_to_vtk(np.ascontiguousarray(n, dtype=np.float64).reshape(-1), deep=1)
    arr.SetName("manning_n")
    img.GetPointData().AddArray(arr)
    return img


runs = []
for n in (None, np.full((NY, NX), 0.03)):
    g = vtkRainRunoffFilter()
    src = image({"elevation": slope + bowl}) if n is None else with_manning(slope + bowl, n)
    g.SetInputConnection(producer(src).GetOutputPort())
    g.SetRainRate(80.0)
    g.SetEndTime(30.0)
    runs.append(at(g, 30.0)[0])
T.check(runs[0] is not None and runs[1] is not None and np.array_equal(runs[0], runs[1])
        and runs[0].max() > 0.0, "a manning_n array of ManningN (0.03) everywhere: the same depths "
        "bit for bit")
g = vtkRainRunoffFilter()
g.SetInputConnection(producer(image({"elevation": bowl})).GetOutputPort())
g.SetPermeabilityMapConnection(producer(with_manning(bowl, np.full((NY, NX), 2.0))).GetOutputPort())
errs = T.ErrorCatcher(g)
d, out = at(g, 10.0)
T.check(d is None and len(errs.messages) == 1 and "Rain Runoff's PermeabilityMap: The Manning map "
        "has the value 2 s/m^(1/3) at cell (0, 0)" in errs.text(),
        "a manning_n of 2 on the PermeabilityMap refused with one sentence: %r" % errs.text()[:200])

# No-data points: a NaN hole and a NaN border are outside the terrain, walls
# by default (nothing leaves), outfalls with NoDataBoundary 0; their outputs
# are NaN, the ledger closes, the rain falls on the terrain's points only.
nd = slope + bowl
nd = nd.copy()
nd[:2, :] = nd[-2:, :] = np.nan
nd[:, :2] = nd[:, -2:] = np.nan
nd[12:15, 18:23] = np.nan
holes = np.isnan(nd)
for kind in (1, 0):
    g = rain(nd, RainRate=80.0, EndTime=60.0, NoDataBoundary=kind)
    d, out = at(g, 60.0)
    ok = d is not None
    rain_q = 80.0 * MM_PER_H * float((~holes).sum()) * DX * DX * 60.0
    if ok:
        m = maps_of(out)
        nan_right = (np.array_equal(np.isnan(d), holes)
                     and np.array_equal(np.isnan(m["max_depth"]), holes))
        closes = abs(field(out, "balance_error")) <= 1e-6 * rain_q
        rain_ok = abs(field(out, "rain_volume") - rain_q) <= 1e-6 * rain_q
        outflow = field(out, "outflow_volume")
    T.check(ok and nan_right and closes and rain_ok
            and (outflow == 0.0 if kind == 1 else outflow > 0.0),
            "no-data points as %s: NaN exactly there, the rain on the other points (%g m^3), "
            "outflow %g m^3, the ledger closed" % ("walls" if kind == 1 else "outfalls", rain_q,
                                                  outflow if ok else -1))

# Gauges: three columns each in the hydrograph, the output's values at the
# nearest terrain point at every output time, whatever the request order.
def gauge_points(xy):
    pts = vtkPoints()
    for gx, gy in xy:
        pts.InsertNextPoint(gx, gy, 0.0)
    poly = vtkPolyData()
    poly.SetPoints(pts)
    return poly


GAUGE_IJ = ((3, 4), (20, 16), (37, 29))
# Off the lattice by less than half a spacing: each snaps to its point.
gxy = [(100.0 + gi * DX + 0.4, -50.0 + gj * DX - 0.3) for gi, gj in GAUGE_IJ]


def gauged(**kw):
    f = rain(slope + bowl, RainRate=80.0, CheckpointInterval=2, DebrisFactor=0.5, **kw)
    f.SetGaugesConnection(producer(gauge_points(gxy)).GetOutputPort())
    return f


ga = gauged()
want = {}
for t in TIMES:
    d, out = at(ga, t)
    z = vtk_to_numpy(out.GetPointData().GetArray("water_surface")).reshape(NY, NX)
    q = vtk_to_numpy(out.GetPointData().GetArray("discharge")).reshape(NY, NX)
    want[t] = [(d[gj, gi], z[gj, gi], q[gj, gi]) for gi, gj in GAUGE_IJ]
rows = hydrograph(ga)
ok = len(rows.get("gauge2_discharge", [])) == len(TIMES)
for k, t in enumerate(TIMES):
    for n_, (gi, gj) in enumerate(GAUGE_IJ):
        got = tuple(rows["gauge%d_%s" % (n_, w)][k] for w in ("depth", "surface", "discharge"))
        ok = ok and got == tuple(np.float32(v) for v in want[t][n_])
T.check(ok, "gauge columns: the depth, surface and discharge of the output at each gauge, "
        "every output time, to the bit")
T.check(max(rows["gauge1_depth"]) > 0.0 and max(rows["gauge1_discharge"]) > 0.0,
        "the middle gauge sees water and flow")
T.check(np.array_equal(rows["outflow_rate"], fwd_hydro[60.0]["outflow_rate"], equal_nan=True),
        "gauges change no other column")
gb = gauged()
for t in (40.0, 10.0, 60.0):
    at(gb, t)
rows_b = hydrograph(gb)
T.check(rows_b.keys() == rows.keys() and all(np.array_equal(rows_b[c], rows[c], equal_nan=True)
                                             for c in rows),
        "gauge columns the same after requests 40, 10, 60 s")
off = rain(bowl)
off.SetGaugesConnection(producer(gauge_points([(0.0, 0.0)])).GetOutputPort())
errs = T.ErrorCatcher(off)
d, _ = at(off, 10.0)
T.check(d is None and len(errs.messages) == 1 and "Gauges point 0" in errs.text()
        and "off the terrain" in errs.text(), "a gauge off the terrain refused: %r"
        % errs.text()[:200])

# ---- bad input: one sentence, an empty output, the next good update works ------
bad_elev = bowl.copy()
bad_elev[3, 7] = np.inf  # NaN is a no-data point; infinities are refused
cases = [
    ({"elevation": bad_elev}, {}, "elevation"),
    # no elevation, no active scalars, and two arrays: nothing to take as heights
    ({"height": bowl, "roughness": bowl}, {}, "elevation"),
    ({"elevation": bowl, "water_depth": -np.ones((NY, NX))}, {}, "water_depth"),
    ({"elevation": bowl}, {"RainRate": float("nan")}, "RainRate"),
    ({"elevation": bowl}, {"ManningN": float("nan")}, "ManningN"),
    ({"elevation": bowl}, {"CourantNumber": 0.0}, "CourantNumber"),
    ({"elevation": bowl}, {"OutputInterval": 0.0}, "OutputInterval"),
    ({"elevation": bowl}, {"EndTime": float("nan")}, "EndTime"),
]
for arrays, props, word in cases:
    g = vtkRainRunoffFilter()
    src = image(arrays)
    src.GetPointData().SetActiveScalars(None)
    g.SetInputConnection(producer(src).GetOutputPort())
    for kname, v in props.items():
        getattr(g, "Set" + kname)(v)
    errs = T.ErrorCatcher(g)
    g.UpdateInformation()
    g.Update()
    out = g.GetOutput()
    T.check(out.GetNumberOfPoints() == 0 and word in errs.text(),
            "%s refused with a sentence naming it and an empty output: %r"
            % (word, errs.text()[:160]))
flat3d = vtkImageData()
flat3d.SetDimensions(NX, NY, 2)
arr = numpy_to_vtk(np.zeros(NX * NY * 2, np.float32), deep=1)
arr.SetName("elevation")
flat3d.GetPointData().AddArray(arr)
g = vtkRainRunoffFilter()
g.SetInputConnection(producer(flat3d).GetOutputPort())
errs = T.ErrorCatcher(g)
g.Update()
T.check(g.GetOutput().GetNumberOfPoints() == 0 and "2-D" in errs.text(),
        "a 3-D input refused: %r" % errs.text()[:160])
g = vtkRainRunoffFilter()
g.SetInputConnection(producer(image({"elevation": bowl}, spacing=0.0)).GetOutputPort())
errs = T.ErrorCatcher(g)
g.Update()
T.check(g.GetOutput().GetNumberOfPoints() == 0 and len(errs.messages) == 1
        and "spacing above 0 m" in errs.text(), "a zero spacing refused: %r" % errs.text()[:160])

# Setters clamp to the core's parameter table; an error speaks the user's unit.
g = vtkRainRunoffFilter()
g.SetRainRate(-1.0)
T.check(g.GetRainRate() == 0.0, "RainRate -1 clamps to 0 mm/h: %r" % g.GetRainRate())
g.SetRainRate(1e9)
T.check(0.0 < g.GetRainRate() < 1e9, "RainRate 1e9 clamps to the table's maximum: %r"
        % g.GetRainRate())
g.SetManningN(-1.0)
T.check(g.GetManningN() == 0.0, "ManningN -1 clamps to the table's minimum 0: %r"
        % g.GetManningN())
g.SetFlowModel(5)
T.check(g.GetFlowModel() == 1, "FlowModel 5 clamps to 1: %r" % g.GetFlowModel())
g = rain(bowl, RainRate=float("nan"))
errs = T.ErrorCatcher(g)
at(g, 10.0)
T.check("mm/h" in errs.text() and "m/s" not in errs.text(),
        "a RainRate error speaks mm/h: %r" % errs.text()[:200])

# No `elevation` array: the active scalars are the heights (the Height Array's
# default rule), the same water as under the name elevation.
src = image({"height": bowl, "roughness": 0.0 * bowl})
src.GetPointData().SetActiveScalars("height")
g = vtkRainRunoffFilter()
g.SetInputConnection(producer(src).GetOutputPort())
g.SetEndTime(60.0)
g.SetOutputInterval(10.0)
g.SetRainRate(10.0)
errs = T.ErrorCatcher(g)
d_active, _ = at(g, 20.0)
d_named, _ = at(rain(bowl), 20.0)
T.check(not errs.messages and d_active is not None and np.array_equal(d_active, d_named),
        "the active scalars 'height' as the heights: the same depths (%s)" % errs.messages)
# Choosing the heights it already reads (as ParaView does once the Input's
# arrays are known) keeps the state; choosing other heights sets it up again.
before = g.GetRestartCount()
g.SetInputArrayToProcess(0, 0, 0, 0, "elevation")
at(g, 30.0)
g.SetInputArrayToProcess(0, 0, 0, 0, "")
at(g, 40.0)
T.check(g.GetRestartCount() == before, "the default Height Array set again: no new set-up "
        "(%d, %d)" % (before, g.GetRestartCount()))
g.SetInputArrayToProcess(0, 0, 0, 0, "roughness")
at(g, 40.0)
T.check(g.GetRestartCount() == before + 1, "another Height Array: set up again (%d)"
        % g.GetRestartCount())
# Nothing to take (two arrays, no elevation, no active scalars): refused, one
# sentence only, however often and for whatever time the output is asked for.
src = image({"height": bowl, "roughness": 0.0 * bowl})
src.GetPointData().SetActiveScalars(None)
g = vtkRainRunoffFilter()
g.SetInputConnection(producer(src).GetOutputPort())
errs = T.ErrorCatcher(g)
for t in (10.0, 10.0, 20.0, 0.0):
    d, _ = at(g, t)
T.check(d is None and len(errs.messages) == 1 and "'elevation'" in errs.text()
        and "Height Array" in errs.text(),
        "missing elevation refused once with a sentence naming it: %d %r"
        % (len(errs.messages), errs.text()[:200]))

# The forgotten Spacing: 1 m spacing under heights spanning hundreds of metres.
tall = image({"elevation": 300.0 * i / (NX - 1.0)}, spacing=1.0)
g = vtkRainRunoffFilter()
g.SetInputConnection(producer(tall).GetOutputPort())
g.SetEndTime(20.0)
g.SetRainRate(10.0)
warns = T.ErrorCatcher(g, event="WarningEvent")
at(g, 10.0)
g.SetRainRate(20.0)  # set up again on the same terrain: no second warning
d, _ = at(g, 20.0)
T.check(d is not None and len(warns.messages) == 1 and "Spacing" in warns.text()
        and "300" in warns.text(), "spacing warning once: %d %r"
        % (len(warns.messages), warns.text()[:200]))
quiet = rain(bowl)
warns = T.ErrorCatcher(quiet, event="WarningEvent")
at(quiet, 10.0)
T.check(len(warns.messages) == 0, "no spacing warning for a 2 m grid")

# A kernel that fails to build (bad GRAUPEL_CL_OPTIONS): one sentence with the
# build log and an empty output; with the options fixed the next update works.
os.environ["GRAUPEL_CL_OPTIONS"] = "-cl-no-such-option"
g = rain(slope + bowl, RainRate=50.0)
errs = T.ErrorCatcher(g)
d, _ = at(g, 10.0)
T.check(d is None and "rain_runoff" in errs.text() and "failed to build" in errs.text(),
        "a failed kernel build is reported: %r" % errs.text()[:200])
del os.environ["GRAUPEL_CL_OPTIONS"]
g.Modified()
d, _ = at(g, 10.0)
T.check(d is not None and np.array_equal(d, ref[10.0]), "works again once the options are fixed")

# After a failure the same filter works once the input is fixed.
g = rain(bad_elev)
errs = T.ErrorCatcher(g)
d, _ = at(g, 10.0)
T.check(d is None and "elevation" in errs.text(), "an infinite elevation refused")
g.SetInputConnection(producer(image({"elevation": slope + bowl})).GetOutputPort())
g.SetRainRate(50.0)
d, _ = at(g, 10.0)
T.check(d is not None and np.array_equal(d, ref[10.0]), "works again with a good terrain")

T.finish()
