"""vtkSnowMeltFilter in a pipeline (pvbatch in the plugin build, plain python3 on
Debian's VTK): a flat snowpack melting at a constant temperature with the sun off
(SWE = initial - MF (T - T0) t at every output), the water ledger (balance 0,
released_volume the sum of the intervals' released volumes, the mean water_release
times interval and area the interval's volume, rain_rate = water_release / 3.6e6),
the Forcing table (sample and hold inside an output interval; a table of three rows
equals constant runs split by hand through RestartFile, bit for bit), determinism and
out-of-order requests, the sun (a south-facing slope melts more than a north-facing
one), bad input (no snow, times that do not increase, NaN AirTemperature: one
sentence and an empty output; Latitude 95 clamped to 90 with a warning), and under
pvbatch the proxy."""
import glob
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args()

from vtkmodules.util.numpy_support import vtk_to_numpy, numpy_to_vtk  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData  # noqa: E402
from vtkmodules.vtkCommonExecutionModel import (  # noqa: E402
    vtkStreamingDemandDrivenPipeline as SDDP,
    vtkTrivialProducer,
)

from graupel import vtkSnowMeltFilter  # noqa: E402

NX, NY, DX = 20, 16, 10.0
HOUR, DAY = 3600.0, 86400.0
_keep = []  # a vtkAlgorithmOutput does not keep its producer alive
ARRAYS = ["snow_depth", "snow_density", "swe", "liquid_water", "melt_rate", "water_release",
          "radiation", "elevation", "rain_rate"]
LEDGER = ["time", "steps", "snowfall_in", "snowfall_volume", "rain_volume", "melt_volume",
          "refrozen_volume", "released_volume", "released_interval_volume", "stored_swe_volume",
          "stored_liquid_volume", "balance_error"]


def image(arrays, dims=(NX, NY), spacing=DX):
    img = vtkImageData()
    img.SetDimensions(dims[0], dims[1], 1)
    img.SetSpacing(spacing, spacing, 1.0)
    for name, values in arrays.items():
        arr = numpy_to_vtk(np.ascontiguousarray(values, dtype=np.float32).reshape(-1), deep=1)
        arr.SetName(name)
        img.GetPointData().AddArray(arr)
    return img


def producer(data):
    p = vtkTrivialProducer()
    p.SetOutput(data)
    _keep.append(p)
    return p.GetOutputPort()


flat = np.zeros((NY, NX))
SNOW = {"elevation": flat, "snow_depth": np.full((NY, NX), 1.0),
        "snow_density": np.full((NY, NX), 300.0)}
SWE0 = 0.3  # m w.e.


def melt(arrays=SNOW, forcing=None, **kw):
    f = vtkSnowMeltFilter()
    f.SetInputConnection(producer(image(arrays)))
    if forcing is not None:
        f.SetInputConnection(1, producer(T.table(forcing)))
    f.SetEndTime(kw.pop("EndTime", 2 * DAY))
    f.SetOutputInterval(kw.pop("OutputInterval", 6 * HOUR))
    for k, v in kw.items():
        getattr(f, "Set" + k)(v)
    return f


def at(f, t):
    f.UpdateTimeStep(t)
    out = f.GetOutput()
    if out.GetNumberOfPoints() == 0:
        return None, out
    return {n: vtk_to_numpy(out.GetPointData().GetArray(n)).copy() for n in ARRAYS}, out


def field(out, name):
    return out.GetFieldData().GetArray(name).GetValue(0)


def ledger(out):
    return [field(out, n) for n in LEDGER]


# ---- defaults and advertised times --------------------------------------------------
f = vtkSnowMeltFilter()
T.check(f.GetEndTime() == 864000.0 and f.GetOutputInterval() == 21600.0,
        "time defaults EndTime 10 days, OutputInterval 6 h")
T.check(f.GetMeltFactor() == 1.8 and f.GetRadiationFactor() == 0.0006 and f.GetLatitude() == 46.0
        and f.GetTimeStep() == 3600.0 and f.GetCastShadows() == 1,
        "the core's table gives the defaults")
T.check(f.GetInitialSnowDepth() == 0.0 and f.GetAirTemperature() == 2.0
        and f.GetPrecipitation() == 0.0, "defaults InitialSnowDepth 0, AirTemperature 2, rain 0")
m = melt()
m.UpdateInformation()
info = m.GetOutputInformation(0)
steps = [info.Get(SDDP.TIME_STEPS(), k) for k in range(info.Length(SDDP.TIME_STEPS()))]
T.check(steps == [k * 6 * HOUR for k in range(9)], "TIME_STEPS every 6 h up to 2 days")

# ---- a flat snowpack, sun off: SWE = SWE0 - MF (T - T0) t -----------------------------
TEMP, MF, T0 = 5.0, 3.0, 0.5
times = [k * 6 * HOUR for k in range(9)]
pack = melt(AirTemperature=TEMP, MeltFactor=MF, ThresholdTemperature=T0, RadiationFactor=0.0,
            LiquidWaterCapacity=0.0, LapseRate=0.0)
worst, outs = 0.0, {}
for t in times:
    v, out = at(pack, t)
    outs[t] = (v, ledger(out))
    want = SWE0 - MF * 1e-3 * (TEMP - T0) * t / DAY
    worst = max(worst, float(np.abs(v["swe"].astype(np.float64) - want).max()))
T.check(worst < 1e-6, "SWE = initial - MF (T - T0) t at every output: worst %.3g m" % worst)
print("flat pack: SWE worst error %.3g m over %d outputs" % (worst, len(times)))
v, led = outs[times[-1]]
T.check(np.array_equal(v["rain_rate"], (v["water_release"].astype(np.float64) / 3.6e6)
                       .astype(np.float32)), "rain_rate = water_release / 3.6e6 m/s")
rate = MF * (TEMP - T0) / 24.0
T.check(abs(float(v["water_release"].mean()) - rate) < 1e-5 * rate,
        "water_release %.6f mm/h = MF (T - T0) / 24 = %.6f" % (v["water_release"].mean(), rate))

# ---- the ledger, with liquid water held (capacity 0.1) -------------------------------
wet = melt(AirTemperature=TEMP, MeltFactor=MF, RadiationFactor=0.0, Precipitation=0.5,
           RainSnowThreshold=1.0, LapseRate=0.0)
AREA = DX * DX
balance, rel_sum, worst_mean, worst_bal = 0.0, 0.0, 0.0, 0.0
for k, t in enumerate(times):
    v, out = at(wet, t)
    L = dict(zip(LEDGER, ledger(out)))
    water_in = L["snowfall_in"] + L["snowfall_volume"] + L["rain_volume"]
    worst_bal = max(worst_bal, abs(L["balance_error"]) / water_in)
    if k > 0:
        rel_sum += L["released_interval_volume"]
        mean_volume = float(v["water_release"].astype(np.float64).sum()) * 6.0 * 1e-3 * AREA
        err = abs(mean_volume - L["released_interval_volume"]) / max(L["released_interval_volume"],
                                                                     1e-30)
        worst_mean = max(worst_mean, err)
        if k == len(times) - 1:
            T.check(L["released_volume"] > 0 and L["stored_liquid_volume"] > 0,
                    "water was released (%g m3) and held (%g m3)"
                    % (L["released_volume"], L["stored_liquid_volume"]))
T.check(worst_bal < 1e-12, "balance_error / water in: %.3g" % worst_bal)
T.check(abs(rel_sum - L["released_volume"]) <= 1e-9 * L["released_volume"],
        "released_volume %.9g = sum of released_interval_volume %.9g" % (L["released_volume"],
                                                                         rel_sum))
T.check(worst_mean < 1e-6, "mean water_release x interval x area = released_interval_volume: "
        "worst relative %.3g" % worst_mean)
print("ledger: balance %.3g of water in; released %.6g m3 vs sum of intervals %.6g m3; mean "
      "release x interval x area within %.3g" % (worst_bal, L["released_volume"], rel_sum,
                                                 worst_mean))

# ---- Forcing: sample and hold inside an interval ------------------------------------
held = melt(forcing={"time": [0.0, 9 * HOUR], "air_temperature": [TEMP, -3.0]},
            AirTemperature=40.0, MeltFactor=MF, ThresholdTemperature=T0, RadiationFactor=0.0,
            LiquidWaterCapacity=0.0, LapseRate=0.0)
v, out = at(held, 12 * HOUR)
want = SWE0 - MF * 1e-3 * (TEMP - T0) * 9.0 / 24.0
err = float(np.abs(v["swe"].astype(np.float64) - want).max())
T.check(err < 1e-6, "a row at 9 h cuts the 6-12 h interval: SWE at 12 h within %.3g m" % err)
T.check(abs(float(v["melt_rate"].mean()) - MF * (TEMP - T0) / 24.0 * 0.5) < 1e-5,
        "melt_rate at 12 h is the interval's mean (%g mm/h)" % v["melt_rate"].mean())

# ---- an edited Forcing table sets the simulation up again -----------------------------
edited = melt(forcing={"time": [0.0], "air_temperature": [TEMP]}, RadiationFactor=0.0,
              ThresholdTemperature=0.0, LapseRate=0.0)
_, out = at(edited, 6 * HOUR)
before = field(out, "melt_volume")
_keep[-1].GetOutputDataObject(0).GetColumnByName("air_temperature").SetValue(0, 2 * TEMP)
_keep[-1].GetOutputDataObject(0).Modified()
_, out = at(edited, 6 * HOUR)
T.check(abs(field(out, "melt_volume") - 2 * before) <= 1e-6 * before,
        "a Forcing edited upstream is read again: melt %g -> %g m3"
        % (before, field(out, "melt_volume")))

# ---- Forcing: three rows equal constant runs split by hand, bit for bit --------------
ROWS = {"time": [0.0, 12 * HOUR, 30 * HOUR], "air_temperature": [4.0, -2.0, 7.0],
        "precipitation": [0.0, 1.5, 0.4]}
hill = 40.0 * np.sin(np.linspace(0, 3, NX))[None, :] + 3.0 * np.arange(NY)[:, None]
HILL = dict(SNOW, elevation=hill)
SUN = dict(Latitude=46.0, StartDayOfYear=120, StartHour=6.0)
by_table = melt(HILL, forcing=ROWS, **SUN)
ref48, out = at(by_table, 48 * HOUR)
ref48_ledger = ledger(out)
scratch = os.path.join(a.scratch, "snow_melt")
os.makedirs(scratch, exist_ok=True)
hand = []
for k in range(3):
    kw = dict(SUN, AirTemperature=ROWS["air_temperature"][k],
              Precipitation=ROWS["precipitation"][k])
    if k > 0:
        kw["RestartFile"] = os.path.join(scratch, "part%d.json" % (k - 1))
    if k < 2:
        kw["CheckpointFile"] = os.path.join(scratch, "part%d.json" % k)
    part = melt(HILL, **kw)
    hand.append(part)
    end = ROWS["time"][k + 1] if k < 2 else 48 * HOUR
    errors = T.ErrorCatcher(part)
    v, out = at(part, end)
    T.check(v is not None and not errors.messages, "hand-split part %d runs: %r"
            % (k, errors.text()))
same = v is not None and all(np.array_equal(v[n], ref48[n]) for n in ARRAYS)
T.check(same, "Forcing of 3 rows = constant runs split by hand at its rows, every array bit for bit")
T.check(v is not None and ledger(out)[2:] == ref48_ledger[2:],
        "and the ledger too (%g m3 melted)" % ref48_ledger[LEDGER.index("melt_volume")])
T.check(float(ref48["radiation"].max()) >= 0.0 and ref48_ledger[LEDGER.index("rain_volume")] > 0,
        "the rows rained (%g m3)" % ref48_ledger[LEDGER.index("rain_volume")])

# ---- determinism and requests out of order --------------------------------------------
fwd = {t: at(by_table, t)[0] for t in times}
again = melt(HILL, forcing=ROWS, CheckpointInterval=2, **SUN)
same = True
for t in (3 * 6 * HOUR, 1 * 6 * HOUR, 3 * 6 * HOUR, 7 * 6 * HOUR, 0.0, 5 * 6 * HOUR):
    v, _ = at(again, t)
    same = same and v is not None and all(np.array_equal(v[n], fwd[t][n]) for n in ARRAYS)
T.check(same, "a fresh filter asked t = 18 h, 6 h, 18 h, 42 h, 0, 30 h gives the forward run's "
        "bits (every array, melt_rate and water_release means included)")
T.check(again.GetRestoreCount() >= 1 or again.GetRestartCount() >= 2,
        "going back restored a checkpoint (%d) or restarted (%d)"
        % (again.GetRestoreCount(), again.GetRestartCount()))

# ---- the sun: a south-facing slope melts more than a north-facing one ----------------
j = np.arange(NY)[:, None] * DX + 0.0 * np.arange(NX)[None, :]
slope = 0.5  # 27 degrees
volumes = {}
for name, z in (("south", slope * j), ("north", -slope * j + slope * (NY - 1) * DX)):
    f = melt(dict(SNOW, elevation=z), AirTemperature=2.0, LapseRate=0.0, MeltFactor=1.8,
             RadiationFactor=0.0006, Latitude=46.0, StartDayOfYear=100, EndTime=DAY)
    v, out = at(f, DAY)
    volumes[name] = field(out, "melt_volume")
ratio = volumes["south"] / volumes["north"]
T.check(ratio > 1.0, "south-facing melts more than north-facing: %.6g / %.6g m3 = %.3f"
        % (volumes["south"], volumes["north"], ratio))
print("sun: melt south-facing %.6g m3, north-facing %.6g m3, ratio %.3f"
      % (volumes["south"], volumes["north"], ratio))

# ---- bad input: one sentence, an empty output ------------------------------------------
bare = melt({"elevation": flat})
errors = T.ErrorCatcher(bare)
v, _ = at(bare, 6 * HOUR)
T.check(v is None and len(errors.messages) == 1 and "no snow" in errors.text()
        and "InitialSnowDepth" in errors.text(), "no snow: one sentence: %r" % errors.text())
bare.SetInitialSnowDepth(0.5)
v, _ = at(bare, 6 * HOUR)
T.check(v is not None and len(errors.messages) == 1
        and abs(float(v["snow_depth"].max()) - 0.5) < 0.01,
        "with InitialSnowDepth 0.5 m it runs (depth %g m)" % (v["snow_depth"].max() if v else -1))
back = melt(forcing={"time": [0.0, 6 * HOUR, 6 * HOUR], "air_temperature": [1.0, 2.0, 3.0]})
errors = T.ErrorCatcher(back)
v, _ = at(back, 6 * HOUR)
T.check(v is None and len(errors.messages) == 1 and "increase" in errors.text(),
        "Forcing times not increasing: one sentence: %r" % errors.text())
nan = melt(AirTemperature=float("nan"))
errors = T.ErrorCatcher(nan)
v, _ = at(nan, 6 * HOUR)
T.check(v is None and len(errors.messages) == 1 and "AirTemperature" in errors.text(),
        "NaN AirTemperature: one sentence: %r" % errors.text())
nanrow = melt(forcing={"time": [0.0, 6 * HOUR], "precipitation": [1.0, float("nan")]})
errors = T.ErrorCatcher(nanrow)
v, _ = at(nanrow, 6 * HOUR)
T.check(v is None and len(errors.messages) == 1 and "precipitation" in errors.text(),
        "NaN in the Forcing: one sentence: %r" % errors.text())
hot = melt(forcing={"time": [0.0], "air_temperature": [150.0]})
errors = T.ErrorCatcher(hot)
v, _ = at(hot, 6 * HOUR)
T.check(v is None and len(errors.messages) == 1, "a Forcing of 150 degC: one sentence: %r"
        % errors.text())
print("\n".join(errors.messages))
polar = melt()
polar.SetLatitude(95.0)
T.check(polar.GetLatitude() == 90.0, "Latitude 95 clamps to 90")
warnings = T.ErrorCatcher(polar, event="WarningEvent")
errors = T.ErrorCatcher(polar)
v, _ = at(polar, 6 * HOUR)
T.check(v is not None and not errors.messages and len(warnings.messages) == 1
        and "Latitude" in warnings.text(),
        "and the next update warns once and runs: %r" % warnings.text())

# ---- per-point forcing from a temporal Input (FollowInputTime) ---------------------------
from vtkmodules.util.vtkAlgorithm import VTKPythonAlgorithmBase  # noqa: E402

FRAME_TIMES = [0.0, 9 * HOUR, 15 * HOUR]
LEFT = (np.arange(NX) < NX // 2)[None, :] & np.ones((NY, 1), dtype=bool)  # west half
WARM = [(3.0, 7.0), (6.0, 1.5), (2.0, 9.0)]  # degC, (west, east) per frame


class Frames(VTKPythonAlgorithmBase):
    """The snow of SNOW at FRAME_TIMES, each frame with the per-point arrays that
    forcing(k) gives (held until the next frame, as weather-model frames)."""

    def __init__(self, forcing, times=FRAME_TIMES):
        VTKPythonAlgorithmBase.__init__(self, nInputPorts=0, nOutputPorts=1,
                                        outputType="vtkImageData")
        self.forcing = forcing
        self.times = list(times)
        self.asked = []

    def RequestInformation(self, request, inInfo, outInfo):
        info = outInfo.GetInformationObject(0)
        info.Set(SDDP.WHOLE_EXTENT(), (0, NX - 1, 0, NY - 1, 0, 0), 6)
        info.Set(SDDP.TIME_STEPS(), self.times, len(self.times))
        info.Set(SDDP.TIME_RANGE(), (self.times[0], self.times[-1]), 2)
        return 1

    def RequestData(self, request, inInfo, outInfo):
        info = outInfo.GetInformationObject(0)
        t = info.Get(SDDP.UPDATE_TIME_STEP()) if info.Has(SDDP.UPDATE_TIME_STEP()) else 0.0
        k = max([i for i, s in enumerate(self.times) if s <= t + 1e-9] or [0])
        self.asked.append(self.times[k])
        out = vtkImageData.GetData(outInfo)
        out.ShallowCopy(image(dict(SNOW, **self.forcing(k))))
        out.GetInformation().Set(out.DATA_TIME_STEP(), self.times[k])
        return 1


def held(t, k, times=FRAME_TIMES):
    """Seconds of [0, t] over which frame k holds (the first from 0, the last on)."""
    lo = times[k] if k > 0 else 0.0
    hi = times[k + 1] if k + 1 < len(times) else np.inf
    return max(0.0, min(hi, t) - lo)


def temperature_frame(k):
    return {"air_temperature": np.where(LEFT, WARM[k][0], WARM[k][1])}


def follow(source, **kw):
    f = vtkSnowMeltFilter()
    f.SetInputConnection(source.GetOutputPort())
    f.SetFollowInputTime(1)
    f.SetEndTime(kw.pop("EndTime", DAY))
    f.SetOutputInterval(kw.pop("OutputInterval", 6 * HOUR))
    for k, v in kw.items():
        getattr(f, "Set" + k)(v)
    return f, T.ErrorCatcher(f)


PLAIN = dict(MeltFactor=MF, ThresholdTemperature=T0, RadiationFactor=0.0, CastShadows=0,
             LiquidWaterCapacity=0.0, AirTemperature=-20.0)
OUT_TIMES = [k * 6 * HOUR for k in range(5)]
src = Frames(temperature_frame)
fol, caught = follow(src, **PLAIN)
worst, forward = 0.0, {}
for t in OUT_TIMES:
    v, out = at(fol, t)
    forward[t] = (v, ledger(out))
    for half, col in ((LEFT, 0), (~LEFT, 1)):
        melt_m = sum(MF * 1e-3 * (WARM[k][col] - T0) * held(t, k) / DAY for k in range(3))
        got = SWE0 - v["swe"].astype(np.float64)[half.ravel()]
        worst = max(worst, float(np.abs(got - melt_m).max()))
T.check(worst < 1e-6, "per-point air_temperature frames at 0, 9, 15 h: each half's melt = "
        "sum MF (T_k - T0) held_k at every output, worst %.3g m" % worst)
T.check(float(forward[OUT_TIMES[-1]][0]["swe"][0]) != float(forward[OUT_TIMES[-1]][0]["swe"][-1]),
        "the halves melt differently")
print("temporal forcing: SWE per half within %.3g m of the frames' sum over %d outputs"
      % (worst, len(OUT_TIMES)))

# Out of order, on a fresh filter with a checkpoint every 2 outputs: the same bits.
again, caught2 = follow(Frames(temperature_frame), CheckpointInterval=2, **PLAIN)
same = True
for t in (18 * HOUR, 6 * HOUR, DAY, 0.0, 12 * HOUR, 6 * HOUR):
    v, out = at(again, t)
    same = same and v is not None and ledger(out) == forward[t][1] and all(
        np.array_equal(v[n], forward[t][0][n]) for n in ARRAYS)
T.check(same, "asked 18 h, 6 h, 24 h, 0, 12 h, 6 h: the forward run's bits, ledger included")
T.check(again.GetRestoreCount() >= 1, "a checkpoint was restored (%d)" % again.GetRestoreCount())
T.check(not caught.messages and not caught2.messages,
        "no error (%s)" % (caught.messages + caught2.messages))

# Frames without the arrays: the constants hold, bit for bit as without FollowInputTime.
bare_frames, _ = follow(Frames(lambda k: {}), **dict(PLAIN, AirTemperature=TEMP))
ref = melt(**dict(PLAIN, AirTemperature=TEMP, EndTime=DAY))
v1, _ = at(bare_frames, DAY)
v2, _ = at(ref, DAY)
T.check(all(np.array_equal(v1[n], v2[n]) for n in ARRAYS),
        "frames without air_temperature or precipitation: AirTemperature holds, the same bits")

# Precipitation frames: snow on the cold west half, rain on the warm east half.
i_grid = np.arange(NX)[None, :] + 0.0 * np.arange(NY)[:, None]
RATES = [(0.5 + 0.1 * (i_grid % 4)) * (k + 1) for k in range(3)]  # mm/h


def wet_frame(k):
    return {"air_temperature": np.where(LEFT, -4.0, 5.0), "precipitation": RATES[k]}


wet_src = Frames(wet_frame)
wf, caught3 = follow(wet_src, CastShadows=0)
worst = 0.0
for t in OUT_TIMES[1:]:
    _, out = at(wf, t)
    L = dict(zip(LEDGER, ledger(out)))
    for name, half in (("snowfall_volume", LEFT), ("rain_volume", ~LEFT)):
        want = sum(float(RATES[k][half].astype(np.float32).astype(np.float64).sum()) * 1e-3
                   * held(t, k) / HOUR * AREA for k in range(3))
        worst = max(worst, abs(L[name] - want) / want)
    T.check(L["balance_error"] == 0.0, "t = %g h: balance 0 (%g)" % (t / HOUR, L["balance_error"]))
T.check(worst < 1e-6, "precipitation frames: snowfall (west) and rain (east) volumes = sum "
        "rate area held_k at every output, worst relative %.3g" % worst)
T.check(not caught3.messages, "no error (%s)" % caught3.messages)
print("temporal precipitation: snowfall and rain volumes within %.3g of the frames' sum" % worst)


# A frame with a NaN temperature: one sentence, an empty output.
def nan_frame(k):
    f = temperature_frame(k)
    if k == 2:
        f["air_temperature"] = f["air_temperature"].copy()
        f["air_temperature"][3, 5] = np.nan
    return f


nf, caught4 = follow(Frames(nan_frame), **PLAIN)
v, _ = at(nf, DAY)
T.check(v is None and len(caught4.messages) == 1 and "air_temperature" in caught4.text()
        and "t = 54000 s" in caught4.text(),
        "a frame with NaN air_temperature: one sentence, empty output: %r" % caught4.text())
print(caught4.text())

# ---- the ParaView proxy ---------------------------------------------------------------
plugin = a.plugin
if plugin is None:
    import graupel

    lib = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(graupel.__file__))))
    found = glob.glob(os.path.join(lib, "paraview-*", "plugins", "Graupel", "Graupel.so"))
    plugin = found[0] if found else None
if plugin is not None:
    from paraview import servermanager  # noqa: E402

    px = globals()
    from paraview import simple as pv  # noqa: E402

    pv.LoadPlugin(plugin, ns=px)
    proto = servermanager.ProxyManager().GetPrototypeProxy("filters", "SnowMelt")
    T.check(proto is not None, "proxy SnowMelt is registered")
    units = {"AirTemperature": "degC", "Precipitation": "mm/h", "InitialSnowDepth": "m:",
             "MeltFactor": "mm w.e.", "TimeStep": "Seconds", "SettlingTime": "Days",
             "Latitude": "Degrees"}
    for prop, unit in units.items():
        doc = proto.GetProperty(prop).GetDocumentation().GetDescription()
        T.check(doc.strip().startswith(unit), "SnowMelt.%s documents its unit: %r" % (prop, doc))
    terrain = px["ProceduralTerrain"](Dimensions=[48, 40])
    sm = px["SnowMelt"](Input=terrain, InitialSnowDepth=1.0, AirTemperature=3.0)
    T.check(sm.EndTime == 864000.0 and sm.OutputInterval == 21600.0, "the proxy's time defaults")
    sm.UpdatePipeline(DAY)
    T.check(all(k in sm.PointData.keys() for k in ARRAYS), "SnowMelt arrays %r"
            % sm.PointData.keys())
    T.check(sm.PointData["melt_rate"].GetRange()[1] > 0.0, "the proxy's snow melts (up to %g mm/h)"
            % sm.PointData["melt_rate"].GetRange()[1])
else:
    print("no ParaView plugin beside the module: proxy checks skipped (plain VTK)")

T.finish()
