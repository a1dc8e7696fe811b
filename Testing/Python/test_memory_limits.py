"""Grids that do not fit in memory, under an address-space limit (the soft
RLIMIT_AS, set in-process at what is mapped plus a budget, as `prlimit --as`
would): Procedural Terrain at 40000 x 40000 (12.8 GB) and at 22000 x 22000
(3.9 GB: before the check its host array fit and PoCL's lazily allocated
buffer then failed inside the driver, which asserted and aborted the
process), Rain Runoff, Terrain Analysis and Terrain Surface on terrains too
large, and a set of particles too many. Each is refused at once with exactly
one error sentence that names the filter and the grid and gives both
figures (what it needs, what this process can use), the output is empty, the
process goes on, and a grid that fits still runs. Also: Procedural Terrain's
progress text and fractions on a large grid."""
import os
import re
import resource
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args()

from vtkmodules.util.numpy_support import numpy_to_vtk  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData  # noqa: E402
from vtkmodules.vtkCommonExecutionModel import vtkTrivialProducer  # noqa: E402

from graupel import (  # noqa: E402
    vtkProceduralTerrainSource,
    vtkRainParticlesSource,
    vtkRainRunoffFilter,
    vtkTerrainAnalysisFilter,
    vtkTerrainSurfaceFilter,
)

def mapped():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")


HARD = resource.getrlimit(resource.RLIMIT_AS)[1]


def limit(budget):
    """The soft address-space limit at what is mapped now plus budget bytes."""
    resource.setrlimit(resource.RLIMIT_AS, (mapped() + int(budget), HARD))


def unlimit():
    resource.setrlimit(resource.RLIMIT_AS, (HARD, HARD))


# On a GPU the device's part is said apart, and this is the host's part.
SENTENCE = re.compile(r"(?P<label>[A-Z][A-Za-z ]*): (?P<subject>.+?) needs (?P<need>[0-9.]+) "
                      r"(?P<nunit>GB|MB)(?P<host> of host memory)? \((?P<per>[0-9]+) bytes a "
                      r"point\) but this process can use (?P<have>[0-9.]+) (?P<unit>GB|MB) "
                      r"\(its address-space limit\); (?P<fix>[^.]+)\.")


def refused(algorithm, label, subject, budget, need=None, per=None):
    """Updates algorithm under budget bytes and checks the one refusal."""
    # The executive's errors too ("Algorithm ... returned failure ..."):
    # exactly one sentence in all.
    errs = T.ErrorCatcher(algorithm, algorithm.GetExecutive())
    warnings = T.ErrorCatcher(algorithm, event="WarningEvent")
    limit(budget)
    algorithm.Update()
    unlimit()
    out = algorithm.GetOutputDataObject(0)
    T.check(out.GetNumberOfPoints() == 0, "%s: %s refused with an empty output" % (label, subject))
    T.check(len(errs.messages) == 1 and not warnings.messages,
            "%s: exactly one error (%r %r)" % (label, errs.messages, warnings.messages))
    m = SENTENCE.search(errs.text())
    T.check(m is not None, "%s: the sentence has both figures: %r" % (label, errs.text()))
    if not m:
        return None
    have = float(m["have"]) * (1.0 if m["unit"] == "GB" else 1e-3)
    T.check(m["label"] == label and m["subject"] == subject,
            "%s: names the filter and %s: %r" % (label, subject, errs.text()))
    T.check(0.9 * budget / 1e9 - 0.1 <= have <= budget / 1e9 + 0.05,
            "%s: can use %s GB of a %.1f GB budget" % (label, have, budget / 1e9))
    if m["host"]:
        print("the device keeps its buffers apart: figures not compared")
        return m
    if need is not None:
        T.check(m["need"] + " " + m["nunit"] == need, "%s: needs %s (%s %s)"
                % (label, need, m["need"], m["nunit"]))
    if per is not None:
        T.check(int(m["per"]) == per, "%s: %d bytes a point (%s)" % (label, per, m["per"]))
    print(errs.text())
    return m


_producers = []  # a vtkAlgorithmOutput does not keep its producer alive


def terrain_image(n, arrays=("elevation",)):
    img = vtkImageData()
    img.SetDimensions(n, n, 1)
    img.SetSpacing(10.0, 10.0, 1.0)
    for name in arrays:
        values = np.zeros(n * n, dtype=np.float32)
        arr = numpy_to_vtk(values, deep=1)
        arr.SetName(name)
        img.GetPointData().AddArray(arr)
    producer = vtkTrivialProducer()
    producer.SetOutput(img)
    _producers.append(producer)
    return producer


GB = 1e9

# ---- Procedural Terrain -------------------------------------------------------
terrain = vtkProceduralTerrainSource()
terrain.SetDimensions(64, 64)
terrain.Update()  # the context made and the kernel built before any limit
T.check(terrain.GetOutput().GetNumberOfPoints() == 64 * 64, "a small terrain first")

# 40000^2: the elevation buffer and its host copy, 4 + 4 bytes a point.
terrain.SetDimensions(40000, 40000)
refused(terrain, "Procedural Terrain", "a 40000 x 40000 grid", 3 * GB, need="12.8 GB", per=8)
# 22000^2 (3.9 GB): the grid that used to abort the process inside PoCL.
terrain.SetDimensions(22000, 22000)
refused(terrain, "Procedural Terrain", "a 22000 x 22000 grid", 3 * GB, need="3.9 GB", per=8)
# A grid that fits runs under the same limit, and the same source again.
terrain.SetDimensions(2000, 1500)
quiet = T.ErrorCatcher(terrain, terrain.GetExecutive())
limit(3 * GB)
terrain.Update()
unlimit()
out = terrain.GetOutput()
T.check(out.GetNumberOfPoints() == 2000 * 1500 and
        out.GetPointData().GetArray("elevation").GetRange()[1] > 0.0,
        "a 2000 x 1500 terrain under the same limit is computed")
T.check(not quiet.messages, "and says nothing (%r)" % quiet.messages)

# Progress on a large grid: the text names the source and the grid, the
# fraction rises band by band.
seen = []
tag = terrain.AddObserver(
    "ProgressEvent", lambda o, e: seen.append((o.GetProgress(), o.GetProgressText())))
terrain.SetDimensions(2048, 4096)
terrain.Update()
terrain.RemoveObserver(tag)
fractions = [p for p, _ in seen]
T.check(len([p for p in fractions if 0.0 < p < 1.0]) >= 1 and fractions[-1] == 1.0
        and fractions == sorted(fractions),
        "progress rises band by band to 1 (%r)" % fractions)
# (The executive's first report, at 0, comes before RequestData sets the text.)
T.check(all(t == "Procedural Terrain: 2048 x 4096 points" for p, t in seen if p > 0.0),
        "progress text names the grid (%r)" % {t for _, t in seen})

# An abort in a band ends the update with an empty output and one warning; an
# update that starts with the abort already set (as the GUI sets it again
# while the aborted Render lasts) returns its empty output at once and
# silently; the next update computes the whole terrain.
abort = T.AbortOnce(terrain)
said = T.ErrorCatcher(terrain, event="WarningEvent")
terrain.Modified()
terrain.Update()
abort.remove()
T.check(abort.hits == 1 and terrain.GetOutput().GetNumberOfPoints() == 0 and
        len(said.messages) == 1 and "aborted" in said.text(),
        "Procedural Terrain aborted in a band: empty, one warning (%r)" % said.messages)
said.clear()
# VTK 9.2's aborted-output protocol (SetAbortExecuteAndUpdateTime, the ABORTED
# flag) keeps an abort set before an update; VTK 9.1's executive clears it
# before RequestData, so there an update cannot begin aborted.
VTK92 = hasattr(terrain, "SetAbortExecuteAndUpdateTime")
if VTK92:
    terrain.SetAbortExecute(1)
    terrain.Modified()
    terrain.Update()
    T.check(terrain.GetOutput().GetNumberOfPoints() == 0 and not said.messages
            and not terrain.GetAbortExecute(),
            "an update begun aborted is empty at once, silently")
terrain.Update()
T.check(terrain.GetOutput().GetNumberOfPoints() == 2048 * 4096, "the next update is whole")

# ---- Rain Runoff: a simulation on a terrain too large --------------------------
small = terrain_image(64)
rain = vtkRainRunoffFilter()
rain.SetInputConnection(small.GetOutputPort())
rain.SetEndTime(10.0)
rain.SetOutputInterval(10.0)
rain.Update()
T.check(rain.GetOutputDataObject(0).GetNumberOfPoints() == 64 * 64, "Rain Runoff runs on 64 x 64")
big = terrain_image(4000)
rain.SetInputConnection(big.GetOutputPort())
m = refused(rain, "Rain Runoff", "a 4000 x 4000 grid", 2 * GB)
if m:
    T.check(float(m["need"]) > 2.0 and 250 <= int(m["per"]) <= 400,
            "Rain Runoff: the state, outputs and a checkpoint (%s GB, %s bytes a point)"
            % (m["need"], m["per"]))
rain.SetInputConnection(small.GetOutputPort())
limit(2 * GB)
rain.Update()
unlimit()
T.check(rain.GetOutputDataObject(0).GetNumberOfPoints() == 64 * 64,
        "Rain Runoff runs again on 64 x 64 under the limit")
_producers.remove(big)
del big

# ---- Terrain Analysis and Terrain Surface on a 3000 x 3000 terrain -----------
mid = terrain_image(3000)
analysis = vtkTerrainAnalysisFilter()
analysis.SetInputConnection(terrain_image(32).GetOutputPort())
analysis.Update()
analysis.SetInputConnection(mid.GetOutputPort())
# 37 bytes a point on the device, 33 of outputs.
refused(analysis, "Terrain Analysis", "a 3000 x 3000 grid", 0.4 * GB, need="630.0 MB", per=70)
surface = vtkTerrainSurfaceFilter()
surface.SetInputConnection(mid.GetOutputPort())
surface.SetMaximumPoints(0)  # every point
# A position (24), normal (12), quad (40), the display copy (4) and the
# input's elevation (4).
refused(surface, "Terrain Surface", "a 3000 x 3000 terrain", 0.4 * GB, need="756.0 MB", per=84)
# With the default MaximumPoints (2048 x 2048) it is drawn at every second
# point, 1501 x 1501, under the same limit.
surface.SetMaximumPoints(4194304)
limit(0.4 * GB)
surface.Update()
unlimit()
stride = surface.GetOutput().GetFieldData().GetArray("surface_stride")
T.check(stride is not None and stride.GetValue(0) == 2
        and surface.GetOutput().GetNumberOfPoints() == 1501 * 1501 + 4 * (1501 + 1501),
        "Terrain Surface draws the 3000 x 3000 terrain at every second point under the limit "
        "(%d points)" % surface.GetOutput().GetNumberOfPoints())
surface.SetMaximumPoints(0)
surface.SetInputConnection(terrain_image(100).GetOutputPort())
limit(0.4 * GB)
surface.Update()
unlimit()
T.check(surface.GetOutput().GetNumberOfPoints() >= 100 * 100, "Terrain Surface of 100 x 100 runs")

# Terrain Surface on 2000 x 2000 points: progress band by band with its
# text, and an abort there leaves an empty output; the next update is whole.
surface.SetInputConnection(terrain_image(2000).GetOutputPort())
seen = []
tag = surface.AddObserver(
    "ProgressEvent", lambda o, e: seen.append((o.GetProgress(), o.GetProgressText())))
abort = T.AbortOnce(surface)
surface.Update()
abort.remove()
surface.RemoveObserver(tag)
T.check(abort.hits == 1 and surface.GetOutput().GetNumberOfPoints() == 0,
        "Terrain Surface aborted in a band: empty")
T.check("Terrain Surface: 2000 x 2000 points" in {t for p, t in seen if p > 0.0},
        "Terrain Surface's progress names the grid (%r)" % {t for _, t in seen})
if not VTK92:
    surface.Modified()  # VTK 9.1 keeps an aborted output as if it were whole
surface.Update()
T.check(surface.GetOutput().GetNumberOfPoints() >= 2000 * 2000, "and then builds it")

# ---- Rain Particles: too many -------------------------------------------------
particles = vtkRainParticlesSource()
particles.Update()
particles.SetCount(1 << 24)
# Their outputs (40 bytes a particle) on the device and copied, and a
# vertex cell each (16).
refused(particles, "Rain Particles", "a set of 16777216 particles", 0.4 * GB, per=96)

T.finish()
