#!/usr/bin/env python3
"""Rain Runoff side by side with its peers on the real DEM.

The scenario, the same for all three: Data/jacksboro_fault_dem.exr (403 x 344
points, 74.5 m east-west, 92.1 m north-south), 3 h of 50 mm/h rain on sealed
ground (no infiltration), Manning n 0.03, water leaving through every edge,
the depth recorded every 30 min.

- Graupel: vtkRainRunoffFilter, the user-facing VTK module (plain python3 on
  Debian's VTK, from the `vtk` preset's build tree) or the plugin's
  (pvpython), both FlowModels; timed apart: the import, reading the EXR,
  the set-up (UpdateTimeStep(0): OpenCL context, program build, upload), the
  run (UpdateTimeStep(end): the steps, the ledger at each output time and the
  output's read-back) and the steps taken. Once with PoCL's kernel cache
  emptied (the first run on a machine) and then warm.
- GRASS GIS r.sim.water (Debian's grass-core) in a temporary UTM 16N location with
  the DEM's rows, columns and resolutions; dx and dy from r.slope.aspect
  (timed apart), rain_value 50, infil_value 0, man_value 0.03, niterations
  180, output_step 30 with -t, a fixed random_seed, nprocs = the cores.
- ANUGA (the same physics as FlowModel 0: the 2-D shallow-water equations by
  finite volumes, second order) on Graupel's cells: a mesh whose vertices are
  the cells' corners, each cell (centred on a DEM point) cut into two
  triangles that take its elevation (flat, as Graupel's cell is; a mesh on the
  points themselves smooths each one-point pit into its six triangles), a
  Rate_operator for the rain, Manning friction, on every edge a dry outfall
  (a Dirichlet boundary whose stage lies below every bed, with no momentum:
  water leaves where it flows out and none comes in, as at Graupel's open
  edge), its default flow algorithm
  unless --anuga-algorithm says otherwise; a cell's depth is the mean of its
  two triangles'.
- Landlab's OverlandFlow (de Almeida et al. 2012, the scheme of FlowModel 1)
  on a RasterModelGrid with the DEM's own spacings (xy_spacing=(74.5, 92.1):
  Landlab's raster grid allows rectangular cells; its step uses the shorter;
  --square takes the mean spacing instead), steep_slopes on, its own adaptive
  step through run_one_step(output interval).

Agreement: Pearson's r of the final depth fields against each Graupel run
(on the common grid: all points, and the points wet in either), and the
stored and outflow volumes (outflow = rain - stored where a peer keeps no
ledger). Times: each run's wall clock and the CPU seconds of its process and
all it waited for (on a shared machine they move less with the load).

    python3 Testing/Benchmarks/peers.py --install --build build-vtk  # as root
    python3 Testing/Benchmarks/peers.py --build build-vtk            # the `vtk` preset's tree
    python3 Testing/Benchmarks/peers.py --build build-vtk --out /tmp/peers  # + depth fields
    python3 Testing/Benchmarks/peers.py --build build-vtk --profile  # where Graupel's time goes

`--only graupel,grass,landlab,anuga` picks runs (ANUGA, whose run takes the longest, only when
named); `--core-lib DIR` runs Graupel with the core library in DIR (a `core` preset's
build-core/kernels) in place of the build tree's; `--hours`, `--rain`, `--manning`,
`--max-time-step` change the scenario (MaxTimeStep is Graupel's; its default, 3600 s, is no
cap). Not part of the test command: its figures go in RESULTS.md.
"""
import argparse
import glob
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
DEM = os.path.join(ROOT, "Data", "jacksboro_fault_dem.exr")
MM_PER_H = 1.0 / 3.6e6  # m/s


def log(*a):
    print(*a, file=sys.stderr, flush=True)


# ---------------------------------------------------------------- install

def install_anuga(venv):
    """ANUGA from PyPI (a wheel for Python 3.11) into a venv of its own."""
    py = os.path.join(venv, "bin", "python3")
    if not os.path.exists(py):
        subprocess.check_call([sys.executable, "-m", "venv", venv])
    subprocess.check_call([py, "-m", "pip", "install", "-q", "anuga"])


def install(venv):
    """grass-core from Debian (as root), landlab from PyPI into a venv of its
    own: landlab pulls a numpy 2 that Debian's VTK 9.1 must not see."""
    if shutil.which("grass") is None:
        run = [] if os.geteuid() == 0 else ["sudo"]
        subprocess.check_call(run + ["apt-get", "update", "-q"])
        subprocess.check_call(run + ["env", "DEBIAN_FRONTEND=noninteractive", "apt-get",
                                     "install", "-y", "-q", "--no-install-recommends",
                                     "grass-core"])
    py = os.path.join(venv, "bin", "python3")
    if not os.path.exists(py):
        subprocess.check_call([sys.executable, "-m", "venv", venv])
    # landlab 2.10 on needs requireit, written for Python 3.12 (PEP 695). 2.9
    # calls np.intersect1d on the links every step, which numpy 2.3's hashed
    # unique makes 10 times slower (0.9 of 1.1 s a step here): numpy 2.2.
    spec = ["landlab"] if sys.version_info >= (3, 12) else ["landlab<2.10", "numpy<2.3"]
    subprocess.check_call([py, "-m", "pip", "install", "-q"] + spec)


# ---------------------------------------------------------------- workers

def read_dem(a):
    """The DEM worker_dem wrote: its elevations (row 0 south) and spacings."""
    import numpy as np
    dem = np.load(os.path.join(a.work, "dem.npz"))
    return dem["elevation"], float(dem["dx"]), float(dem["dy"])


def save(a, res, depth):
    """A worker's result: its figures (RESULT.json) and final depths (RESULT.npz)."""
    import numpy as np
    np.savez(a.result + ".npz", depth=depth)
    with open(a.result + ".json", "w") as fp:
        json.dump(res, fp)


def worker_dem(a):
    """Reads the EXR with Graupel's reader and writes dem.npz (row 0 south)."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from graupel import vtkEXRHeightFieldReader
    import numpy as np
    r = vtkEXRHeightFieldReader()
    r.SetFileName(DEM)  # the file holds the spacing, 74.5 x 92.1 m (Data/README.md)
    r.Update()
    img = r.GetOutput()
    nx, ny, _ = img.GetDimensions()
    sp = img.GetSpacing()
    if sp[:2] == (1.0, 1.0):
        sys.exit("dem: %s holds no spacing (an old copy of Data/?)" % DEM)
    z = vtk_to_numpy(img.GetPointData().GetArray("elevation")).reshape(ny, nx).astype(np.float64)
    np.savez(os.path.join(a.work, "dem.npz"), elevation=z, dx=sp[0], dy=sp[1])
    log("dem: %d x %d points, spacing %.1f x %.1f m, %.0f..%.0f m"
        % (nx, ny, sp[0], sp[1], z.min(), z.max()))


def worker_graupel(a):
    t0 = time.perf_counter()
    import numpy as np
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from graupel import vtkEXRHeightFieldReader, vtkRainRunoffFilter
    t_import = time.perf_counter() - t0
    with open("/proc/self/maps") as fp:  # which core library runs (--core-lib)
        core = sorted({ln.split()[-1] for ln in fp if "libgraupel_core" in ln})
    log("graupel: core library %s" % ", ".join(core))

    t0 = time.perf_counter()
    r = vtkEXRHeightFieldReader()
    r.SetFileName(DEM)  # spacing and origin from the file
    r.Update()
    t_read = time.perf_counter() - t0

    end = a.hours * 3600.0
    f = vtkRainRunoffFilter()
    f.SetInputConnection(r.GetOutputPort())
    f.SetRainRate(a.rain)
    f.SetPermeability(0.0)
    f.SetManningN(a.manning)
    f.SetBoundary(0)
    f.SetFlowModel(a.flow_model)
    if a.max_time_step is not None:
        f.SetMaxTimeStep(a.max_time_step)
    f.SetEndTime(end)
    f.SetOutputInterval(a.interval * 60.0)

    t0 = time.perf_counter()
    f.UpdateTimeStep(0.0)
    t_setup = time.perf_counter() - t0
    if f.GetOutput().GetNumberOfPoints() == 0:
        sys.exit("graupel: the set-up failed (see the message above)")

    t0 = time.perf_counter()
    f.UpdateTimeStep(end)
    t_run = time.perf_counter() - t0
    out = f.GetOutput()
    if out.GetNumberOfPoints() == 0:
        sys.exit("graupel: the run failed (see the message above)")
    nx, ny, _ = out.GetDimensions()
    depth = vtk_to_numpy(out.GetPointData().GetArray("water_depth")).reshape(ny, nx).copy()
    fd = out.GetFieldData()

    def field(name):
        return float(fd.GetArray(name).GetTuple1(0))

    res = {
        "t_import": t_import, "t_read": t_read, "t_setup": t_setup, "t_run": t_run,
        "steps": int(field("steps")), "time": field("time"),
        "rain_volume": field("rain_volume"), "outflow_volume": field("outflow_volume"),
        "stored_volume": field("stored_volume"), "balance_error": field("balance_error"),
        "max_time_step": f.GetMaxTimeStep(),
    }
    save(a, res, depth)


def worker_landlab(a):
    t0 = time.perf_counter()
    import numpy as np
    from landlab import RasterModelGrid
    from landlab.components import OverlandFlow
    t_import = time.perf_counter() - t0
    z, dx, dy = read_dem(a)
    ny, nx = z.shape
    t0 = time.perf_counter()
    if a.square:
        d = 0.5 * (dx + dy)
        grid = RasterModelGrid((ny, nx), xy_spacing=(d, d))
    else:
        grid = RasterModelGrid((ny, nx), xy_spacing=(dx, dy))
    grid.add_field("topographic__elevation", z.reshape(-1).copy(), at="node")
    grid.add_zeros("surface_water__depth", at="node")
    of = OverlandFlow(grid, mannings_n=a.manning, rainfall_intensity=a.rain * MM_PER_H,
                      steep_slopes=True)
    t_setup = time.perf_counter() - t0
    end = a.hours * 3600.0
    h = grid.at_node["surface_water__depth"]
    # Landlab's own loop: run_one_step(dt) takes as many stable steps as dt
    # needs (calc_time_step once per step, counted here).
    steps = [0]
    calc = of.calc_time_step

    def counted():
        steps[0] += 1
        return calc()

    of.calc_time_step = counted
    t0 = time.perf_counter()
    elapsed = 0.0
    while elapsed < end - 1e-9:
        dt = min(a.interval * 60.0, end - elapsed)
        of.run_one_step(dt=dt)
        elapsed += dt
    steps = steps[0]
    t_run = time.perf_counter() - t0
    depth = np.asarray(h).reshape(ny, nx).copy()
    area = grid.dx * grid.dy
    core = grid.core_nodes
    stored = float(np.asarray(h)[core].sum() * area)
    rain = a.rain * MM_PER_H * end * len(core) * area
    res = {"t_import": t_import, "t_setup": t_setup, "t_run": t_run, "steps": steps,
           "rain_volume": rain, "stored_volume": stored, "outflow_volume": rain - stored,
           "spacing": [grid.dx, grid.dy]}
    save(a, res, depth)


def worker_anuga(a):
    t0 = time.perf_counter()
    import numpy as np
    import anuga
    from anuga.abstract_2d_finite_volumes.mesh_factory import rectangular
    t_import = time.perf_counter() - t0
    z, dx, dy = read_dem(a)
    ny, nx = z.shape
    t0 = time.perf_counter()
    # Cell (i, j) is centred on DEM point (i, j), at x = i dx, y = j dy.
    points, tris, boundary = rectangular(nx, ny, nx * dx, ny * dy, origin=(-0.5 * dx, -0.5 * dy))
    domain = anuga.Domain(points, tris, boundary)
    xy = domain.centroid_coordinates
    cell = (np.floor(xy[:, 1] / dy + 0.5).astype(int) * nx
            + np.floor(xy[:, 0] / dx + 0.5).astype(int))
    domain.set_name("anuga")
    domain.set_datadir(a.work)
    domain.set_store(False)
    if a.anuga_algorithm:
        domain.set_flow_algorithm(a.anuga_algorithm)
    zc = z.reshape(-1)[cell]
    domain.set_quantity("elevation", numeric=np.repeat(zc[:, None], 3, axis=1),
                        location="vertices")
    domain.set_quantity("friction", a.manning)
    domain.set_quantity("stage", expression="elevation")
    # A dry outfall, as Graupel's open edge: the ghost's stage below every bed
    # (no water, no momentum), so the edge passes outflow only. ANUGA's
    # Transmissive_boundary copies the edge triangle's state, inflowing
    # momentum included, and on this DEM went unstable 1.1-1.3 h in (a
    # triangle near the north edge at 96 m of water and 59 m/s, the step
    # collapsing): its 3 h run never finished.
    edge = anuga.Dirichlet_boundary([float(z.min()) - 1.0, 0.0, 0.0])
    domain.set_boundary({tag: edge for tag in domain.get_boundary_tags()})
    anuga.Rate_operator(domain, rate=a.rain * MM_PER_H)
    t_setup = time.perf_counter() - t0
    end = a.hours * 3600.0
    t0 = time.perf_counter()
    steps = 0
    for _ in domain.evolve(yieldstep=a.interval * 60.0, finaltime=end):
        steps += domain.number_of_steps  # the steps since the last yield
    t_run = time.perf_counter() - t0
    height = domain.get_quantity("height")
    stored = float((height.centroid_values * domain.areas).sum())
    depth = (np.bincount(cell, weights=height.centroid_values, minlength=nx * ny)
             / np.bincount(cell, minlength=nx * ny)).reshape(ny, nx)
    rain = a.rain * MM_PER_H * end * float(domain.areas.sum())
    res = {"t_import": t_import, "t_setup": t_setup, "t_run": t_run,
           "steps": int(steps), "triangles": len(domain),
           "flow_algorithm": domain.get_flow_algorithm(), "rain_volume": rain,
           "stored_volume": stored, "outflow_volume": rain - stored}
    save(a, res, depth)


def worker_grass(a):
    """Runs inside `grass --tmp-location XY --exec`."""
    import numpy as np
    import grass.script as gs
    from grass.script import array as garray
    dem = np.load(os.path.join(a.work, "dem.npz"))
    z = dem["elevation"]
    ny, nx = z.shape
    dx, dy = float(dem["dx"]), float(dem["dy"])
    gs.run_command("g.region", n=ny * dy, s=0, e=nx * dx, w=0, rows=ny, cols=nx, quiet=True)
    reg = gs.region()
    if reg["rows"] != ny or reg["cols"] != nx or abs(reg["ewres"] - dx) > 1e-6:
        sys.exit("grass: the region is %r, not the DEM's" % reg)
    el = garray.array()
    el[...] = z[::-1]  # GRASS's row 0 is north
    el.write("elev", overwrite=True)
    t0 = time.perf_counter()
    gs.run_command("r.slope.aspect", elevation="elev", dx="dzdx", dy="dzdy", quiet=True)
    t_prep = time.perf_counter() - t0
    end_min = int(round(a.hours * 60))
    t0 = time.perf_counter()
    gs.run_command("r.sim.water", flags="t", elevation="elev", dx="dzdx", dy="dzdy",
                   rain_value=a.rain, infil_value=0.0, man_value=a.manning, depth="depth",
                   discharge="disch", niterations=end_min, output_step=int(a.interval),
                   random_seed=1, nprocs=os.cpu_count(), quiet=True)
    t_run = time.perf_counter() - t0
    maps = gs.list_strings("raster", pattern="depth*")
    last = sorted(maps, key=lambda m: m.split("@")[0])[-1].split("@")[0]
    d = garray.array(last)
    depth = np.nan_to_num(np.asarray(d, dtype=np.float64))[::-1].copy()
    area = dx * dy
    stored = float(depth.sum() * area)
    rain = a.rain * MM_PER_H * a.hours * 3600.0 * nx * ny * area
    res = {"t_prep": t_prep, "t_run": t_run, "rain_volume": rain, "stored_volume": stored,
           "outflow_volume": rain - stored, "depth_map": last, "maps": sorted(maps)}
    save(a, res, depth)


# ---------------------------------------------------------------- driver

def graupel_env(build, deps, core_lib=None):
    """The Python module of BUILD; core_lib: a folder whose libgraupel_core
    the module loads instead of its own (its RUNPATH yields to
    LD_LIBRARY_PATH)."""
    env = dict(os.environ)
    mod = glob.glob(os.path.join(build, "lib*", "python3", "site-packages"))
    if not mod:
        sys.exit("no Graupel Python module under %s (build the `vtk` preset)" % build)
    paths = [mod[0]]
    libs = [core_lib] if core_lib else []
    if deps:
        paths.append(os.path.join(deps, "usr", "lib", "python3", "dist-packages"))
        libs.append(os.path.join(deps, "usr", "lib", "x86_64-linux-gnu"))
    if libs:
        env["LD_LIBRARY_PATH"] = ":".join(libs)
    env["PYTHONPATH"] = ":".join(paths)
    return env


def cpu_children():
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def child(cmd, env, label):
    """Runs a worker; its wall time and the CPU time of it and all it waited
    for (on a shared machine the CPU seconds move less with the load)."""
    c0, t0 = cpu_children(), time.perf_counter()
    p = subprocess.run(cmd, env=env)
    wall, cpu = time.perf_counter() - t0, cpu_children() - c0
    if p.returncode != 0:
        sys.exit("%s failed (exit %d)" % (label, p.returncode))
    return wall, cpu


def common_args(a):
    return ["--hours", str(a.hours), "--rain", str(a.rain), "--manning", str(a.manning),
            "--interval", str(a.interval), "--work", a.work]


def load(result):
    import numpy as np
    with open(result + ".json") as fp:
        res = json.load(fp)
    res["depth"] = np.load(result + ".npz")["depth"]
    return res


def corr(a, b, wet=0.01):
    import numpy as np
    x, y = a.reshape(-1), b.reshape(-1)
    m = (x > wet) | (y > wet)

    def r(u, v):
        return float(np.corrcoef(u, v)[0, 1]) if u.size > 1 and u.std() > 0 and v.std() > 0 \
            else float("nan")
    return r(x, y), r(x[m], y[m])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--install", action="store_true",
                    help="install grass-core (apt-get) and landlab (pip, into --venv)")
    ap.add_argument("--build", help="Graupel build tree with the Python module (vtk preset)")
    ap.add_argument("--vtk-deps", help="root of the unpacked VTK 9.1 packages "
                    "(default: BUILD/deps/root, as graupel.sh lays them)")
    ap.add_argument("--python", default="/usr/bin/python3",
                    help="interpreter for Graupel (python3 with the vtk build, pvpython)")
    ap.add_argument("--venv", help="venv holding landlab (default: BUILD/peers-venv)")
    ap.add_argument("--anuga-venv", help="venv holding ANUGA (default: BUILD/peers-anuga-venv)")
    ap.add_argument("--anuga-algorithm", help="ANUGA's flow algorithm (default: its own, DE0)")
    ap.add_argument("--core-lib", help="folder of the libgraupel_core to run (a core build's "
                    "build-core/kernels) in place of BUILD's")
    ap.add_argument("--only", default="graupel,grass,landlab")
    ap.add_argument("--models", default="0,1", help="Graupel FlowModels to run")
    ap.add_argument("--hours", type=float, default=3.0)
    ap.add_argument("--rain", type=float, default=50.0, help="mm/h")
    ap.add_argument("--manning", type=float, default=0.03)
    ap.add_argument("--interval", type=float, default=30.0, help="output interval, min")
    ap.add_argument("--max-time-step", type=float, help="Graupel's MaxTimeStep, s (default: "
                    "the filter's)")
    ap.add_argument("--no-cold", action="store_true",
                    help="skip the Graupel runs with PoCL's kernel cache emptied")
    ap.add_argument("--grass-location", default="EPSG:32616",
                    help="the temporary GRASS location: a metric projection (UTM 16N, where "
                    "the DEM lies) or XY")
    ap.add_argument("--square", action="store_true",
                    help="Landlab on square cells of the mean spacing")
    ap.add_argument("--profile", action="store_true",
                    help="instead of the side by side: where Graupel's time goes (builds "
                    "peers_profile.c against BUILD's core library and runs it per FlowModel "
                    "and MaxTimeStep)")
    ap.add_argument("--profile-caps", default="1,3600",
                    help="MaxTimeStep values for --profile, s")
    ap.add_argument("--no-plain", action="store_true",
                    help="--profile: skip the plain gr_rain_runoff_advance run after the "
                    "timed one")
    ap.add_argument("--out", help="folder for the depth fields (npz) and the results (json)")
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    ap.add_argument("--work", help=argparse.SUPPRESS)
    ap.add_argument("--result", help=argparse.SUPPRESS)
    ap.add_argument("--flow-model", type=int, default=0, help=argparse.SUPPRESS)
    a = ap.parse_args()

    if a.worker:
        {"dem": worker_dem, "graupel": worker_graupel, "landlab": worker_landlab,
         "grass": worker_grass, "anuga": worker_anuga}[a.worker](a)
        return

    venv = a.venv or (os.path.join(os.path.abspath(a.build), "peers-venv") if a.build else None)
    anuga_venv = a.anuga_venv or (os.path.join(os.path.abspath(a.build), "peers-anuga-venv")
                                  if a.build else None)
    if a.install:
        if not venv:
            sys.exit("--install needs --venv or --build (the venv goes into the build tree)")
        install(venv)
        install_anuga(anuga_venv)
        if not a.build:
            return
    if not a.build:
        sys.exit("--build: the Graupel build tree (the `vtk` preset's build-vtk/, or a plugin "
                 "tree with --python pvpython)")
    deps = a.vtk_deps or os.path.join(a.build, "deps", "root")
    if not os.path.isdir(deps):
        deps = None
    only = set(a.only.split(","))
    a.work = a.out or tempfile.mkdtemp(prefix="graupel-peers-")
    os.makedirs(a.work, exist_ok=True)
    me = os.path.abspath(__file__)
    genv = graupel_env(a.build, deps, a.core_lib and os.path.abspath(a.core_lib))
    child([a.python, me, "--worker", "dem", "--work", a.work], genv, "reading the DEM")

    if a.profile:
        profile(a, deps)
        return

    rows = []  # (label, result dict, process wall)
    if "graupel" in only:
        for m in [int(x) for x in a.models.split(",")]:
            for cold in ([True, False] if not a.no_cold else [False]):
                env = dict(genv)
                if cold:
                    env["POCL_CACHE_DIR"] = tempfile.mkdtemp(prefix="pocl-cold-")
                res = os.path.join(a.work, "graupel_m%d_%s" % (m, "cold" if cold else "warm"))
                cmd = [a.python, me, "--worker", "graupel", "--result", res,
                       "--flow-model", str(m)] + common_args(a)
                if a.max_time_step is not None:
                    cmd += ["--max-time-step", str(a.max_time_step)]
                log("graupel: FlowModel %d, %s kernel cache" % (m, "cold" if cold else "warm"))
                wall = child(cmd, env, "graupel")
                if cold:
                    shutil.rmtree(env["POCL_CACHE_DIR"], ignore_errors=True)
                label = "Graupel %s%s" % ("shallow water" if m == 0 else "local inertial",
                                          ", cold cache" if cold else "")
                rows.append((label, load(res), wall))
    if "grass" in only:
        if shutil.which("grass") is None:
            sys.exit("no grass: run with --install (as root)")
        res = os.path.join(a.work, "grass")
        log("grass: r.sim.water")
        wall = child(["grass", "--tmp-location", a.grass_location, "--exec", "/usr/bin/python3",
                      me, "--worker", "grass", "--result", res] + common_args(a),
                     dict(os.environ), "grass")
        rows.append(("GRASS r.sim.water", load(res), wall))
    if "landlab" in only:
        py = os.path.join(venv, "bin", "python3") if venv else None
        if not py or not os.path.exists(py):
            sys.exit("no landlab venv at %s: run with --install" % venv)
        res = os.path.join(a.work, "landlab")
        log("landlab: OverlandFlow")
        cmd = [py, me, "--worker", "landlab", "--result", res] + common_args(a)
        if a.square:
            cmd.append("--square")
        wall = child(cmd, dict(os.environ), "landlab")
        rows.append(("Landlab OverlandFlow", load(res), wall))

    if "anuga" in only:
        py = os.path.join(anuga_venv, "bin", "python3") if anuga_venv else None
        if not py or not os.path.exists(py):
            sys.exit("no ANUGA venv at %s: run with --install" % anuga_venv)
        res = os.path.join(a.work, "anuga")
        log("anuga: Domain.evolve")
        cmd = [py, me, "--worker", "anuga", "--result", res] + common_args(a)
        if a.anuga_algorithm:
            cmd += ["--anuga-algorithm", a.anuga_algorithm]
        env = dict(os.environ)
        env.setdefault("OMP_NUM_THREADS", str(os.cpu_count()))
        wall = child(cmd, env, "anuga")
        rows.append(("ANUGA", load(res), wall))

    report(rows, a)
    if not a.out:
        shutil.rmtree(a.work, ignore_errors=True)


def depressions(z):
    """Depth of each closed depression (priority flood from the edges, where
    water leaves): the DEM's pits, which rain fills and whose depth sets the
    Courant step."""
    import heapq
    import numpy as np
    ny, nx = z.shape
    filled = z.copy()
    seen = np.zeros(z.shape, bool)
    seen[0, :] = seen[-1, :] = seen[:, 0] = seen[:, -1] = True
    heap = [(float(z[j, i]), j, i) for j, i in zip(*np.nonzero(seen))]
    heapq.heapify(heap)
    while heap:
        e, j, i = heapq.heappop(heap)
        for jj, ii in ((j + 1, i), (j - 1, i), (j, i + 1), (j, i - 1)):
            if 0 <= jj < ny and 0 <= ii < nx and not seen[jj, ii]:
                seen[jj, ii] = True
                filled[jj, ii] = max(z[jj, ii], e)
                heapq.heappush(heap, (float(filled[jj, ii]), jj, ii))
    return filled - z


def profile(a, deps):
    """Builds peers_profile.c and runs it: context, set-up (the program
    build), first steps, then the run with the steps and the stable step's
    read-backs timed apart, per FlowModel and MaxTimeStep; the first run of
    each model with PoCL's kernel cache emptied."""
    import numpy as np
    dem = np.load(os.path.join(a.work, "dem.npz"))
    z = dem["elevation"].astype(np.float32)
    ny, nx = z.shape
    raw = os.path.join(a.work, "dem.f32")
    z.tofile(raw)
    exe = os.path.join(a.work, "peers_profile")
    lib = os.path.join(a.build, "lib")
    subprocess.check_call(["cc", "-O2", "-std=c11", "-I" + os.path.join(ROOT, "kernels", "include"),
                           "-I" + os.path.join(a.build, "kernels"),
                           os.path.join(HERE, "peers_profile.c"), "-L" + lib, "-lgraupel_core",
                           "-Wl,-rpath," + lib, "-lm", "-o", exe])
    print("\nprofile: %g h of %g mm/h, Manning n %g, %d x %d points; load average %.1f %.1f %.1f "
          "on %d cores" % (a.hours, a.rain, a.manning, nx, ny, *os.getloadavg(), os.cpu_count()))
    print("| FlowModel | MaxTimeStep s | kernel cache | context s | set-up s | 1st step s | "
          "step s | steps | at the cap | min dt s | stepping s | ms/step | read-backs | "
          "read-backs s | run CPU s | advance s (CPU s) |")
    print("|" + "---|" * 16)
    dep = depressions(dem["elevation"])
    dx, dy = float(dem["dx"]), float(dem["dy"])
    print("depressions: %.4g m³ (the rain of 3 h at 50 mm/h: %.4g m³), deepest %.1f m; "
          "points deeper than 1, 5, 10 m: %d, %d, %d"
          % (dep.sum() * dx * dy, 0.15 * nx * ny * dx * dy, dep.max(), (dep > 1).sum(),
             (dep > 5).sum(), (dep > 10).sum()))
    results = []
    for m in [int(x) for x in a.models.split(",")]:
        for k, cap in enumerate(float(c) for c in a.profile_caps.split(",")):
            env = dict(os.environ)
            cold = k == 0 and not a.no_cold
            if cold:
                env["POCL_CACHE_DIR"] = tempfile.mkdtemp(prefix="pocl-cold-")
            log("profile: FlowModel %d, MaxTimeStep %g s" % (m, cap))
            out = subprocess.run([exe, raw, str(nx), str(ny), str(float(dem["dx"])),
                                  str(float(dem["dy"])), str(a.hours), str(a.rain),
                                  str(a.manning), str(m), str(cap), "0" if a.no_plain else "1"],
                                 env=env, check=True, capture_output=True, text=True).stdout
            if cold:
                shutil.rmtree(env["POCL_CACHE_DIR"], ignore_errors=True)
            r = json.loads(out)
            r["cold"] = cold
            results.append(r)
            g, inv = 9.80665, (1.0 / dx ** 2 + 1.0 / dy ** 2) ** 0.5
            # The Courant steps the deepest water allows (rain_runoff.c):
            # local inertial cfl sqrt(0.8) / (sqrt(g h) |1/d|), shallow water
            # (still water) min(1, 9 cfl / 7) / 2 / (sqrt(g h) (1/dx + 1/dy)).
            c = (g * r["max_depth"]) ** 0.5
            log("  deepest water %.2f m: Courant step %.2f s (local inertial), %.2f s (shallow "
                "water, still)" % (r["max_depth"], 0.7 * 0.8 ** 0.5 / (c * inv),
                                   0.45 / (c * (1.0 / dx + 1.0 / dy))))
            # Each stretch ends with a one-point sample (the wait): taken off.
            stepping = r["t_steps"] - r["reads"] * r["t_sample"]
            print("| %d | %g | %s | %.2f | %.2f | %.3f | %.4f | %d | %d | %.3f | %.2f | %.2f | %d | "
                  "%.2f | %.2f | %s |"
                  % (m, cap, "cold" if cold else "warm", r["t_context"], r["t_create"],
                     r["t_first_step"], r["t_second_step"], r["steps"], r["capped_steps"],
                     r["dt_min"], stepping, 1e3 * stepping / max(r["steps"], 1), r["reads"],
                     r["t_reads"], r["cpu_run"],
                     "%.2f (%.2f), %d steps" % (r["t_advance"], r["cpu_advance"],
                                                r["advance_steps"])
                     if r["advance_steps"] else "—"))
    if a.out:
        with open(os.path.join(a.out, "profile.json"), "w") as fp:
            json.dump(results, fp, indent=1)


def report(rows, a):
    refs = [(name, next((r for l, r, _ in rows if l == "Graupel " + name), None))
            for name in ("shallow water", "local inertial")]
    refs = [(name, r) for name, r in refs if r is not None]
    load_avg = os.getloadavg()
    print("\n%g h of %g mm/h on %s, Manning n %g, open edges; load average %.1f %.1f %.1f on %d "
          "cores" % (a.hours, a.rain, os.path.basename(DEM), a.manning, *load_avg,
                     os.cpu_count()))
    hdr = ("| run | process s | process CPU s | solver s | set-up s | steps | stored m³ | "
           "outflow m³ | " + "".join("r vs %s (all; wet > 1 cm) | " % n for n, _ in refs))
    hdr = hdr.rstrip()
    print(hdr)
    print("|" + "---|" * (hdr.count("|") - 1))
    solver = {}
    for label, r, (wall, cpu) in rows:
        # The solver's time as a user waits for it: Graupel's set-up (context,
        # program build, upload) and run; GRASS's r.sim.water; Landlab's loop.
        s = r["t_run"] + r.get("t_setup", 0.0)
        solver[label] = (s, wall, cpu)
        rs = "".join(" %.4f; %.4f |" % corr(ref["depth"], r["depth"]) for _, ref in refs)
        print("| %s | %.2f | %.2f | %.2f | %s | %s | %.4g | %.4g |%s"
              % (label, wall, cpu, s, "%.2f" % r["t_setup"] if "t_setup" in r else
                 "%.2f (dx, dy)" % r["t_prep"] if "t_prep" in r else "—",
                 r.get("steps", "—"), r["stored_volume"], r["outflow_volume"], rs))
    peers = [(l, v) for l, v in solver.items() if not l.startswith("Graupel")]
    gr = [(l, v) for l, v in solver.items() if l.startswith("Graupel") and "cold" not in l]
    if peers and gr:
        print("\nspeed-up (peer's time / Graupel's: solver; whole process; process CPU):")
        for gl, (gs_, gw, gc) in gr:
            print("  %s: " % gl + ", ".join("%s %.2fx; %.2fx; %.2fx" % (pl, ps / gs_, pw / gw,
                                                                        pc / gc)
                                            for pl, (ps, pw, pc) in peers))
    for label, r, _ in rows:
        if label.startswith("Graupel"):
            print("  %s: import %.2f s, EXR %.2f s, set-up %.2f s, run %.2f s, %d steps "
                  "(%.2f ms/step, mean dt %.3f s, MaxTimeStep %g s), balance error %.3g m³"
                  % (label, r["t_import"], r["t_read"], r["t_setup"], r["t_run"], r["steps"],
                     1e3 * r["t_run"] / max(r["steps"], 1), r["time"] / max(r["steps"], 1),
                     r["max_time_step"], r["balance_error"]))
        elif "steps" in r:
            print("  %s: import %.2f s, set-up %.2f s, run %.2f s, %d steps (%.2f ms/step)"
                  % (label, r["t_import"], r["t_setup"], r["t_run"], r["steps"],
                     1e3 * r["t_run"] / max(r["steps"], 1)))
    if a.out:
        with open(os.path.join(a.out, "summary.json"), "w") as fp:
            json.dump([{k: v for k, v in r.items() if k != "depth"}
                       | {"label": l, "wall": w[0], "cpu": w[1]} for l, r, w in rows], fp,
                      indent=1)
        print("depth fields: %s/*.npz (row 0 south)" % a.out)


if __name__ == "__main__":
    main()
