"""Strong scaling of the simulations over MPI ranks, for
RESULTS.md, not a test:

  PYTHONPATH=build/lib/python3/site-packages \\
  xvfb-run -a mpiexec -n K pvbatch Testing/Benchmarks/mpi_scaling.py \\
      --plugin build/lib/paraview-5.11/plugins/Graupel/Graupel.so [--size N] [--steps S]
      [--simulation snow_deformation|rain_runoff|snow_accumulation|water_surface]

snow_deformation (the default): a sphere ploughs along the middle of an N x N
snow field (the strips' edge with 2 ranks) for S steps of 1/64 s;
rain_runoff: 40 mm/h on a procedural terrain of N x N points 5 m apart (the
shallow-water model; S outputs of 10 s); snow_accumulation: tilted snow over
the same terrain at 0.1 m, a box across the strips' edge (S steps of 300 s);
water_surface: a lake with raindrops (S outputs of 1 s). Each after one output of
warm-up (program builds); prints the wall time of the timed update on rank 0 and, apart, the
time rank 0 spent in halo exchanges: reading its strips from the device
(which waits for the step's kernels queued before it), the messages with the
waiting for the neighbour, and writing its rings."""
import argparse
import time

p = argparse.ArgumentParser()
p.add_argument("--plugin", required=True)
p.add_argument("--size", type=int, default=512)
p.add_argument("--steps", type=int, default=64)  # a multiple of 4
p.add_argument("--simulation", default="snow_deformation",
               choices=["snow_deformation", "rain_runoff", "snow_accumulation", "water_surface"])
a, _ = p.parse_known_args()

from paraview import servermanager  # noqa: E402
from paraview.simple import *  # noqa: E402,F401,F403

LoadPlugin(a.plugin, ns=globals())
import graupel  # noqa: E402,F401 (the filters' own Python classes, for the halo timing calls)
ranks = servermanager.vtkProcessModule.GetProcessModule().GetNumberOfLocalPartitions()
N = a.size
if a.simulation == "snow_deformation":
    DX, STEP = 0.05, 1.0 / 64.0
    terrain = ProceduralTerrain(Dimensions=[N, N], Spacing=DX, Seed=5, HeightScale=0.3)
    ball = Sphere(Center=[2.0, 0.5 * (N - 1) * DX, 0.6], Radius=0.4, ThetaResolution=48,
                  PhiResolution=48)
    make = lambda end, out: SnowDeformation(  # noqa: E731
        Input=terrain, Objects=ball, ObjectVelocity=[2.0, 0.0, 0.0], TimeStep=STEP,
        EndTime=end, OutputInterval=out, CheckpointInterval=0)
elif a.simulation == "rain_runoff":
    STEP = 10.0
    terrain = ProceduralTerrain(Dimensions=[N, N], Spacing=5.0, Seed=7, HeightScale=20.0)
    make = lambda end, out: RainRunoff(  # noqa: E731
        Input=terrain, RainRate=40.0, EndTime=end, OutputInterval=out, CheckpointInterval=0)
elif a.simulation == "snow_accumulation":
    STEP = 300.0
    terrain = ProceduralTerrain(Dimensions=[N, N], Spacing=0.1, Seed=11, Frequency=300.0,
                                HeightScale=2.5)
    box = Box(Center=[0.05 * (N - 1), 0.05 * (N - 1), 2.2], XLength=1.6, YLength=2.4,
              ZLength=0.6)
    make = lambda end, out: SnowAccumulation(  # noqa: E731
        Input=terrain, Objects=box, SnowDirection=[0.3, 1.0, -1.0], Flutter=3.0,
        SnowfallRate=8.0, TimeStep=STEP, EndTime=end, OutputInterval=out, CheckpointInterval=0)
else:
    STEP = 1.0
    terrain = ProceduralTerrain(Dimensions=[N, N], Spacing=1.0, Seed=9, HeightScale=4.0)
    make = lambda end, out: WaterSurface(  # noqa: E731
        Input=terrain, UseLakeLevel=1, LakeLevel=2.0, DropRate=0.05, DropAmplitude=0.01,
        DropRadius=0.5, Seed=3, EndTime=end, OutputInterval=out, CheckpointInterval=0)
warm = 4 * STEP
sim = make(warm + a.steps * STEP, warm)
sim.UpdatePipeline(0.0)
sim.UpdatePipeline(warm)  # not timed: the device programs are built here
t0 = time.perf_counter()
sim.UpdatePipeline(warm + a.steps * STEP)
wall = time.perf_counter() - t0
f = sim.GetClientSideObject()
share = sim.FieldData["piece_cells"].GetRange()
h = [1e3 * f.GetHaloExchangeSeconds(k) / a.steps for k in range(4)]
extra = ("; relax_iterations %g" % sim.FieldData["relax_iterations"].GetRange()[1]
         if a.simulation == "snow_deformation" else "")
print("mpi_scaling: %s, %d rank(s), %d x %d, %d steps: %.2f ms a step; halo exchange %.2f ms "
      "a step on rank 0 (strips from the device, waiting for its kernels, %.2f; messages and "
      "waiting for the neighbour %.2f; rings to the device %.2f; %d exchanges); piece_cells "
      "%.0f-%.0f of %d%s"
      % (a.simulation, ranks, N, N, a.steps, 1e3 * wall / a.steps, h[0], h[1], h[2], h[3],
         f.GetHaloExchangeCount(), share[0], share[1], N * N, extra))
