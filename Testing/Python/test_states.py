"""pvbatch: every state file in Examples/states/ (Examples/make_states.py)
loads as File > Load State loads it, with data files searched under the
states' folder (run from elsewhere, so the relative names in the states
resolve only through that search): the readers find their files, every
source then gives a non-empty output at the state's time, and the view
renders a picture (not just the background)."""
import glob
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

def extra(p):
    p.add_argument("--states", required=True)
    p.add_argument("--built-states", default=None)


a = T.args(extra)

import numpy as np  # noqa: E402
from paraview import servermanager  # noqa: E402
import paraview.simple as pvs  # noqa: E402
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402
from vtkmodules.vtkIOImage import vtkPNGReader  # noqa: E402

states = os.path.abspath(a.states)
os.chdir(a.scratch)
expected = ["rain_jacksboro", "season", "snow_accumulation", "snow_deformation", "terrain"]
found = sorted(os.path.basename(p)[:-5] for p in glob.glob(os.path.join(states, "*.pvsm")))
T.check(found == expected, "the states are %s (found %s)" % (expected, found))


def file_names(proxy):
    prop = proxy.GetProperty("FileName")
    if prop is None:
        return []
    value = prop.GetData()
    return [value] if isinstance(value, str) else list(value)


# The plugin's proxies outlive ResetSession: load it once.
pvs.LoadPlugin(a.plugin, ns=vars(pvs))
for name in found:
    pvs.ResetSession()
    text = open(os.path.join(states, name + ".pvsm")).read()
    absolute = re.findall(r'value="(/[^"]*\.(?:exr|vtm|vtp|vti|vtk|png|csv))"', text)
    T.check(not absolute, "%s: no absolute data path in the state (%s)" % (name, absolute))
    pvs.LoadState(os.path.join(states, name + ".pvsm"), data_directory=states)
    views = pvs.GetRenderViews()
    T.check(len(views) == 1, "%s: one render view (%d)" % (name, len(views)))
    if not views:
        continue
    view = views[0]
    t = view.ViewTime
    sources = pvs.GetSources()
    # Rain Runoff's half hour on the DEM takes a minute here: the test runs
    # its first output interval only (the state's times are checked as saved).
    for (label, _), proxy in sources.items():
        if proxy.GetXMLName() == "RainRunoff" and name == "rain_jacksboro":
            T.check(proxy.EndTime == 1800.0 and t == 1800.0,
                    "%s: %s runs to %g s, shown at %g s" % (name, label, proxy.EndTime, t))
            proxy.EndTime = proxy.OutputInterval
            t = view.ViewTime = proxy.OutputInterval
    empty, missing = [], []
    for (label, _), proxy in sorted(sources.items()):
        for path in file_names(proxy):
            if not os.path.isfile(path):
                missing.append("%s: %s" % (label, path))
        proxy.UpdatePipeline(t)
        info = proxy.GetDataInformation()
        if info.GetNumberOfPoints() == 0 and info.DataInformation.GetNumberOfRows() == 0:
            empty.append(label)
    T.check(not missing, "%s: every data file found (%s)" % (name, missing))
    T.check(not empty, "%s: every one of %d sources has data at t = %g s (empty: %s)"
            % (name, len(sources), t, empty))
    # The DEM's spacing comes from its file (the state sets none), so the
    # state's camera, placed for the real 30 x 31.6 km, sees the terrain.
    dems = [(label, proxy) for (label, _), proxy in sources.items()
            if proxy.GetXMLName() == "EXRHeightFieldReader"
            and "jacksboro" in "".join(file_names(proxy))]
    T.check(len(dems) == (1 if name == "rain_jacksboro" else 0),
            "%s: %d readers of the DEM" % (name, len(dems)))
    for label, proxy in dems:
        b = proxy.GetDataInformation().GetBounds()
        T.check(abs(b[1] - 402 * 74.5) < 1e-6 and abs(b[3] - 343 * 92.1) < 1e-6,
                "%s: %s opens at the DEM's real size (bounds %s)" % (name, label, b))
    png = os.path.join(a.scratch, "state_%s.png" % name)
    pvs.SaveScreenshot(png, view, ImageResolution=[400, 300])
    r = vtkPNGReader()
    r.SetFileName(png)
    r.Update()
    img = vtk_to_numpy(r.GetOutput().GetPointData().GetScalars()).reshape(-1, 3).astype(int)
    background = np.round(np.asarray(view.Background) * 255).astype(int)
    drawn = float(np.mean(np.abs(img - background).sum(axis=1) > 24))
    print("%s: %d sources at t = %g s, %.0f%% of the picture drawn" % (
        name, len(sources), t, 100 * drawn))
    T.check(drawn > 0.2, "%s: the view draws the scene (%.2f of the pixels)" % (name, drawn))

# The build tree's copies (Plugin/CMakeLists.txt) load with the dialog's
# defaults (Use File Names From State), from any folder: every reader finds
# its file and reads it.
if a.built_states:
    built = sorted(os.path.basename(p)[:-5]
                   for p in glob.glob(os.path.join(a.built_states, "*.pvsm")))
    T.check(built == expected, "the built states are %s (found %s)" % (expected, built))
    for name in built:
        pvs.ResetSession()
        pvs.LoadState(os.path.join(a.built_states, name + ".pvsm"))
        readers = [(label, proxy) for (label, _), proxy in pvs.GetSources().items()
                   if file_names(proxy)]
        bad = []
        for label, proxy in readers:
            proxy.UpdatePipeline()
            info = proxy.GetDataInformation()
            if (not all(os.path.isfile(f) for f in file_names(proxy))
                    or (info.GetNumberOfPoints() == 0
                        and info.DataInformation.GetNumberOfRows() == 0)):
                bad.append(label)
        T.check(not bad, "%s, loaded with the defaults: %d readers, all read (not: %s)"
                % (name, len(readers), bad))
T.finish()
