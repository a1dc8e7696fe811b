"""pvpython: a property value out of its range is said, once, in one warning
sentence with the range, the value asked for and the value used, and the
output's field data carries the value used (graupel_used_<property>, which the
GUI writes back into the panel). A value in range drops the note. Checked on
three classes of different bases: a simulation (Rain Runoff, core table row),
an objects simulation (Snow Deformation's TimeStep, a fixed range) and a
source (Procedural Terrain)."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402

T.args()
import graupel  # noqa: E402


def used(alg, prop):
    out = alg.GetOutputDataObject(0)
    arr = out.GetFieldData().GetArray("graupel_used_" + prop) if out else None
    return arr.GetValue(0) if arr else None


terrain = graupel.vtkProceduralTerrainSource()
terrain.SetDimensions(24, 20)

cases = [
    # class, property, value asked, value used, the sentence
    (graupel.vtkRainRunoffFilter, "RainRate", -5.0, 0.0,
     "Rain Runoff: RainRate must be from 0 to 3600 mm/h; it was set to -5 mm/h, so 0 mm/h is used."),
    (graupel.vtkSnowDeformationFilter, "TimeStep", 100.0, 60.0,
     "Snow Deformation: TimeStep must be from 1e-06 to 60 s; it was set to 100 s, so 60 s is used."),
    (graupel.vtkProceduralTerrainSource, "Octaves", 40, None, "Procedural Terrain: Octaves must be"),
]
for cls, prop, asked, expect, sentence in cases:
    alg = cls()
    if alg.GetNumberOfInputPorts() > 0:
        alg.SetInputConnection(terrain.GetOutputPort())
    warn = T.ErrorCatcher(alg, event="WarningEvent")
    getattr(alg, "Set" + prop)(asked)
    now = getattr(alg, "Get" + prop)()
    if expect is not None:
        T.check(now == expect, "%s.%s = %g reads back as %g (%g)" % (cls.__name__, prop, asked, now,
                                                                   expect))
    else:
        T.check(now != asked, "%s.%s = %g is moved into its range (%g)" % (cls.__name__, prop,
                                                                        asked, now))
    alg.Update()
    first = warn.text()
    T.check(sentence in first and first.count(" is used.") == 1,
            "%s: one warning: %r" % (cls.__name__, first))
    T.check(used(alg, prop) == now, "%s: field data graupel_used_%s = %s" % (cls.__name__, prop,
                                                                            used(alg, prop)))
    # Once: a second update (the same value written back, as the GUI does)
    # says nothing more.
    warn.clear()
    getattr(alg, "Set" + prop)(now)
    alg.Modified()
    alg.Update()
    T.check(warn.text() == "", "%s: said once (then %r)" % (cls.__name__, warn.text()))
    T.check(used(alg, prop) == now, "%s: still noted after the same value" % cls.__name__)
    # A value in range drops the note.
    inside = {"RainRate": 20.0, "TimeStep": 0.02, "Octaves": 3}[prop]
    getattr(alg, "Set" + prop)(inside)
    alg.Update()
    T.check(used(alg, prop) is None and warn.text() == "",
            "%s: a value in range drops the note" % cls.__name__)
T.finish()
