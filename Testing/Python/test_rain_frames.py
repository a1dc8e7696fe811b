"""Rain that varies in space and time: Rain Runoff with FollowInputTime on a
temporal Input whose `rain_rate` (m/s per point) changes at its time steps
(as a series of radar frames on the terrain's grid would): three frames at
0, 100 and 250 s, each a different field, over a walled 40 x 30 grid of
5 m cells, run to 400 s with outputs every 50 s. Each frame rains over its
whole interval (sample and hold), so the ledger's rain volume must be
sum_k sum_cells rate_k dx dy (t_{k+1} - t_k) to 1e-6, at every output
(partial intervals included), with the ledger closed; going back in time
and forward again gives the same bits (the frames are set again after a
snapshot is restored); a frame without `rain_rate` after frames with it is
refused with one sentence.

RainFrames = 1 ("over the interval before it", for a rate that is the mean
over the interval ending at its time, as Snow Melt's release): the frame at
t_k rains over (t_{k-1}, t_k], the first frame before its time, the last
after its time (held). The frames at 0, 100 and 250 s then rain over
(0, 100] (the frame at 100 s), (100, 400] (the frame at 250 s): the frame
at 0 s ends no interval of the run and is never asked for. Frames at 50,
150 and 300 s (a run that starts before the first frame): (0, 50] the frame
at 50 s, (50, 150] at 150 s, (150, 400] at 300 s. Rain volume to 1e-6 at
every output, ledger closed; asked out of order, with and without
checkpoints, and after switching RainFrames away and back: the same bits."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args()

from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy  # noqa: E402
from vtkmodules.util.vtkAlgorithm import VTKPythonAlgorithmBase  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData  # noqa: E402
from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline as SDDP  # noqa: E402

from graupel import vtkRainRunoffFilter  # noqa: E402

NX, NY, DX = 40, 30, 5.0
TIMES = [0.0, 100.0, 250.0]
x, y = np.meshgrid(np.arange(NX), np.arange(NY))
ELEVATION = (0.02 * x + 0.3 * np.sin(0.4 * y)).astype(np.float32).ravel()
FRAMES = [(1e-5 * (k + 1) * (1.0 + 0.5 * np.sin(0.3 * x + k) * np.cos(0.2 * y))).astype(
    np.float32).ravel() for k in range(len(TIMES))]


class Frames(VTKPythonAlgorithmBase):
    """A terrain whose rain_rate changes at TIMES (held until the next)."""

    def __init__(self, drop_last=False, times=TIMES):
        VTKPythonAlgorithmBase.__init__(self, nInputPorts=0, nOutputPorts=1,
                                        outputType="vtkImageData")
        self.drop_last = drop_last
        self.times = list(times)
        self.asked = []  # the frame times delivered, in order

    def RequestInformation(self, request, inInfo, outInfo):
        info = outInfo.GetInformationObject(0)
        info.Set(SDDP.WHOLE_EXTENT(), (0, NX - 1, 0, NY - 1, 0, 0), 6)
        info.Set(SDDP.TIME_STEPS(), self.times, len(self.times))
        info.Set(SDDP.TIME_RANGE(), (self.times[0], self.times[-1]), 2)
        return 1

    def RequestData(self, request, inInfo, outInfo):
        times = self.times
        info = outInfo.GetInformationObject(0)
        t = info.Get(SDDP.UPDATE_TIME_STEP()) if info.Has(SDDP.UPDATE_TIME_STEP()) else 0.0
        k = max(i for i, s in enumerate(times) if s <= t + 1e-9) if t >= times[0] else 0
        self.asked.append(times[k])
        out = vtkImageData.GetData(outInfo)
        out.SetDimensions(NX, NY, 1)
        out.SetSpacing(DX, DX, 1.0)
        e = numpy_to_vtk(ELEVATION, deep=1)
        e.SetName("elevation")
        out.GetPointData().AddArray(e)
        if not (self.drop_last and k == len(times) - 1):
            r = numpy_to_vtk(FRAMES[k], deep=1)
            r.SetName("rain_rate")
            out.GetPointData().AddArray(r)
        out.GetInformation().Set(out.DATA_TIME_STEP(), times[k])
        return 1


def rain_volume(t):
    """sum over frames of rate dx dy times the part of [0, t] it holds."""
    v = 0.0
    for k, start in enumerate(TIMES):
        end = TIMES[k + 1] if k + 1 < len(TIMES) else float("inf")
        held = max(0.0, min(end, t) - start)
        v += float(FRAMES[k].astype(np.float64).sum()) * DX * DX * held
    return v


src = Frames()
rain = vtkRainRunoffFilter()
rain.SetInputConnection(src.GetOutputPort())
rain.SetFollowInputTime(1)
rain.SetEndTime(400.0)
rain.SetOutputInterval(50.0)
rain.SetBoundary(1)  # closed: every drop stays
caught = T.ErrorCatcher(rain)


def at(t):
    rain.UpdateTimeStep(t)
    out = rain.GetOutput()
    fd = out.GetFieldData()
    return (fd.GetArray("rain_volume").GetValue(0), fd.GetArray("balance_error").GetValue(0),
            vtk_to_numpy(out.GetPointData().GetArray("water_depth")).copy())


first = {}
for t in (50.0, 100.0, 150.0, 250.0, 300.0, 400.0):
    vol, err, depth = at(t)
    first[t] = depth
    want = rain_volume(t)
    T.check(abs(vol - want) <= 1e-6 * want,
            "t = %g s: rain volume %.9g m3, frames held give %.9g (rel %.1e)"
            % (t, vol, want, abs(vol - want) / want))
    T.check(abs(err) <= 1e-6 * vol, "t = %g s: the ledger closes (%.2e m3)" % (t, err))
T.check(not caught.messages, "no error (%s)" % caught.messages)
# One constant frame would give another volume: the frames are followed.
T.check(abs(rain_volume(400.0) - float(FRAMES[0].astype(np.float64).sum()) * DX * DX * 400.0)
        > 0.1 * rain_volume(400.0), "the frames differ enough to tell")
for t in (150.0, 400.0, 100.0):
    _, _, depth = at(t)
    T.check(np.array_equal(depth, first[t]), "t = %g s again (back and forth): the same bits" % t)

bad = Frames(drop_last=True)
rain2 = vtkRainRunoffFilter()
rain2.SetInputConnection(bad.GetOutputPort())
rain2.SetFollowInputTime(1)
rain2.SetEndTime(400.0)
rain2.SetOutputInterval(50.0)
caught2 = T.ErrorCatcher(rain2)
rain2.UpdateTimeStep(300.0)
T.check(rain2.GetOutput().GetNumberOfPoints() == 0 and len(caught2.messages) == 1
        and "no point array 'rain_rate' at t = 250 s" in caught2.messages[0],
        "a frame without rain after frames with it: one sentence, empty (%s)" % caught2.messages)

# ------------------------------------------ RainFrames = 1: the interval before
OUTPUTS = (50.0, 100.0, 150.0, 200.0, 250.0, 300.0, 350.0, 400.0)


def interval_volume(t, times, mode):
    """sum over frames of rate dx dy times the part of (0, t] it rains: mode 0
    [t_k, t_k+1), mode 1 (t_k-1, t_k]; the first frame from -inf, the last to
    +inf either way."""
    v = 0.0
    n = len(times)
    for k in range(n):
        if mode == 0:
            lo = times[k] if k > 0 else -np.inf
            hi = times[k + 1] if k + 1 < n else np.inf
        else:
            lo = times[k - 1] if k > 0 else -np.inf
            hi = times[k] if k + 1 < n else np.inf
        held = max(0.0, min(hi, t) - max(lo, 0.0))
        v += float(FRAMES[k].astype(np.float64).sum()) * DX * DX * held
    return v


def runoff(source, mode, checkpoints=10):
    f = vtkRainRunoffFilter()
    f.SetInputConnection(source.GetOutputPort())
    f.SetFollowInputTime(1)
    f.SetRainFrames(mode)
    f.SetEndTime(400.0)
    f.SetOutputInterval(50.0)
    f.SetCheckpointInterval(checkpoints)
    f.SetBoundary(1)
    return f, T.ErrorCatcher(f)


def state(f, t):
    f.UpdateTimeStep(t)
    out = f.GetOutput()
    fd = out.GetFieldData()
    return (fd.GetArray("rain_volume").GetValue(0), fd.GetArray("balance_error").GetValue(0),
            vtk_to_numpy(out.GetPointData().GetArray("water_depth")).copy())


T.check(rain.GetRainFrames() == 0, "RainFrames is 0 by default (%d)" % rain.GetRainFrames())
probe = vtkRainRunoffFilter()
probe.SetRainFrames(7)
T.check(probe.GetRainFrames() == 1, "RainFrames clamps 7 to 1 (%d)" % probe.GetRainFrames())
probe.SetRainFrames(-3)
T.check(probe.GetRainFrames() == 0, "RainFrames clamps -3 to 0 (%d)" % probe.GetRainFrames())

for times, modes in ((TIMES, (1,)), ([50.0, 150.0, 300.0], (0, 1))):
    for mode in modes:
        src1 = Frames(times=times)
        f1, c1 = runoff(src1, mode)
        label = "RainFrames %d, frames at %s s" % (mode, "/".join("%g" % x for x in times))
        ref = {}
        worst = 0.0
        for t in OUTPUTS:
            vol, err, depth = state(f1, t)
            ref[t] = (vol, depth)
            want = interval_volume(t, times, mode)
            worst = max(worst, abs(vol - want) / want)
            T.check(abs(vol - want) <= 1e-6 * want,
                    "%s, t = %g s: rain volume %.9g m3, intervals give %.9g (rel %.1e)"
                    % (label, t, vol, want, abs(vol - want) / want))
            T.check(abs(err) <= 1e-6 * vol, "%s, t = %g s: the ledger closes (%.2e m3)"
                    % (label, t, err))
        print("%s: rain volume within %.1e of the intervals' sum at 8 outputs" % (label, worst))
        if times[0] == 0.0 and mode == 1:
            T.check(0.0 not in src1.asked,
                    "%s: the frame at 0 s ends no interval and is never read (%s)"
                    % (label, sorted(set(src1.asked))))
            T.check(abs(interval_volume(400.0, times, 1) - rain_volume(400.0))
                    > 0.05 * rain_volume(400.0), "%s: differs enough from sample and hold" % label)
            T.check(not np.array_equal(ref[400.0][1], first[400.0]),
                    "%s: water differs from RainFrames 0's at 400 s" % label)
        # Back and forth on the same filter (no checkpoint: from time 0).
        for t in (150.0, 400.0, 100.0, 300.0):
            vol, _, depth = state(f1, t)
            T.check(np.array_equal(depth, ref[t][1]) and vol == ref[t][0],
                    "%s, t = %g s again (back and forth): the same bits" % (label, t))
        # Another filter asked out of order, with a checkpoint every 2 outputs.
        f2, c2 = runoff(Frames(times=times), mode, checkpoints=2)
        for t in (400.0, 150.0, 300.0, 100.0, 250.0, 50.0, 350.0, 200.0):
            vol, _, depth = state(f2, t)
            T.check(np.array_equal(depth, ref[t][1]) and vol == ref[t][0],
                    "%s, t = %g s out of order, checkpoints every 2 outputs: the same bits"
                    % (label, t))
        T.check(f2.GetRestoreCount() > 0, "%s: checkpoints were restored (%d)"
                % (label, f2.GetRestoreCount()))
        # Away and back: the property sets the simulation up again.
        f1.SetRainFrames(1 - mode)
        state(f1, 300.0)
        f1.SetRainFrames(mode)
        vol, _, depth = state(f1, 300.0)
        T.check(np.array_equal(depth, ref[300.0][1]) and vol == ref[300.0][0],
                "%s: RainFrames switched away and back, t = 300 s: the same bits" % label)
        T.check(not c1.messages and not c2.messages,
                "%s: no error (%s)" % (label, c1.messages + c2.messages))
T.finish()
