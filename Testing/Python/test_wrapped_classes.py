"""The Graupel VTK classes used directly from Python (pvpython in the plugin
build, plain python3 in the VTK-alone build): terrain values, pieces,
determinism, EXR round trips, the real DEM in Data/, and error paths."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args()

import vtkmodules  # noqa: E402
from vtkmodules.util.numpy_support import vtk_to_numpy, numpy_to_vtk  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData  # noqa: E402

import graupel  # noqa: E402
from graupel import (  # noqa: E402
    vtkEXRFieldWriter,
    vtkEXRHeightFieldReader,
    vtkProceduralTerrainSource,
)

if a.expect_vtk:
    # The VTK-alone build must run on Debian's VTK 9.1, not ParaView's.
    T.check(vtkmodules.__file__.startswith(a.expect_vtk),
            "vtkmodules comes from %s" % vtkmodules.__file__)
T.check(graupel.__doc__ and "Graupel" in graupel.__doc__, "graupel package docstring")


def elevation(src, extent=None):
    if extent:
        src.UpdateExtent(extent)
    else:
        src.Update()
    img = src.GetOutput()
    arr = img.GetPointData().GetArray("elevation")
    nx, ny, _ = img.GetDimensions()
    return vtk_to_numpy(arr).reshape(ny, nx).copy(), img


def terrain(**kw):
    s = vtkProceduralTerrainSource()
    s.SetDimensions(kw.pop("dims", (96, 64)))
    for k, v in kw.items():
        getattr(s, "Set" + k)(v)
    return s


# ---- terrain: defaults, bounds, geometry, device record -----------------------
s = vtkProceduralTerrainSource()
T.check(tuple(s.GetDimensions()) == (512, 512), "default Dimensions 512 512")
T.check(s.GetSpacing() == 2.0 and s.GetOctaves() == 6 and s.GetHeightScale() == 120.0,
        "default Spacing 2, Octaves 6, HeightScale 120")
T.check(s.GetNoiseType() == 0 and s.GetInvert(), "default: inverted ridged multifractal")
T.check(s.GetLacunarity() == 2.0 and s.GetPersistence() == 0.5 and s.GetOffset() == 1.0
        and s.GetGain() == 2.0, "default Lacunarity, Persistence, Offset, Gain")

s = terrain(Spacing=3.0, Origin=(10.0, 20.0, 5.0), Seed=3)
h, img = elevation(s)
T.check(h.dtype == np.float32 and h.shape == (64, 96), "elevation float32 64x96")
T.check(tuple(img.GetSpacing()) == (3.0, 3.0, 1.0), "spacing")
T.check(tuple(img.GetOrigin()) == (10.0, 20.0, 5.0), "origin")
T.check(h.min() >= 0.0 and h.max() <= 120.0, "0 <= elevation <= HeightScale")
T.check(h.max() - h.min() > 10.0, "terrain is not flat (%g m span)" % (h.max() - h.min()))
dev = img.GetFieldData().GetAbstractArray("graupel_device")
T.check(dev is not None and dev.GetValue(0) == s.GetDeviceName() and len(s.GetDeviceName()) > 0,
        "graupel_device names the device")

# Same seed, same field; another seed, another field.
h2, _ = elevation(terrain(Spacing=3.0, Origin=(10.0, 20.0, 5.0), Seed=3))
h3, _ = elevation(terrain(Spacing=3.0, Origin=(10.0, 20.0, 5.0), Seed=4))
T.check(np.array_equal(h, h2), "same seed gives the same field")
T.check(np.sqrt(np.mean((h - h3) ** 2)) > 0.5 * h.std(), "another seed gives another field")

# HeightScale is a linear factor.
h60, _ = elevation(terrain(Spacing=3.0, Origin=(10.0, 20.0, 5.0), Seed=3, HeightScale=60.0))
T.check(np.allclose(h60, 0.5 * h, rtol=0, atol=1e-4), "HeightScale scales linearly")

# A requested piece is exactly that part of the whole (MPI pieces).
piece_src = terrain(Spacing=3.0, Origin=(10.0, 20.0, 5.0), Seed=3)
piece, pimg = elevation(piece_src, (10, 40, 5, 30, 0, 0))
T.check(tuple(pimg.GetExtent()) == (10, 40, 5, 30, 0, 0), "piece extent")
T.check(np.array_equal(piece, h[5:31, 10:41]), "piece equals that part of the whole")

# ---- error paths: one sentence, an empty output, and the next update works ----
bad = terrain(dims=(0, 10))
errs = T.ErrorCatcher(bad)
bad.Update()
T.check("Dimensions" in errs.text(), "Dimensions error sentence: %r" % errs.text())
T.check(bad.GetOutput().GetNumberOfPoints() == 0, "bad Dimensions: empty output")

dev_src = terrain(Device="no-such-device-xyzzy")
errs = T.ErrorCatcher(dev_src)
dev_src.Update()
T.check("no-such-device-xyzzy" in errs.text(), "device error names the request: %r" % errs.text())
T.check(dev_src.GetOutput().GetNumberOfPoints() == 0, "no device: empty output")
dev_src.SetDevice("auto")
dev_src.Update()
T.check(dev_src.GetOutput().GetNumberOfPoints() == 96 * 64, "works again after Device=auto")

far = terrain(Origin=(1e14, 0.0, 0.0))
errs = T.ErrorCatcher(far)
far.Update()
T.check("Origin" in errs.text() and far.GetOutput().GetNumberOfPoints() == 0,
        "absurd Origin refused with a sentence: %r" % errs.text())

# A kernel that fails to build (bad GRAUPEL_CL_OPTIONS): one sentence with the
# build log, an empty output; with the options fixed the next update works.
os.environ["GRAUPEL_CL_OPTIONS"] = "-cl-no-such-option"
broken = terrain(Octaves=3)
errs = T.ErrorCatcher(broken)
broken.Update()
T.check("failed to build" in errs.text() and broken.GetOutput().GetNumberOfPoints() == 0,
        "build failure reported with an empty output: %r" % errs.text()[:200])
del os.environ["GRAUPEL_CL_OPTIONS"]
broken.Modified()
broken.Update()
T.check(broken.GetOutput().GetNumberOfPoints() == 96 * 64, "works again once the options are fixed")

# A grid one row larger than the device's largest buffer (or than the memory
# this process can get) is refused before any host memory is taken. (How large
# that is depends on the device and, for PoCL, on the machine's memory: ask it.)
max_bytes = s.GetDeviceMaxBufferBytes()
T.check(max_bytes > 0, "the device reports its largest buffer (%d bytes)" % max_bytes)
side = int((max_bytes / 4) ** 0.5) + 1
if side * side <= 4e9:  # beyond that the grid check refuses first (core.runtime tests it)
    big = terrain(dims=(side, side))
    errs = T.ErrorCatcher(big)
    big.Update()
    T.check(("allows at most" in errs.text() or "can use" in errs.text())
            and big.GetOutput().GetNumberOfPoints() == 0,
            "a %d x %d grid (%.0f MiB) refused: %r" % (side, side, 4.0 * side * side / 2**20,
                                                      errs.text()[:200]))

# Aborted mid-run (between bands): an empty output and a warning, and the next
# update computes the whole terrain again.
long_src = terrain(dims=(4096, 2048))
abort = T.AbortOnce(long_src)
long_src.Update()
T.check(abort.hits == 1 and long_src.GetOutput().GetNumberOfPoints() == 0,
        "an aborted update leaves an empty output")
abort.remove()
long_src.Update()
T.check(long_src.GetOutput().GetNumberOfPoints() == 4096 * 2048, "the next update is whole")

# ---- EXR: writer -> reader keeps every value and name -------------------------
scratch = a.scratch
os.makedirs(scratch, exist_ok=True)
img = vtkImageData()
img.DeepCopy(s.GetOutput())
ny, nx = h.shape
depth = (np.arange(nx * ny, dtype=np.float32) * 0.001).reshape(-1)
vel = np.stack([np.full(nx * ny, 1.5, np.float32), depth, -depth], axis=1)
d = numpy_to_vtk(depth, deep=1)
d.SetName("snow_depth")
v = numpy_to_vtk(vel, deep=1)
v.SetName("velocity")
img.GetPointData().AddArray(d)
img.GetPointData().AddArray(v)

for pixel, tol in ((2, 0.0), (1, 2.0 ** -11)):
    path = os.path.join(scratch, "wrapped_%d.exr" % pixel)
    w = vtkEXRFieldWriter()
    w.SetInputData(img)
    w.SetFileName(path)
    w.SetPixelType(pixel)
    T.check(w.Write() == 1 and w.GetErrorCode() == 0, "writer succeeds (pixel %d)" % pixel)
    T.check(vtkEXRHeightFieldReader.CanReadFile(path) == 1, "CanReadFile on written file")
    r = vtkEXRHeightFieldReader()
    r.SetFileName(path)
    r.SetSpacing(3.0, 3.0)
    r.SetOrigin(10.0, 20.0, 5.0)
    r.Update()
    out = r.GetOutput()
    T.check(tuple(out.GetDimensions()) == (nx, ny, 1), "read dimensions")
    T.check(tuple(out.GetOrigin()) == (10.0, 20.0, 5.0), "read origin")
    T.check(tuple(out.GetSpacing()) == (3.0, 3.0, 1.0), "read spacing")
    dev = out.GetFieldData().GetAbstractArray("graupel_device")
    T.check(dev is not None and dev.GetValue(0) == s.GetDeviceName(),
            "graupel_device kept in the file")
    pd = out.GetPointData()
    names = sorted(pd.GetArrayName(i) for i in range(pd.GetNumberOfArrays()))
    T.check(names == ["elevation", "snow_depth", "velocity"], "array names %s" % names)
    back = vtk_to_numpy(pd.GetArray("elevation")).reshape(ny, nx)
    T.check(np.all(np.abs(back - h) <= tol * np.maximum(np.abs(h), 6.1e-5)),
            "elevation round trip (pixel %d)" % pixel)
    vb = vtk_to_numpy(pd.GetArray("velocity"))
    T.check(vb.shape == (nx * ny, 3), "velocity back as 3 components")
    T.check(np.all(np.abs(vb - vel) <= tol * np.maximum(np.abs(vel), 6.1e-5)),
            "velocity round trip (pixel %d)" % pixel)
    T.check(pd.GetScalars() is not None and pd.GetScalars().GetName() == "elevation",
            "elevation is the active scalar")

# Chosen arrays only; HeightScale touches elevation only; lone channels.
path = os.path.join(scratch, "chosen.exr")
w = vtkEXRFieldWriter()
w.SetInputData(img)
w.SetFileName(path)
w.AddArrayName("snow_depth")
T.check(w.GetNumberOfArrayNames() == 1 and w.GetArrayName(0) == "snow_depth", "array list")
w.Write()
r = vtkEXRHeightFieldReader()
r.SetFileName(path)
r.Update()
pd = r.GetOutput().GetPointData()
T.check(pd.GetNumberOfArrays() == 1 and pd.GetArrayName(0) == "snow_depth",
        "a lone Graupel field keeps its name")
img2 = vtkImageData()
img2.SetDimensions(nx, ny, 1)
e = numpy_to_vtk(h.reshape(-1) / 120.0, deep=1)
e.SetName("Y")
img2.GetPointData().AddArray(e)
path = os.path.join(scratch, "lone.exr")
w = vtkEXRFieldWriter()
w.SetInputData(img2)
w.SetFileName(path)
w.Write()
r = vtkEXRHeightFieldReader()
r.SetFileName(path)
r.SetHeightScale(120.0)
r.Update()
back = vtk_to_numpy(r.GetOutput().GetPointData().GetArray("elevation")).reshape(ny, nx)
T.check(np.allclose(back, h, rtol=1e-6, atol=1e-4), "lone channel 'Y' read as elevation x HeightScale")

# Reader errors: missing, not EXR, truncated; each an empty output.
garbage = os.path.join(scratch, "garbage.exr")
with open(garbage, "wb") as f:
    f.write(b"this is not an EXR file at all" * 10)
truncated = os.path.join(scratch, "truncated.exr")
with open(os.path.join(scratch, "wrapped_2.exr"), "rb") as f:
    blob = f.read()
with open(truncated, "wb") as f:
    f.write(blob[: len(blob) // 2])
for path in (os.path.join(scratch, "missing.exr"), garbage, truncated):
    r = vtkEXRHeightFieldReader()
    errs = T.ErrorCatcher(r)
    r.SetFileName(path)
    r.Update()
    T.check(r.GetOutput().GetNumberOfPoints() == 0, "empty output for %s" % path)
    T.check(os.path.basename(path) in errs.text(), "error names the file: %r" % errs.text())
T.check(vtkEXRHeightFieldReader.CanReadFile(garbage) == 0, "CanReadFile refuses garbage")

# Writer errors: 3-D input, unknown array, no file name.
cube = vtkImageData()
cube.SetDimensions(4, 4, 4)
c = numpy_to_vtk(np.zeros(64, np.float32), deep=1)
c.SetName("elevation")
cube.GetPointData().AddArray(c)
for setup, word in ((lambda w: w.SetInputData(cube), "2-D"),
                    (lambda w: (w.SetInputData(img), w.AddArrayName("nope")), "nope")):
    w = vtkEXRFieldWriter()
    errs = T.ErrorCatcher(w)
    setup(w)
    w.SetFileName(os.path.join(scratch, "never.exr"))
    w.Write()
    T.check(w.GetErrorCode() != 0 and word in errs.text(), "writer error %r: %r" % (word, errs.text()))
T.check(not os.path.exists(os.path.join(scratch, "never.exr")), "no file written on error")

# Reader properties and writer inputs that are refused, each with a sentence.
r = vtkEXRHeightFieldReader()
errs = T.ErrorCatcher(r)
r.Update()
T.check("no FileName" in errs.text() and r.GetOutput().GetNumberOfPoints() == 0,
        "reader without FileName: %r" % errs.text())
r = vtkEXRHeightFieldReader()
errs = T.ErrorCatcher(r)
r.SetFileName(os.path.join(scratch, "wrapped_2.exr"))
r.SetSpacing(0.0, 1.0)
r.Update()
# The file's own spacing (3 3, kept by the writer) wins while GeometryFromFile is on.
T.check(r.GetGeometryFromFile() == 1 and r.GetOutput().GetSpacing() == (3.0, 3.0, 1.0)
        and not errs.text(), "file spacing wins: %s %r" % (r.GetOutput().GetSpacing(), errs.text()))
r.GeometryFromFileOff()
r.Update()
T.check("Spacing" in errs.text() and r.GetOutput().GetNumberOfPoints() == 0,
        "reader Spacing 0: %r" % errs.text())
zero_spacing = terrain(Spacing=0.0)
errs = T.ErrorCatcher(zero_spacing)
zero_spacing.Update()
T.check("Spacing" in errs.text() and zero_spacing.GetOutput().GetNumberOfPoints() == 0,
        "terrain Spacing 0: %r" % errs.text())

# NaN elevations (no-data cells) are read, with one warning that says so.
nan_img = vtkImageData()
nan_img.SetDimensions(4, 3, 1)
nan_vals = np.arange(12, dtype=np.float32)
nan_vals[[2, 7]] = np.nan
nan_arr = numpy_to_vtk(nan_vals, deep=1)
nan_arr.SetName("elevation")
nan_img.GetPointData().AddArray(nan_arr)
w = vtkEXRFieldWriter()
w.SetInputData(nan_img)
w.SetFileName(os.path.join(scratch, "nan.exr"))
w.Write()
r = vtkEXRHeightFieldReader()
warns = T.ErrorCatcher(r, event="WarningEvent")
r.SetFileName(os.path.join(scratch, "nan.exr"))
r.Update()
T.check("2 elevation values" in warns.text() and r.GetOutput().GetNumberOfPoints() == 12,
        "NaN elevations read with a warning: %r" % warns.text())

for setup, word in ((lambda w: w.SetInputData(img), "no FileName"),
                    (lambda w: (w.SetInputData(vtkImageData()),
                                w.SetFileName(os.path.join(scratch, "never3.exr"))), "2-D"),
                    (lambda w: (w.SetInputData(img), w.SetFileName(
                        os.path.join(scratch, "no-such-dir", "x.exr"))), "no-such-dir")):
    w = vtkEXRFieldWriter()
    errs = T.ErrorCatcher(w)
    setup(w)
    w.Write()
    T.check(w.GetErrorCode() != 0 and word in errs.text(), "writer error %r: %r" % (word, errs.text()))
empty_img = vtkImageData()
empty_img.SetDimensions(3, 3, 1)
w = vtkEXRFieldWriter()
errs = T.ErrorCatcher(w)
w.SetInputData(empty_img)
w.SetFileName(os.path.join(scratch, "never2.exr"))
w.Write()
T.check("no numeric point arrays" in errs.text(), "writer with no arrays: %r" % errs.text())

# ---- the real DEM in Data/ matches its source ---------------------------------
dem = os.path.join(a.data, "jacksboro_fault_dem.exr")
r = vtkEXRHeightFieldReader()
r.SetFileName(dem)
r.Update()
out = r.GetOutput()
T.check(tuple(out.GetDimensions()) == (403, 344, 1), "DEM is 403 x 344")
z = vtk_to_numpy(out.GetPointData().GetArray("elevation")).reshape(344, 403)
T.check(z.min() == 236.0 and z.max() == 1076.0, "DEM elevation 236..1076 m")
# Its geometry is in the file (graupel.spacing, graupel.origin): the reader's
# defaults give the real size, 3 arc-seconds as Data/README.md states them
# (74.5 m east-west, 92.1 m north-south), the south-west point at the origin;
# with GeometryFromFile off the reader's own 1 m applies, so the file is what
# gives it.
T.check(out.GetSpacing() == (74.5, 92.1, 1.0) and out.GetOrigin() == (0.0, 0.0, 0.0),
        "DEM spacing %s and origin %s from the file" % (out.GetSpacing(), out.GetOrigin()))
r1 = vtkEXRHeightFieldReader()
r1.SetFileName(dem)
r1.SetGeometryFromFile(0)
r1.Update()
T.check(r1.GetOutput().GetSpacing() == (1.0, 1.0, 1.0), "DEM without the file's geometry: %s"
        % (r1.GetOutput().GetSpacing(),))
src = "/usr/share/matplotlib/mpl-data/sample_data/jacksboro_fault_dem.npz"
if os.path.exists(src):
    ref = np.load(src)["elevation"].astype(np.float32)
    # The source's first row is the northern edge; ours is the southern one.
    T.check(np.array_equal(z, ref[::-1]), "DEM equals the source, north up")
else:
    T.check(False, "the DEM's source %s is missing (python-matplotlib-data)" % src)

T.finish()
