"""Strong scaling of Snow Deformation over MPI ranks (issue 11), for
RESULTS.md, not a test:

  xvfb-run -a mpiexec -n K pvbatch Testing/Benchmarks/mpi_scaling.py \\
      --plugin build/lib/paraview-5.11/plugins/Graupel/Graupel.so [--size N] [--steps S]

A sphere ploughs along the middle of an N x N snow field (the strips' edge
with 2 ranks) for S steps of 1/64 s after one output of warm-up (program
builds); prints the wall time of the timed update on rank 0 and, apart, the
time rank 0 spent in halo exchanges: reading its strips from the device
(which waits for the step's kernels queued before it), the messages with the
waiting for the neighbour, and writing its rings."""
import argparse
import time

p = argparse.ArgumentParser()
p.add_argument("--plugin", required=True)
p.add_argument("--size", type=int, default=512)
p.add_argument("--steps", type=int, default=64)  # a multiple of 4
a, _ = p.parse_known_args()

from paraview import servermanager  # noqa: E402
from paraview.simple import *  # noqa: E402,F401,F403

LoadPlugin(a.plugin, ns=globals())
ranks = servermanager.vtkProcessModule.GetProcessModule().GetNumberOfLocalPartitions()
N, DX, STEP = a.size, 0.05, 1.0 / 64.0
warm = 4 * STEP
terrain = ProceduralTerrain(Dimensions=[N, N], Spacing=DX, Seed=5, HeightScale=0.3)
ball = Sphere(Center=[2.0, 0.5 * (N - 1) * DX, 0.6], Radius=0.4, ThetaResolution=48,
              PhiResolution=48)
snow = SnowDeformation(Input=terrain, Objects=ball, ObjectVelocity=[2.0, 0.0, 0.0],
                       TimeStep=STEP, EndTime=warm + a.steps * STEP,
                       OutputInterval=warm, CheckpointInterval=0)
snow.UpdatePipeline(0.0)
snow.UpdatePipeline(warm)  # not timed: the device programs are built here
t0 = time.perf_counter()
snow.UpdatePipeline(warm + a.steps * STEP)
wall = time.perf_counter() - t0
f = snow.GetClientSideObject()
share = snow.FieldData["piece_cells"].GetRange()
h = [1e3 * f.GetHaloExchangeSeconds(k) / a.steps for k in range(4)]
print("mpi_scaling: %d rank(s), %d x %d, %d steps: %.2f ms a step; halo exchange %.2f ms a step "
      "on rank 0 (strips from the device, waiting for its kernels, %.2f; messages and waiting for "
      "the neighbour %.2f; rings to the device %.2f; %d exchanges); piece_cells %.0f-%.0f of %d; "
      "relax_iterations %g"
      % (ranks, N, N, a.steps, 1e3 * wall / a.steps, h[0], h[1], h[2], h[3],
         f.GetHaloExchangeCount(), share[0], share[1], N * N,
         snow.FieldData["relax_iterations"].GetRange()[1]))
