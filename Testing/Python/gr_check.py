"""Small helpers shared by Graupel's Python tests: argument parsing, checks
that count failures instead of stopping at the first, and error capture."""
import argparse
import os
import sys

_failures = []
_checks = [0]


def args(extra=None):
    p = argparse.ArgumentParser()
    p.add_argument("--plugin", default=None)
    p.add_argument("--data", required=True)
    p.add_argument("--scratch", required=True)
    p.add_argument("--baseline", default=None)
    p.add_argument("--expect-vtk", default=None)
    p.add_argument("--generate-baseline", action="store_true")
    if extra:
        extra(p)
    a, _ = p.parse_known_args()
    return a


def mpi_setup(ns):
    """For the tests pvbatch runs under mpiexec: parses the arguments (with
    --ranks, the ranks the run should have), brings paraview.simple's names
    into the test's namespace ns (as `from paraview.simple import *` does),
    loads the plugin there and checks the ranks. Returns (args, ranks)."""
    a = args(lambda p: p.add_argument("--ranks", type=int, default=2))
    from paraview import servermanager
    import paraview.simple as simple
    ns.update({k: getattr(simple, k) for k in dir(simple) if not k.startswith("_")})
    simple.LoadPlugin(a.plugin, ns=ns)
    ranks = servermanager.vtkProcessModule.GetProcessModule().GetNumberOfLocalPartitions()
    check(ranks == a.ranks, "running on %d ranks (%d)" % (a.ranks, ranks))
    return a, ranks


def check(cond, what):
    _checks[0] += 1
    if not cond:
        _failures.append(what)
        print("CHECK failed: " + what, file=sys.stderr)


def near(a, b, tol, what):
    check(abs(a - b) <= tol, "%s: %r vs %r (tol %g)" % (what, a, b, tol))


def finish():
    """Prints the tally; exits non-zero on failure. On success the script
    simply ends, so that pvbatch under MPI shuts its ranks down in order."""
    print("%d passed, %d failed" % (_checks[0] - len(_failures), len(_failures)))
    if _failures:
        sys.exit(1)


def piece_share(share, ranks, label=None):
    """Checks the range of a split run's piece_share (each rank's owned
    points over the grid's): the whole grid on one rank, at most 55 % each
    on two, a strip (under half) each on more."""
    pre = "%s: " % label if label else ""
    if ranks == 1:
        check(share == (1.0, 1.0), "%sone rank simulates the whole grid (%r)" % (pre, share))
    elif ranks == 2:
        check(share[0] > 0.0 and share[1] <= 0.55,
              "%seach of 2 ranks simulates at most 55%% of the grid (%r)" % (pre, share))
    else:
        check(share[0] > 0.0 and share[1] < 0.5,
              "%seach of %d ranks simulates a strip (%r)" % (pre, ranks, share))


class ErrorCatcher:
    """Collects the sentences an algorithm reports (ErrorEvent, or the event
    given, such as WarningEvent)."""

    def __init__(self, *objects, event="ErrorEvent"):
        from vtkmodules.util.misc import calldata_type
        from vtkmodules.util.vtkConstants import VTK_STRING

        self.messages = []

        @calldata_type(VTK_STRING)
        def on_error(obj, event, data):
            self.messages.append(str(data))

        self._cb = on_error
        for o in objects:
            o.AddObserver(event, on_error)

    def text(self):
        return "\n".join(self.messages)

    def clear(self):
        self.messages = []


class AbortOnce:
    """Aborts an algorithm's update once, at its first progress report
    strictly between 0 and 1 (as a user pressing Abort mid-run); `hits` says
    whether it did."""

    def __init__(self, algorithm):
        self.hits = 0
        self._algorithm = algorithm
        self._tag = algorithm.AddObserver("ProgressEvent", self._on_progress)

    def _on_progress(self, obj, event):
        if 0.0 < obj.GetProgress() < 1.0 and self.hits == 0:
            self.hits = 1
            obj.SetAbortExecute(1)

    def remove(self):
        self._algorithm.RemoveObserver(self._tag)


# For a ProgrammableFilter's script: the lines that make gr_check importable
# on every rank (pvbatch's other ranks run the script without the test's
# sys.path).
IMPORT = "import sys\nsys.path.insert(0, %r)\nimport gr_check\n" % (
    os.path.dirname(os.path.abspath(__file__)))


def piece_compare(algorithm, ref, fields, ledger, nx, ny, extra=()):
    """In a ProgrammableFilter's script, on every rank of a split run: the
    rank's piece (the filter's input, an image of the nx x ny grid's extent)
    against ref, the whole grid computed in that rank by the wrapped classes.
    Adds to the output (the piece) the point arrays `mismatch` (at each
    point, how many of the point arrays `fields` differ from ref's in any
    bit), `ledger_mismatch` (how many of the field-data values `ledger`
    differ in any byte of their doubles, so that -0.0 against 0.0 or a NaN
    counts; the same at every point), `piece_share` (the piece's
    piece_cells over the grid, -1 without) and each (name, value) of extra:
    a number, or a whole-grid array of nx * ny values cropped to the piece.
    The ranks' arrays are then reduced by ParaView's data information
    (Fetch brings only rank 0's piece in pvbatch)."""
    import numpy as np
    from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
    img = algorithm.GetInputDataObject(0, 0)
    out = algorithm.GetOutputDataObject(0)
    out.ShallowCopy(img)
    e0, e1, f0, f1, _, _ = img.GetExtent()
    rows, cols = f1 - f0 + 1, e1 - e0 + 1
    bad = np.zeros(rows * cols, dtype=np.float32)
    for name in fields:
        r = vtk_to_numpy(ref.GetPointData().GetArray(name)).reshape(ny, nx, -1)
        m = vtk_to_numpy(img.GetPointData().GetArray(name)).reshape(rows, cols, -1)
        bad += (m.view(np.uint32) != r[f0:f1 + 1, e0:e1 + 1].view(np.uint32)).any(axis=2) \
            .reshape(-1)
    ledger_bad = 0
    for name in ledger:
        x, y = img.GetFieldData().GetArray(name), ref.GetFieldData().GetArray(name)
        if x is None or y is None or \
                np.float64(x.GetTuple1(0)).tobytes() != np.float64(y.GetTuple1(0)).tobytes():
            ledger_bad += 1
    cells = img.GetFieldData().GetArray("piece_cells")
    share = cells.GetTuple1(0) / float(nx * ny) if cells else -1.0
    n = bad.size
    arrays = [("mismatch", bad), ("ledger_mismatch", np.full(n, ledger_bad, np.float32)),
              ("piece_share", np.full(n, share, np.float32))]
    for name, value in extra:
        if np.ndim(value) == 0:
            arrays.append((name, np.full(n, float(value), np.float32)))
        else:
            whole = np.asarray(value, dtype=np.float32).reshape(ny, nx)
            arrays.append((name, whole[f0:f1 + 1, e0:e1 + 1].reshape(-1)))
    for name, values in arrays:
        arr = numpy_to_vtk(np.ascontiguousarray(values), deep=1)
        arr.SetName(name)
        out.GetPointData().AddArray(arr)


def table(columns):
    """A vtkTable of double columns from {name: values}."""
    from vtkmodules.vtkCommonCore import vtkDoubleArray
    from vtkmodules.vtkCommonDataModel import vtkTable
    t = vtkTable()
    for name, values in columns.items():
        c = vtkDoubleArray()
        c.SetName(name)
        for v in values:
            c.InsertNextValue(v)
        t.AddColumn(c)
    return t


def digest(alg, time, names):
    """SHA-256 of the named point arrays of alg's output at time (b"none" for
    a missing one): one value to compare runs by, bit for bit."""
    import hashlib
    from vtkmodules.util.numpy_support import vtk_to_numpy
    alg.UpdateTimeStep(time)
    pd = alg.GetOutput().GetPointData()
    h = hashlib.sha256()
    for name in names:
        arr = pd.GetArray(name)
        h.update(vtk_to_numpy(arr).tobytes() if arr is not None else b"none")
    return h.hexdigest()


def _hash_attributes(h, label, attrs):
    """Feeds h every array of a vtkFieldData (point, cell, field or row
    data) in name order: its name, type, shape and bytes (strings as text)."""
    import numpy as np
    from vtkmodules.util.numpy_support import vtk_to_numpy
    arrays = []
    for k in range(attrs.GetNumberOfArrays()):
        arr = attrs.GetAbstractArray(k)
        arrays.append(((arr.GetName() or ""), k, arr))
    for name, _, arr in sorted(arrays, key=lambda e: (e[0], e[1])):
        h.update(("%s/%s/%s/%d/%d;" % (label, name, arr.GetClassName(),
                                       arr.GetNumberOfTuples(),
                                       arr.GetNumberOfComponents())).encode())
        if arr.IsA("vtkDataArray"):
            h.update(np.ascontiguousarray(vtk_to_numpy(arr)).tobytes())
        else:
            h.update("\0".join(str(arr.GetVariantValue(v).ToString())
                               for v in range(arr.GetNumberOfValues())).encode())


def _hash_data(h, label, data):
    if data is None:
        h.update(("%s:none;" % label).encode())
        return
    h.update(("%s:%s;" % (label, data.GetClassName())).encode())
    if data.IsA("vtkCompositeDataSet"):
        it = data.NewIterator()
        it.InitTraversal()
        k = 0
        while not it.IsDoneWithTraversal():
            _hash_data(h, "%s.%d" % (label, k), it.GetCurrentDataObject())
            it.GoToNextItem()
            k += 1
        return
    _hash_attributes(h, label + "/field", data.GetFieldData())
    if data.IsA("vtkDataSet"):
        import numpy as np
        from vtkmodules.util.numpy_support import vtk_to_numpy
        h.update(repr(data.GetBounds()).encode())
        if data.IsA("vtkPointSet") and data.GetPoints() is not None:
            h.update(np.ascontiguousarray(vtk_to_numpy(data.GetPoints().GetData())).tobytes())
        _hash_attributes(h, label + "/point", data.GetPointData())
        _hash_attributes(h, label + "/cell", data.GetCellData())
    elif data.IsA("vtkTable"):
        _hash_attributes(h, label + "/row", data.GetRowData())


def digest_all(alg, time):
    """SHA-256 of everything alg outputs at time, on every output port:
    every point, cell, field (the ledger) and row array (name, type, shape,
    bytes) and a point set's points. Two runs that give the same digest agree
    bit for bit; 0.0 against -0.0 or two NaNs of other payloads differ."""
    import hashlib
    alg.UpdateTimeStep(time)
    h = hashlib.sha256()
    for port in range(alg.GetNumberOfOutputPorts()):
        _hash_data(h, str(port), alg.GetOutputDataObject(port))
    return h.hexdigest()
