"""pvbatch: terrain -> EXR Field Writer -> EXR Height Field Reader keeps every
value (float exactly, half to half precision), names and vectors, and the
image's spacing, origin and field data (the ledger)."""
import os
import struct
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args()

import numpy as np  # noqa: E402
from paraview import servermanager  # noqa: E402
from paraview.simple import *  # noqa: E402,F401,F403
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402

LoadPlugin(a.plugin, ns=globals())

t = ProceduralTerrain(Dimensions=[131, 77], Spacing=5.0, Seed=42, NoiseType="Billow")
calc = Calculator(Input=t, ResultArrayName="velocity", Function="iHat*elevation - jHat*coordsX + 0.25*kHat")
calc.ResultArrayType = "Float"
orig = servermanager.Fetch(calc)
opd = orig.GetPointData()

for pixel, tol in (("Float", 0.0), ("Half", 2.0 ** -11)):
    path = os.path.join(a.scratch, "roundtrip_%s.exr" % pixel)
    SaveData(path, proxy=calc, PixelType=pixel)
    r = OpenDataFile(path)
    r.Spacing = [5.0, 5.0]
    back = servermanager.Fetch(r)
    T.check(back.GetDimensions() == orig.GetDimensions(), "%s: dimensions" % pixel)
    bpd = back.GetPointData()
    names = sorted(bpd.GetArrayName(i) for i in range(bpd.GetNumberOfArrays()))
    T.check(names == ["elevation", "velocity"], "%s: names %s" % (pixel, names))
    for name in ("elevation", "velocity"):
        x = vtk_to_numpy(opd.GetArray(name))
        y = vtk_to_numpy(bpd.GetArray(name))
        T.check(x.shape == y.shape, "%s: %s shape" % (pixel, name))
        err = np.abs(x - y) - tol * np.maximum(np.abs(x), 6.1e-5)
        T.check(x.shape == y.shape and err.max() <= 0.0,
                "%s: %s values (worst excess %g)" % (pixel, name, err.max()))
    Delete(r)

# Geometry and field data: a DEM saved with spacing 74.5 x 92.1, origin
# (100, 200, 0) and a ledger comes back with them.
from vtkmodules.vtkCommonCore import vtkDoubleArray, vtkStringArray  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData  # noqa: E402

dem = servermanager.Fetch(ProceduralTerrain(Dimensions=[33, 21], Spacing=1.0, Seed=7))
img = vtkImageData()
img.DeepCopy(dem)
img.SetSpacing(74.5, 92.1, 1.0)
img.SetOrigin(100.0, 200.0, 0.0)
ledger = {"rain_volume": 1234.5678901234567, "time": 1800.0, "infiltrated_volume": 1e-300}
for name, value in ledger.items():
    arr = vtkDoubleArray()
    arr.SetName(name)
    arr.InsertNextValue(value)
    img.GetFieldData().AddArray(arr)
pairs = vtkDoubleArray()
pairs.SetName("pairs")
pairs.SetNumberOfComponents(2)
for v in ((1.0, -2.5), (3.25, 1e300)):
    pairs.InsertNextTuple(v)
img.GetFieldData().AddArray(pairs)
before_dev = img.GetFieldData().GetAbstractArray("graupel_device")
T.check(before_dev is not None and before_dev.GetNumberOfValues() == 1,
        "the terrain carries graupel_device")
device = before_dev.GetValue(0) if before_dev is not None else ""

path = os.path.join(a.scratch, "roundtrip_geometry.exr")
src = PVTrivialProducer()
src.GetClientSideObject().SetOutput(img)
SaveData(path, proxy=src)
r = OpenDataFile(path)
back = servermanager.Fetch(r)
T.check(back.GetSpacing() == (74.5, 92.1, 1.0), "spacing from the file: %s" % (back.GetSpacing(),))
T.check(back.GetOrigin() == (100.0, 200.0, 0.0), "origin from the file: %s" % (back.GetOrigin(),))
bfd = back.GetFieldData()
for name, value in ledger.items():
    arr = bfd.GetArray(name)
    T.check(arr is not None and arr.GetNumberOfTuples() == 1 and arr.GetValue(0) == value,
            "ledger %s: %r" % (name, arr.GetValue(0) if arr is not None else None))
arr = bfd.GetArray("pairs")
T.check(arr is not None and arr.GetNumberOfComponents() == 2 and arr.GetNumberOfTuples() == 2
        and arr.GetTuple2(0) == (1.0, -2.5) and arr.GetTuple2(1) == (3.25, 1e300),
        "2-component field-data array")
dev = bfd.GetAbstractArray("graupel_device")
T.check(dev is not None and dev.GetValue(0) == device and len(device) > 0,
        "graupel_device string kept")
h0 = vtk_to_numpy(img.GetPointData().GetArray("elevation"))
h1 = vtk_to_numpy(back.GetPointData().GetArray("elevation"))
T.check(np.array_equal(h0, h1), "elevation equal after reopening")

# GeometryFromFile off: the properties win.
r.GeometryFromFile = 0
r.Spacing = [2.0, 3.0]
r.Origin = [1.0, 2.0, 3.0]
back = servermanager.Fetch(r)
T.check(back.GetSpacing() == (2.0, 3.0, 1.0) and back.GetOrigin() == (1.0, 2.0, 3.0),
        "GeometryFromFile off: spacing %s origin %s" % (back.GetSpacing(), back.GetOrigin()))
Delete(r)

# A file without the attributes (written by the C core alone) keeps the old
# behaviour: spacing 1 1 unless the properties say otherwise.
import graupel  # noqa: E402
w0 = graupel.vtkEXRFieldWriter()
plain = vtkImageData()
plain.SetDimensions(4, 3, 1)
e = vtkDoubleArray()
e.SetName("elevation")
e.SetNumberOfTuples(12)
e.Fill(5.0)
plain.GetPointData().SetScalars(e)
old_path = os.path.join(a.scratch, "roundtrip_plain.exr")
w0.SetInputData(plain)
w0.SetFileName(old_path)
w0.Write()
rd = graupel.vtkEXRHeightFieldReader()
rd.SetFileName(old_path)
rd.Update()
T.check(rd.GetOutput().GetSpacing() == (1.0, 1.0, 1.0), "default geometry: spacing 1 1")

# A hostile spacing attribute: one error sentence, an empty output.
bad = os.path.join(a.scratch, "roundtrip_bad_spacing.exr")
with open(path, "rb") as f:
    raw = bytearray(f.read())
k = raw.find(b"graupel.spacing\0v2d\0")
T.check(k > 0, "graupel.spacing found in the header")
if k > 0:
    v = k + len(b"graupel.spacing\0v2d\0") + 4
    raw[v:v + 8] = struct.pack("<d", float("nan"))
    with open(bad, "wb") as f:
        f.write(raw)
    rb = graupel.vtkEXRHeightFieldReader()
    caught = T.ErrorCatcher(rb)
    rb.SetFileName(bad)
    rb.Update()
    T.check(rb.GetOutput().GetNumberOfPoints() == 0, "hostile spacing: empty output")
    T.check(len(caught.messages) >= 1 and "graupel.spacing" in caught.messages[0]
            and "nan" in caught.messages[0], "hostile spacing: %s" % caught.messages)

# A writer given a 3-D image reports and writes nothing.
w = Wavelet()
path = os.path.join(a.scratch, "wavelet.exr")
try:
    SaveData(path, proxy=w)
except Exception:
    pass
T.check(not os.path.exists(path), "no EXR written for a 3-D image")

T.finish()
