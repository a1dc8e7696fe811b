"""Snow Melt into Rain Runoff, one chain (pvbatch in the plugin build, plain
python3 on Debian's VTK): a snowpack on a tilted valley melts at 6 degC with
the sun off; Rain Runoff follows Snow Melt's outputs (FollowInputTime) and
rains each output's rain_rate, the mean release over the interval before it,
over that interval (RainFrames 1). Asserted:

  * the water Rain Runoff books as rain equals what Snow Melt released, to
    1e-6 of it, with outputs every 10 min and every 6 h;
  * one ledger over the chain closes: initial SWE + snowfall + rain = SWE and
    liquid water stored + infiltrated + surface water + outflow, to 1e-6 of
    the water in;
  * the outflow does not depend on the output interval: 10 min and 6 h
    outputs give the same outflow and storage within 1 %.
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args()

from vtkmodules.util.numpy_support import numpy_to_vtk  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData  # noqa: E402
from vtkmodules.vtkCommonExecutionModel import vtkTrivialProducer  # noqa: E402

from graupel import vtkRainRunoffFilter, vtkSnowMeltFilter  # noqa: E402

NX, NY, DX = 24, 16, 10.0
HOUR = 3600.0
END = 12.0 * HOUR
j, i = np.mgrid[0:NY, 0:NX]
# A valley falling west, its sides rising north and south: melt water runs to x = 0.
ground = 0.02 * DX * i + 0.05 * DX * np.abs(j - (NY - 1) / 2.0)


def terrain():
    img = vtkImageData()
    img.SetDimensions(NX, NY, 1)
    img.SetSpacing(DX, DX, 1.0)
    for name, values in (("elevation", ground), ("snow_depth", np.full((NY, NX), 0.4)),
                         ("snow_density", np.full((NY, NX), 300.0))):
        arr = numpy_to_vtk(np.ascontiguousarray(values, dtype=np.float32).reshape(-1), deep=1)
        arr.SetName(name)
        img.GetPointData().AddArray(arr)
    src = vtkTrivialProducer()
    src.SetOutput(img)
    return src


def field(out, name):
    return out.GetFieldData().GetArray(name).GetValue(0)


def chain(interval):
    src = terrain()
    melt = vtkSnowMeltFilter()
    melt.SetInputConnection(src.GetOutputPort())
    melt.SetEndTime(END)
    melt.SetOutputInterval(interval)
    melt.SetAirTemperature(6.0)
    melt.SetRadiationFactor(0.0)
    melt.SetMeltFactor(4.0)
    melt.SetLiquidWaterCapacity(0.05)
    runoff = vtkRainRunoffFilter()
    runoff.SetInputConnection(melt.GetOutputPort())
    runoff.SetFollowInputTime(1)
    runoff.SetRainFrames(1)
    runoff.SetRainRate(0.0)
    runoff.SetEndTime(END)
    runoff.SetOutputInterval(interval)
    errs = T.ErrorCatcher(runoff)
    merrs = T.ErrorCatcher(melt)
    runoff.UpdateTimeStep(END)
    r = runoff.GetOutput()
    melt.UpdateTimeStep(END)
    m = melt.GetOutput()
    T.check(not errs.messages and not merrs.messages and r.GetNumberOfPoints() == NX * NY,
            "every %g s: the chain runs (%s %s)" % (interval, errs.messages, merrs.messages))
    return m, r, (src, melt, runoff)


results = {}
for interval in (HOUR / 6.0, 6.0 * HOUR):
    m, r, keep = chain(interval)
    released = field(m, "released_volume")
    rained = field(r, "rain_volume")
    water_in = field(m, "snowfall_in") + field(m, "snowfall_volume") + field(m, "rain_volume")
    stored_snow = field(m, "stored_swe_volume") + field(m, "stored_liquid_volume")
    infiltrated = field(r, "infiltrated_volume")
    surface = field(r, "stored_volume")
    outflow = field(r, "outflow_volume")
    print("every %5.0f s: released %.6f m3, rained %.6f m3; in %.3f = snow %.3f + surface %.3f "
          "+ infiltrated %.3f + outflow %.3f m3" % (interval, released, rained, water_in,
                                                    stored_snow, surface, infiltrated, outflow))
    T.check(released > 0.05 * water_in,
            "a good part of the snow melts and leaves it (%.3f of %.3f m3)" % (released, water_in))
    T.check(abs(rained - released) <= 1e-6 * released,
            "every %g s: Rain Runoff's rain = Snow Melt's release to 1e-6 (%.9f vs %.9f m3)"
            % (interval, rained, released))
    chain_error = water_in - (stored_snow + infiltrated + surface + outflow)
    T.check(abs(chain_error) <= 1e-6 * water_in,
            "every %g s: the chain's ledger closes to 1e-6 of the water in (%.3g m3)"
            % (interval, chain_error))
    results[interval] = (outflow, surface, released)

(o1, s1, r1), (o2, s2, r2) = results[HOUR / 6.0], results[6.0 * HOUR]
T.check(abs(r1 - r2) <= 1e-6 * r1, "the same water released whatever the outputs (%.9f, %.9f)"
        % (r1, r2))
T.check(abs(o1 - o2) <= 0.01 * max(o1, o2) and abs(s1 - s2) <= 0.01 * (s1 + o1),
        "10 min or 6 h outputs: outflow %.4f vs %.4f m3, surface water %.4f vs %.4f m3 (1 %%)"
        % (o1, o2, s1, s2))
T.finish()
