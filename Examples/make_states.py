"""Writes a ParaView state file (.pvsm) per demo scene into Examples/states/,
from the same scene builders the demos and the reference images use:

  terrain.pvsm             the procedural terrain of demo_terrain.py
  rain_jacksboro.pvsm      half an hour of 50 mm/h rain on the real DEM (Data/)
  snow_deformation.pvsm    the wheel through snow of demo_snow_deformation.py
  snow_accumulation.pvsm   the hut and trees under snow and the sledge across
                           it, of demo_snow_accumulation.py
  season.pvsm              season_scene.py's chain (winter snow on the DEM,
                           March melt, runoff) shown on 19 March as Apply
                           shows Snow Melt (coloured by snow_depth)

    xvfb-run -a pvbatch Examples/make_states.py [--plugin .../Graupel.so] [--scene NAME]

A state holds the pipeline, not its data: loading one runs the simulations
again. Data files are written relative to Examples/states/ (the DEM as
../../Data/jacksboro_fault_dem.exr; the snow accumulation's hut, trees and
sledge, made in Python, as .vtm/.vtp files next to the states; the season's
conditioned DEM and forcing table as season_terrain.vti and
season_forcing.csv), so a state
loads from any checkout: in the GUI, File > Load State, then "Search files
under specified directory" (the state's own folder, the default); in Python,
LoadState(path, data_directory=<Examples/states>). Each scene is written by
its own pvbatch process (a fresh session: no colour map or light of one
scene ends up in the next)."""
import argparse
import os
import re
import shutil
import subprocess
import sys

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, here)
SCENES = ("season", "terrain", "rain_jacksboro", "snow_deformation", "snow_accumulation")

p = argparse.ArgumentParser()
p.add_argument("--out", default=os.path.join(here, "states"))
p.add_argument("--scene", choices=SCENES)
p.add_argument("--plugin", default=os.path.join(
    here, "..", "build", "lib", "paraview-5.11", "plugins", "Graupel", "Graupel.so"))
args, _ = p.parse_known_args()
out = os.path.abspath(args.out)
os.makedirs(out, exist_ok=True)

if args.scene is None:
    pvbatch = os.environ.get("PVBATCH") or shutil.which("pvbatch")
    for scene in SCENES:
        cmd = [pvbatch, os.path.abspath(__file__), "--scene", scene, "--out", out,
               "--plugin", os.path.abspath(args.plugin)]
        if subprocess.run(cmd).returncode != 0:
            sys.exit("make_states: the scene %s failed" % scene)
    sys.exit(0)

import paraview.simple as pvs  # noqa: E402

import graupel_scene  # noqa: E402
import landscape_scene  # noqa: E402

landscape_scene.load_plugin(args.plugin)
import snow_scene  # noqa: E402

written = []


def file_producer(data):
    """Stands in for snow_scene._producer: writes `data` (made in Python)
    next to the states and returns a reader of it, which a state can hold."""
    from vtkmodules.vtkIOXML import vtkXMLMultiBlockDataWriter, vtkXMLPolyDataWriter

    multi = data.IsA("vtkMultiBlockDataSet")
    name = "%s_%s.%s" % (args.scene, "objects" if multi else "sledge", "vtm" if multi else "vtp")
    path = os.path.join(out, name)
    writer = vtkXMLMultiBlockDataWriter() if multi else vtkXMLPolyDataWriter()
    writer.SetFileName(path)
    writer.SetInputData(data)
    writer.SetDataModeToAppended()
    writer.SetCompressorTypeToZLib()
    writer.Write()
    written.append(path)
    reader = (pvs.XMLMultiBlockDataReader if multi else pvs.XMLPolyDataReader)(FileName=[path])
    reader.UpdatePipeline()
    return reader


def season_terrain(image):
    """Stands in for season_scene.terrain_producer: the filled DEM as a .vti
    next to the states, read back."""
    from vtkmodules.vtkIOXML import vtkXMLImageDataWriter

    path = os.path.join(out, "season_terrain.vti")
    writer = vtkXMLImageDataWriter()
    writer.SetFileName(path)
    writer.SetInputData(image)
    writer.SetDataModeToAppended()
    writer.SetCompressorTypeToZLib()
    writer.Write()
    written.append(path)
    reader = pvs.XMLImageDataReader(FileName=[path])
    reader.UpdatePipeline()
    return reader


def season_forcing(table):
    """Stands in for season_scene.table_producer: the forcing as a CSV file
    next to the states (times written as decimals: read as doubles)."""
    path = os.path.join(out, "season_forcing.csv")
    names = [table.GetColumnName(k) for k in range(table.GetNumberOfColumns())]
    with open(path, "w") as f:
        f.write(",".join(names) + "\n")
        for i in range(table.GetNumberOfRows()):
            f.write(",".join("%.3f" % table.GetValue(i, k).ToDouble()
                             for k in range(len(names))) + "\n")
    written.append(path)
    reader = pvs.CSVReader(FileName=[path])
    reader.UpdatePipeline()
    return reader


def at_time(t):
    """Puts the animation (and so every view) at `t` seconds, as the state loads."""
    scene = pvs.GetAnimationScene()
    scene.UpdateAnimationUsingDataTimeSteps()
    scene.AnimationTime = t
    pvs.GetTimeKeeper().Time = t


if args.scene == "terrain":
    terrain = pvs.ProceduralTerrain(Dimensions=[512, 512], Spacing=2.0, Seed=2026)
    graupel_scene.show_terrain(terrain)
elif args.scene == "season":
    import season_scene  # noqa: E402

    season_scene.terrain_producer = season_terrain
    season_scene.table_producer = season_forcing
    parts = season_scene.build(os.path.join(here, "..", "Data"))
    for name in ("analysis",):  # the pictures' light: not part of the state
        pvs.Delete(parts[name])
    t = season_scene.DATES[2][0]
    at_time(t)
    graupel_scene.show_surface(parts["melt"], color="snow_depth", time=t, exaggeration=2.5)
elif args.scene == "rain_jacksboro":
    dem = pvs.EXRHeightFieldReader(
        FileName=os.path.realpath(os.path.join(here, "..", "Data", "jacksboro_fault_dem.exr")))
    rain = pvs.RainRunoff(Input=dem, RainRate=50.0, EndTime=1800.0, OutputInterval=300.0,
                          MaxTimeStep=10.0)
    at_time(1800.0)
    graupel_scene.show_water(rain, 1800.0, exaggeration=4.0)
elif args.scene == "snow_deformation":
    snow, times = snow_scene.build()
    at_time(times[-1])
    snow_scene.show(snow, times[-1])
elif args.scene == "snow_accumulation":
    snow_scene._producer = file_producer
    acc, sledge, crossing, _ = snow_scene.build_accumulation()
    at_time(crossing)
    snow_scene.show_accumulation(acc, acc.EndTime, sledge, crossing)

state = os.path.join(out, args.scene + ".pvsm")
pvs.SaveState(state)
# File names relative to the states' folder: LoadState's data directory
# search (vtkLoadStateOptions) finds ../../Data/x.exr and x.vtm from there.
text = open(state).read()
data_dir = os.path.realpath(os.path.join(here, "..", "Data"))
text = text.replace(data_dir + "/", "../../Data/")
for path in written:
    text = text.replace(path, os.path.basename(path))
left = re.findall(r'value="(/[^"]*\.(?:exr|vtm|vtp|vti|csv))"', text)
if left:
    sys.exit("make_states: absolute data paths left in %s: %s" % (state, left))
open(state, "w").write(text)
print("wrote %s" % state)
