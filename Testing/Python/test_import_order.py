"""pvbatch: `import graupel` works whether it comes before or after Graupel
objects were wrapped for Python through a proxy (the bug fixed: after
GetClientSideObject() on a Graupel proxy, VTK's wrapping had recorded each
class as its nearest wrapped base, and `import graupel` then gave abstract
base classes that could not be instantiated).

    pvbatch test_import_order.py --plugin Graupel.so --order proxy-first|import-first ..."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

a = T.args(lambda p: p.add_argument("--order", choices=("proxy-first", "import-first"),
                                    required=True))

CONCRETE = ("vtkProceduralTerrainSource", "vtkEXRHeightFieldReader", "vtkEXRFieldWriter",
            "vtkRainRunoffFilter")

if a.order == "import-first":
    import graupel  # noqa: E402,F401

from paraview.simple import *  # noqa: E402,F401,F403

LoadPlugin(a.plugin, ns=globals())
terrain = ProceduralTerrain(Dimensions=[24, 16])
rain = RainRunoff(Input=terrain)
# Wrapping the proxies' VTK objects is what used to spoil a later import.
wrapped = [terrain.GetClientSideObject(), rain.GetClientSideObject()]

import graupel  # noqa: E402

names = sorted(n for n in dir(graupel) if n.startswith("vtk"))
T.check(set(CONCRETE) <= set(names), "%s: graupel exports %s" % (a.order, names))
for n in names:
    cls = getattr(graupel, n)
    T.check(cls.__name__ == n and cls.__module__.startswith("graupel"),
            "%s: graupel.%s is %s.%s" % (a.order, n, cls.__module__, cls.__name__))
for n in CONCRETE:
    try:
        obj = getattr(graupel, n)()
        T.check(obj.GetClassName() == n, "%s: %s() makes a %s" % (a.order, n, obj.GetClassName()))
    except TypeError as e:
        T.check(False, "%s: %s() fails: %s" % (a.order, n, e))

# The proxies' objects are the Graupel classes, with their own methods.
T.check(type(wrapped[0]).__name__ == "vtkProceduralTerrainSource",
        "%s: the terrain proxy's object is a %s" % (a.order, type(wrapped[0]).__name__))
T.check(hasattr(wrapped[0], "GetSeed"), "%s: the terrain proxy's object has GetSeed" % a.order)

# A wrapped object still runs: a small terrain from Python alone.
s = graupel.vtkProceduralTerrainSource()
s.SetDimensions(24, 16)
s.Update()
T.check(s.GetOutput().GetDimensions() == (24, 16, 1), "%s: terrain from Python" % a.order)

T.finish()
