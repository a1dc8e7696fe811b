"""pvpython: Rain Runoff as a user meets it first. The shipped DEM opened with
File > Open (OpenDataFile, no property set) and Rain Runoff applied with every
default: the run to its default EndTime must leave water that shows (deeper
than the 1 cm WettingDepth, below which the GUI's water-depth map draws dry
ground) over a good part of the DEM and gathered into hollows and valleys,
not a film under 1 cm everywhere. The defaults before (10 mm/h for 600 s,
1.7 mm of rain) left 7 mm at most and no point wet: every water check
below failed. The optional inputs get ParaView's input selector, so the panel can
pick them. On a fresh Procedural Terrain the first minute of Play shows
water in the valleys."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args()

import numpy as np  # noqa: E402
from paraview import servermanager  # noqa: E402
from paraview.simple import *  # noqa: E402,F401,F403
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402

LoadPlugin(a.plugin, ns=globals())

# The panel: every optional input (PermeabilityMap, Gauges, Inflows) is a
# combo box of the pipeline's sources (pqInputSelectorWidget); Input is not.
proto = servermanager.ProxyManager().GetPrototypeProxy("filters", "RainRunoff")
inputs = {}
it = proto.NewPropertyIterator()
it.Begin()
while not it.IsAtEnd():
    if it.GetProperty().IsA("vtkSMInputProperty"):
        inputs[it.GetKey()] = it.GetProperty().GetPanelWidget()
    it.Next()
T.check(inputs == {"Input": None, "PermeabilityMap": "input_selector",
                   "Gauges": "input_selector", "Inflows": "input_selector"},
        "Rain Runoff's optional inputs have the input selector: %s" % inputs)

dem = OpenDataFile(os.path.join(a.data, "jacksboro_fault_dem.exr"))
rain = RainRunoff(Input=dem)
T.check((rain.RainRate, rain.EndTime, rain.OutputInterval, rain.WettingDepth)
        == (100.0, 600.0, 10.0, 0.01),
        "defaults: 100 mm/h, EndTime 600 s, OutputInterval 10 s, WettingDepth 1 cm (%r)"
        % ((rain.RainRate, rain.EndTime, rain.OutputInterval, rain.WettingDepth),))
end = rain.EndTime
rain.UpdatePipeline(end)
out = servermanager.Fetch(rain)
fd = out.GetFieldData()


def ledger(name):
    arr = fd.GetArray(name)
    return arr.GetValue(0) if arr is not None else float("nan")


h = vtk_to_numpy(out.GetPointData().GetArray("water_depth"))
sheet = rain.RainRate / 3.6e6 * end  # m: the rain, were it to stay where it fell
wet = float(np.mean(h > rain.WettingDepth))
gathered = float(np.mean(h > 3.0 * sheet))
print("default Rain Runoff on the DEM: %g s, %.1f mm of rain, %d steps; deepest %.3f m, "
      "wet (> %g m) %.3f, deeper than 3 x the rain %.3f"
      % (ledger("time"), 1e3 * sheet, ledger("steps"), h.max(), rain.WettingDepth, wet,
         gathered))
T.check(ledger("time") == end and out.GetNumberOfPoints() == 403 * 344,
        "the run reaches the default EndTime on the whole DEM")
# Measured: 0.757 m, 0.405 and 0.054 (PoCL). The thresholds leave room for
# another device's rounding, not for a dry map.
T.check(h.max() > 0.5, "the deepest water %.3f m is above 0.5 m" % h.max())
T.check(wet > 0.3, "%.3f of the DEM is wet (deeper than %g m), above 0.3"
        % (wet, rain.WettingDepth))
T.check(gathered > 0.03, "%.3f of the DEM holds more than 3 x the rain (%.0f mm), above 0.03: "
        "the water gathers" % (gathered, 3e3 * sheet))
T.check(abs(ledger("balance_error")) <= 1e-6 * ledger("rain_volume"),
        "the ledger closes: %.3g m^3 of %.4g m^3" % (ledger("balance_error"),
                                                      ledger("rain_volume")))

# A fresh Procedural Terrain (512 x 512 points, 2 m): Play's first minute of
# rain (six frames) already shows water in its valleys, in few steps; the
# whole 600 s takes about 7 600 steps, as the pits fill and deepen.
terrain = ProceduralTerrain()
rain2 = RainRunoff(Input=terrain)
rain2.UpdatePipeline(60.0)
out2 = servermanager.Fetch(rain2)
h2 = vtk_to_numpy(out2.GetPointData().GetArray("water_depth"))
steps2 = out2.GetFieldData().GetArray("steps").GetValue(0)
wet2 = float(np.mean(h2 > rain2.WettingDepth))
print("default Rain Runoff on a default Procedural Terrain at 60 s: %d steps, deepest %.3f m, "
      "wet %.4f" % (steps2, h2.max(), wet2))
# Measured: 114 steps, 0.209 m, 0.0187 (PoCL).
T.check(steps2 <= 200, "the first minute takes %d steps, at most 200" % steps2)
T.check(h2.max() > 0.1 and wet2 > 0.01,
        "after a minute the valleys hold water: deepest %.3f m (> 0.1), %.4f wet (> 0.01)"
        % (h2.max(), wet2))
T.finish()
