"""Long use in one process, through the VTK layer: every simulation of the
module that steps through time (every vtkGraupelSimulation: Rain Runoff,
Snow Deformation, Snow Accumulation, Snow Melt, Water Surface), each also
with the inputs it can follow in time, scrubbed back and forth over its
output times in a random order, N requests in all spread evenly over them:

  rain_sw             Rain Runoff, FlowModel 0 (shallow water), 48 x 48,
                      two gauges (the Hydrograph on port 1)
  rain_li             Rain Runoff, FlowModel 1 (local inertial), 40 x 40, a
                      gauge, a west edge hydrograph and a point inflow with
                      time steps of its own (a temporal input)
  deformation         Snow Deformation, a sphere dragged through snow, 40 x 40
  deformation_steps   Snow Deformation, a sphere with time steps of its own
  accumulation        Snow Accumulation, snowfall with noise on a terrain and
                      a moving box that carries its snow, 32 x 32
  accumulation_steps  Snow Accumulation, a crate with time steps of its own
  melt                Snow Melt, sun, shadows and a Forcing table of warm,
                      freezing and rainy days, 32 x 32
  melt_frames         Snow Melt, per-point forcing from a temporal Input
                      (FollowInputTime), 24 x 24
  water               Water Surface, a lake with raindrop ripples, 48 x 48
  melt_runoff         Rain Runoff following Snow Melt (FollowInputTime,
                      RainFrames 1), 24 x 24
  runoff_water        Water Surface following Rain Runoff's water, 32 x 32

Each has its in-memory checkpoints on, every 3 outputs, with
CheckpointMemoryLimit set (from the size of its first checkpoint) to hold
3.5 of them, fewer than the run makes: the ring is full and drops its
oldest all along. Checked:

  * every time asked again gives the bits of its first visit, and every
    time visited those of a forward run of a fresh filter: every point,
    cell, field (the ledger) and row array and the objects' points on every
    output port (gr_check.digest_all);
  * after every request the ring holds at most GetCheckpointMemoryLimitBytes()
    (GetCheckpointBytes()), and at most 3 checkpoints; going back used them;
  * resident memory is flat: from the request after the first tenth at which
    every ring is full to the end it may grow by at most 4 MiB, the
    allocator's and the OpenCL runtime's slack (a few hundred KiB seen). A
    leak of one output (4 KiB an array and up) or one checkpoint (8 KiB and
    up) a request of one simulation exceeds it in the soak (9 000 requests,
    800 of each simulation); in the test form a leak of 8 KiB every request.

Going back to a checkpoint's own time showed, with an input followed in
time, that input's later time step (the objects') or the last one read
(Water Surface's water), and a Water Surface reset to time 0 the last water
read: deformation_steps, accumulation_steps and runoff_water pin the fixes
(vtkGraupelSimulation steps into such a time; vtkWaterSurfaceFilter reads
the water again at a reset).

    pvpython test_scrub.py --data D --scratch S [--requests N] [--seed K]
                           [--only NAME,...]

The test form makes 600 requests; `./graupel.sh soak` 10 000."""
import os
import random
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402


def extra(p):
    p.add_argument("--requests", type=int, default=600)
    p.add_argument("--seed", type=int, default=3)
    p.add_argument("--only", default="")


a = T.args(extra)

import numpy as np  # noqa: E402
from vtkmodules.util.numpy_support import numpy_to_vtk  # noqa: E402
from vtkmodules.vtkCommonCore import vtkFloatArray, vtkPoints  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkPolyData  # noqa: E402
from vtkmodules.vtkCommonExecutionModel import (  # noqa: E402
    vtkStreamingDemandDrivenPipeline as SDDP,
    vtkTrivialProducer,
)
from vtkmodules.vtkFiltersSources import vtkCubeSource, vtkSphereSource  # noqa: E402

from gr_timed import TimedSource  # noqa: E402
from graupel import (  # noqa: E402
    vtkProceduralTerrainSource,
    vtkRainRunoffFilter,
    vtkSnowAccumulationFilter,
    vtkSnowDeformationFilter,
    vtkSnowMeltFilter,
    vtkWaterSurfaceFilter,
)

HOUR = 3600.0
_keep = []  # a vtkAlgorithmOutput does not hold its producer


def rss_kib():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    return 0


def terrain(n, seed, spacing=1.0, height=8.0):
    t = vtkProceduralTerrainSource()
    t.SetDimensions(n, n)
    t.SetSpacing(spacing)
    t.SetSeed(seed)
    t.SetHeightScale(height)
    _keep.append(t)
    return t.GetOutputPort()


def producer(data):
    p = vtkTrivialProducer()
    p.SetOutput(data)
    _keep.append(p)
    return p.GetOutputPort()


def points(xy, discharge=None):
    pts = vtkPoints()
    for x, y in xy:
        pts.InsertNextPoint(x, y, 0.0)
    pd = vtkPolyData()
    pd.SetPoints(pts)
    if discharge is not None:
        q = vtkFloatArray()
        q.SetName("discharge")
        for v in discharge:
            q.InsertNextValue(v)
        pd.GetPointData().AddArray(q)
    return pd


def table(columns):
    return producer(T.table(columns))


class Steps(TimedSource):
    """A source with time steps TIMES whose output at step k is make(k); it
    keeps no record of the times asked (the soak asks hundreds of thousands)."""

    def __init__(self, times, make, output_type="vtkPolyData", image=None):
        TimedSource.__init__(self, output_type)
        self.TIMES, self.make, self.image = list(times), make, image
        _keep.append(self)

    def RequestInformation(self, request, inInfo, outInfo):
        TimedSource.RequestInformation(self, request, inInfo, outInfo)
        if self.image:  # (nx, ny, spacing)
            nx, ny, dx = self.image
            info = outInfo.GetInformationObject(0)
            info.Set(SDDP.WHOLE_EXTENT(), (0, nx - 1, 0, ny - 1, 0, 0), 6)
            info.Set(vtkImageData.SPACING(), (dx, dx, 1.0), 3)
            info.Set(vtkImageData.ORIGIN(), (0.0, 0.0, 0.0), 3)
        return 1

    def RequestData(self, request, inInfo, outInfo):
        t = self.requested_time(outInfo)
        del self.requested[:]
        k = max(i for i, tk in enumerate(self.TIMES) if tk <= t + 1e-9)
        out = outInfo.GetInformationObject(0).Get(vtkImageData.DATA_OBJECT())
        out.ShallowCopy(self.make(k))
        out.GetInformation().Set(out.DATA_TIME_STEP(), self.TIMES[k])
        return 1


def sphere(centre, radius):
    s = vtkSphereSource()
    s.SetRadius(radius)
    s.SetCenter(*centre)
    s.Update()
    return s.GetOutput()


def cube(bounds):
    c = vtkCubeSource()
    c.SetBounds(*bounds)
    c.Update()
    return c.GetOutput()


def rain_sw():
    r = vtkRainRunoffFilter()
    r.SetInputConnection(terrain(48, 1))
    r.SetGaugesConnection(producer(points([(10.0, 10.0), (30.0, 24.0)])))
    r.SetFlowModel(0)
    r.SetRainRate(80.0)
    r.SetEndTime(300.0)
    r.SetOutputInterval(10.0)
    return r


def rain_li():
    """Local inertial flow, a west edge hydrograph and a river's point inflow
    with time steps of its own (a temporal input) that walks downstream."""
    river = Steps([0.0, 40.0, 80.0, 160.0, 200.0],
                  lambda k: points([(5.0 + 4.0 * k, 20.0)], [[0.5, 1.0, 0.0, 2.0, 0.3][k]]))
    r = vtkRainRunoffFilter()
    r.SetInputConnection(terrain(40, 4))
    r.SetGaugesConnection(producer(points([(20.0, 20.0)])))
    r.SetInflowsConnection(river.GetOutputPort())
    r.SetFlowModel(1)
    r.SetRainRate(60.0)
    r.AddInflowWest(0.0, 0.0)
    r.AddInflowWest(120.0, 2.0)
    r.AddInflowWest(240.0, 0.5)
    r.SetEndTime(300.0)
    r.SetOutputInterval(10.0)
    return r


def deformation():
    s = vtkSnowDeformationFilter()
    s.SetInputConnection(terrain(40, 2))
    s.SetObjectsConnection(producer(sphere((8.0, 20.0, 2.0), 3.0)))
    s.SetInitialSnowDepth(0.4)
    s.SetObjectVelocity(4.0, 0.0, -1.0)
    s.SetEndTime(6.0)
    s.SetOutputInterval(0.25)
    return s


def deformation_steps():
    """Objects with time steps of their own (every 0.5 s, every other
    output time): a sphere that jumps along and sinks."""
    ball = Steps([0.5 * k for k in range(13)],
                 lambda k: sphere((8.0 + 2.0 * k, 20.0, 2.0 - 0.25 * k), 3.0))
    s = vtkSnowDeformationFilter()
    s.SetInputConnection(terrain(40, 3))
    s.SetObjectsConnection(ball.GetOutputPort())
    s.SetInitialSnowDepth(0.4)
    s.SetEndTime(6.0)
    s.SetOutputInterval(0.25)
    return s


def accumulation():
    s = vtkSnowAccumulationFilter()
    s.SetInputConnection(terrain(32, 5, spacing=1.0, height=3.0))
    s.SetObjectsConnection(producer(cube((4.0, 8.0, 12.0, 18.0, 0.0, 3.0))))
    s.SetObjectVelocity(0.002, 0.0, 0.0)
    s.SetSnowfallRate(4.0)
    s.SetSnowDirection(0.3, 0.1, -1.0)
    s.SetNoiseAmplitude(0.3)
    s.SetSeed(9)
    s.SetExposureResolution(64)
    s.SetTimeStep(600.0)
    s.SetEndTime(6 * HOUR)
    s.SetOutputInterval(0.25 * HOUR)
    return s


def accumulation_steps():
    """A crate with time steps of its own (hourly, every fourth output
    time), moved 3 m each hour."""
    crate = Steps([HOUR * k for k in range(7)],
                  lambda k: cube((4.0 + 3.0 * k, 8.0 + 3.0 * k, 12.0, 18.0, 0.0, 3.0)))
    s = vtkSnowAccumulationFilter()
    s.SetInputConnection(terrain(32, 10, spacing=1.0, height=3.0))
    s.SetObjectsConnection(crate.GetOutputPort())
    s.SetSnowfallRate(4.0)
    s.SetNoiseAmplitude(0.3)
    s.SetSeed(4)
    s.SetExposureResolution(64)
    s.SetTimeStep(600.0)
    s.SetEndTime(6 * HOUR)
    s.SetOutputInterval(0.25 * HOUR)
    return s


def melt():
    s = vtkSnowMeltFilter()
    s.SetInputConnection(terrain(32, 6, spacing=10.0, height=60.0))
    s.SetInputConnection(1, table({
        "time": [0.0, 20 * HOUR, 44 * HOUR, 60 * HOUR],
        "air_temperature": [4.0, -6.0, 1.5, 7.0],
        "precipitation": [0.0, 1.0, 3.0, 0.0]}))
    s.SetInitialSnowDepth(0.6)
    s.SetLatitude(46.0)
    s.SetStartDayOfYear(100)
    s.SetCastShadows(1)
    s.SetEndTime(96 * HOUR)
    s.SetOutputInterval(3 * HOUR)
    return s


def weather(k, n=24, dx=10.0):
    """Frame k of a weather model: heights and per-point forcing."""
    img = vtkImageData()
    img.SetDimensions(n, n, 1)
    img.SetSpacing(dx, dx, 1.0)
    j, i = np.mgrid[0:n, 0:n]
    for name, v in (("elevation", 3.0 * i + 2.0 * j),
                    ("air_temperature", [3.0, -4.0, 6.0, 1.0][k % 4] + 0.1 * i),
                    ("precipitation", np.full((n, n), [0.0, 2.0, 0.5, 0.0][k % 4]))):
        arr = numpy_to_vtk(np.ascontiguousarray(v, dtype=np.float32).reshape(-1), deep=1)
        arr.SetName(name)
        img.GetPointData().AddArray(arr)
    return img


def melt_frames():
    """Per-point forcing from a temporal Input (FollowInputTime), a frame
    every 6 h (every other output time)."""
    frames = Steps([6 * HOUR * k for k in range(9)], weather, "vtkImageData", (24, 24, 10.0))
    s = vtkSnowMeltFilter()
    s.SetInputConnection(frames.GetOutputPort())
    s.SetFollowInputTime(1)
    s.SetInitialSnowDepth(0.6)
    s.SetEndTime(48 * HOUR)
    s.SetOutputInterval(3 * HOUR)
    return s


def water():
    w = vtkWaterSurfaceFilter()
    w.SetInputConnection(terrain(48, 7, height=4.0))
    w.SetUseLakeLevel(1)
    w.SetLakeLevel(2.5)
    w.SetDropRate(0.5)
    w.SetDropAmplitude(0.01)
    w.SetDropRadius(1.0)
    w.SetSeed(3)
    w.SetEndTime(12.0)
    w.SetOutputInterval(0.5)
    return w


def melt_runoff():
    """Rain Runoff following Snow Melt in time (FollowInputTime, RainFrames
    1); the upstream keeps checkpoints of its own."""
    m = vtkSnowMeltFilter()
    m.SetInputConnection(terrain(24, 8, spacing=10.0, height=30.0))
    m.SetInitialSnowDepth(0.4)
    m.SetAirTemperature(6.0)
    m.SetMeltFactor(4.0)
    m.SetEndTime(6 * HOUR)
    m.SetOutputInterval(0.25 * HOUR)
    m.SetCheckpointInterval(4)
    _keep.append(m)
    r = vtkRainRunoffFilter()
    r.SetInputConnection(m.GetOutputPort())
    r.SetFollowInputTime(1)
    r.SetRainFrames(1)
    r.SetRainRate(0.0)
    r.SetEndTime(6 * HOUR)
    r.SetOutputInterval(0.25 * HOUR)
    return r


def runoff_water():
    """Water Surface following Rain Runoff's water in time (FollowInputTime,
    a time step every other output time)."""
    r = vtkRainRunoffFilter()
    r.SetInputConnection(terrain(32, 9, height=3.0))
    r.SetRainRate(400.0)
    r.SetEndTime(12.0)
    r.SetOutputInterval(1.0)
    r.SetCheckpointInterval(4)
    _keep.append(r)
    w = vtkWaterSurfaceFilter()
    w.SetInputConnection(r.GetOutputPort())
    w.SetFollowInputTime(1)
    w.SetWetDepth(0.001)
    w.SetDropRate(0.5)
    w.SetEndTime(12.0)
    w.SetOutputInterval(0.5)
    return w


makers = [("rain_sw", rain_sw), ("rain_li", rain_li), ("deformation", deformation),
          ("deformation_steps", deformation_steps), ("accumulation", accumulation),
          ("accumulation_steps", accumulation_steps), ("melt", melt),
          ("melt_frames", melt_frames), ("water", water), ("melt_runoff", melt_runoff),
          ("runoff_water", runoff_water)]
if a.only:
    makers = [(n, m) for n, m in makers if n in a.only.split(",")]

INTERVAL, HELD = 3, 3.5  # a checkpoint every 3 outputs; the limit holds 3.5 of them


class Sim:
    def __init__(self, name, alg):
        self.name, self.alg = name, alg
        alg.UpdateInformation()
        n = alg.GetNumberOfOutputTimes()
        self.times = [alg.GetOutputTime(k) for k in range(n)]
        # The size of one checkpoint, from the first: the limit is set to
        # hold HELD of them, fewer than the run makes, so that the ring is
        # full and drops its oldest all along.
        alg.SetCheckpointInterval(INTERVAL)
        alg.UpdateTimeStep(self.times[INTERVAL])
        self.size = alg.GetCheckpointBytes()
        self.slots = (n - 1) // INTERVAL
        alg.SetCheckpointMemoryLimit(HELD * self.size / 1048576.0)
        self.first = {}
        self.requests = self.revisits = self.differ = 0
        self.over = 0        # requests after which the ring held more than the limit
        self.most = 0        # most checkpoints held
        self.most_bytes = 0  # most bytes held
        self.restores0 = alg.GetRestoreCount()
        self.restarts0 = alg.GetRestartCount()
        self.seconds = 0.0

    def request(self, t):
        start = time.process_time()
        d = T.digest_all(self.alg, t)
        self.seconds += time.process_time() - start
        self.requests += 1
        if t in self.first:
            self.revisits += 1
            if self.first[t] != d:
                self.differ += 1
                if self.differ <= 3:
                    print("%s: t = %g differs from its first visit" % (self.name, t))
        else:
            self.first[t] = d
        held = self.alg.GetCheckpointBytes()
        self.over += int(held > self.alg.GetCheckpointMemoryLimitBytes())
        self.most = max(self.most, self.alg.GetNumberOfCheckpoints())
        self.most_bytes = max(self.most_bytes, held)


sims = [Sim(name, make()) for name, make in makers]
rng = random.Random(a.seed)
mark = None  # (request, resident KiB) once past the first tenth with every ring full
peak = 0
wall, cpu = time.perf_counter(), time.process_time()
for k in range(a.requests):
    sim = sims[rng.randrange(len(sims))]
    sim.request(rng.choice(sim.times))
    if mark is not None:
        peak = max(peak, rss_kib())
    elif k + 1 >= max(1, a.requests // 10) and all(s.most == int(HELD) for s in sims):
        mark = (k + 1, rss_kib())
        peak = mark[1]
end = rss_kib()
wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
if mark is None:
    mark = (a.requests, end)
    peak = end

# A forward run of a fresh filter at every time visited, in order.
for s in sims:
    fresh = dict(makers)[s.name]()
    s.forward_differ = [t for t in sorted(s.first) if T.digest_all(fresh, t) != s.first[t]]
    del fresh

print("%d requests in %.1f s (%.1f s of CPU); resident %d KiB after request %d (the rings "
      "full, limits %.0f KiB in all), at most %d, at the end %d: %+d KiB"
      % (a.requests, wall, cpu, mark[1], mark[0],
         sum(s.alg.GetCheckpointMemoryLimitBytes() for s in sims) / 1024.0, peak, end,
         peak - mark[1]))
print("%-18s %5s %6s %8s %5s %8s %8s %9s %9s %8s %6s" % (
    "simulation", "times", "asked", "revisits", "diff", "restores", "set-ups", "ckpt KiB",
    "limit KiB", "most", "CPU s"))
for s in sims:
    alg = s.alg
    print("%-18s %5d %6d %8d %5d %8d %8d %9.1f %9.1f %5d/%-2d %6.1f" % (
        s.name, len(s.times), s.requests, s.revisits, s.differ,
        alg.GetRestoreCount() - s.restores0, alg.GetRestartCount() - s.restarts0,
        s.size / 1024.0, alg.GetCheckpointMemoryLimitBytes() / 1024.0, s.most, s.slots,
        s.seconds))

for s in sims:
    alg = s.alg
    T.check(s.size > 0, "%s keeps checkpoints in memory (%d bytes each)" % (s.name, s.size))
    T.check(s.differ == 0, "%s: every revisited time gives its first visit's bits "
            "(%d of %d revisits differ)" % (s.name, s.differ, s.revisits))
    T.check(not s.forward_differ, "%s: every time visited gives a fresh forward run's bits "
            "(differ at %r)" % (s.name, s.forward_differ))
    T.check(len(s.first) > 0.7 * len(s.times) and s.revisits > 0,
            "%s: most times visited (%d of %d), some again (%d)"
            % (s.name, len(s.first), len(s.times), s.revisits))
    T.check(s.over == 0 and s.most_bytes <= alg.GetCheckpointMemoryLimitBytes(),
            "%s: the checkpoint ring within CheckpointMemoryLimit (at most %d of %d bytes; "
            "over after %d requests)" % (s.name, s.most_bytes,
                                         alg.GetCheckpointMemoryLimitBytes(), s.over))
    T.check(s.most == int(HELD) and s.most < s.slots,
            "%s: the ring full at %d checkpoints of the %d the run makes (%d)"
            % (s.name, int(HELD), s.slots, s.most))
    T.check(alg.GetRestoreCount() > s.restores0,
            "%s: going back used the checkpoints (%d restores)"
            % (s.name, alg.GetRestoreCount() - s.restores0))
T.check(peak - mark[1] <= 4096, "resident memory flat: %+d KiB from request %d on (at most 4 MiB)"
        % (peak - mark[1], mark[0]))
T.finish()
