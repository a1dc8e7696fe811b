"""Long use in one process, through the VTK layer: Rain Runoff (64 x 64) and
Snow Deformation (a sphere through snow, 48 x 48) scrubbed back and forth
over their output times in a random order, N requests in all, with their
in-memory checkpoints on (every 3 outputs, within 4 MiB). Every time asked
again must give the bits of its first visit, and resident memory must stay
flat: between the end of the first tenth of the requests and the end, it
may grow by at most 8 MiB (the allocator's slack), not by a checkpoint a
request.

    pvpython test_scrub.py --data D --scratch S [--requests N] [--seed K]

The test form makes 600 requests; `./graupel.sh soak` 10 000."""
import os
import random
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402


def extra(p):
    p.add_argument("--requests", type=int, default=600)
    p.add_argument("--seed", type=int, default=3)


a = T.args(extra)

from vtkmodules.vtkFiltersSources import vtkSphereSource  # noqa: E402

from graupel import (  # noqa: E402
    vtkProceduralTerrainSource,
    vtkRainRunoffFilter,
    vtkSnowDeformationFilter,
)


def rss_kib():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    return 0


def terrain(n, seed):
    t = vtkProceduralTerrainSource()
    t.SetDimensions(n, n)
    t.SetSpacing(1.0)
    t.SetSeed(seed)
    t.SetHeightScale(8.0)
    return t


# The sources are kept: a vtkAlgorithmOutput does not hold its producer.
ground = [terrain(64, 1), terrain(48, 2)]
rain = vtkRainRunoffFilter()
rain.SetInputConnection(ground[0].GetOutputPort())
rain.SetRainRate(80.0)
rain.SetEndTime(300.0)
rain.SetOutputInterval(10.0)
sphere = vtkSphereSource()
sphere.SetRadius(3.0)
sphere.SetCenter(10.0, 24.0, 2.0)
snow = vtkSnowDeformationFilter()
snow.SetInputConnection(ground[1].GetOutputPort())
snow.SetObjectsConnection(sphere.GetOutputPort())
snow.SetInitialSnowDepth(0.4)
snow.SetObjectVelocity(4.0, 0.0, -1.0)
snow.SetEndTime(6.0)
snow.SetOutputInterval(0.25)
sims = [(rain, [10.0 * k for k in range(31)], ("water_depth", "discharge")),
        (snow, [0.25 * k for k in range(25)], ("snow_depth", "snow_density"))]
for sim, _, _ in sims:
    sim.SetCheckpointInterval(3)
    sim.SetCheckpointMemoryLimit(4)


digest = T.digest


rng = random.Random(a.seed)
first = [{}, {}]
differ = 0
mark = None
for k in range(a.requests):
    which = rng.randrange(2)
    sim, times, names = sims[which]
    t = rng.choice(times)
    d = digest(sim, t, names)
    if t in first[which]:
        differ += int(first[which][t] != d)
    else:
        first[which][t] = d
    if k + 1 == max(1, a.requests // 10):
        mark = rss_kib()
end = rss_kib()
print("%d requests: %d and %d times visited, resident %d -> %d KiB; restores %d and %d, "
      "set-ups %d and %d" % (a.requests, len(first[0]), len(first[1]), mark, end,
                             rain.GetRestoreCount(), snow.GetRestoreCount(),
                             rain.GetRestartCount(), snow.GetRestartCount()))
T.check(differ == 0, "every revisited time gives its first visit's bits (%d differ)" % differ)
T.check(len(first[0]) > 20 and len(first[1]) > 15, "most times were visited")
T.check(rain.GetRestoreCount() > 0 and snow.GetRestoreCount() > 0,
        "going back used the checkpoints (%d, %d)" % (rain.GetRestoreCount(),
                                                      snow.GetRestoreCount()))
T.check(end - mark <= 8192, "resident memory flat: %+d KiB after the first tenth" % (end - mark))
T.finish()
