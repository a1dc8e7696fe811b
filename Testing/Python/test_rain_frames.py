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
refused with one sentence."""
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

    def __init__(self, drop_last=False):
        VTKPythonAlgorithmBase.__init__(self, nInputPorts=0, nOutputPorts=1,
                                        outputType="vtkImageData")
        self.drop_last = drop_last

    def RequestInformation(self, request, inInfo, outInfo):
        info = outInfo.GetInformationObject(0)
        info.Set(SDDP.WHOLE_EXTENT(), (0, NX - 1, 0, NY - 1, 0, 0), 6)
        info.Set(SDDP.TIME_STEPS(), TIMES, len(TIMES))
        info.Set(SDDP.TIME_RANGE(), (TIMES[0], TIMES[-1]), 2)
        return 1

    def RequestData(self, request, inInfo, outInfo):
        info = outInfo.GetInformationObject(0)
        t = info.Get(SDDP.UPDATE_TIME_STEP()) if info.Has(SDDP.UPDATE_TIME_STEP()) else 0.0
        k = max(i for i, s in enumerate(TIMES) if s <= t + 1e-9) if t >= TIMES[0] else 0
        out = vtkImageData.GetData(outInfo)
        out.SetDimensions(NX, NY, 1)
        out.SetSpacing(DX, DX, 1.0)
        e = numpy_to_vtk(ELEVATION, deep=1)
        e.SetName("elevation")
        out.GetPointData().AddArray(e)
        if not (self.drop_last and k == len(TIMES) - 1):
            r = numpy_to_vtk(FRAMES[k], deep=1)
            r.SetName("rain_rate")
            out.GetPointData().AddArray(r)
        out.GetInformation().Set(out.DATA_TIME_STEP(), TIMES[k])
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
T.finish()
