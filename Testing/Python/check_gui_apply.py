"""On Apply in the ParaView GUI, a Graupel terrain output is shown as a lit
3-D Terrain Surface with a legend titled with units (Plugin/pqGraupelApplyLook.h).
Starts `paraview` (on the test session's Xvfb) with PV_PLUGIN_PATH set and a
QtTesting XML script that plays what a user does: Sources > Graupel >
Procedural Terrain, Apply; Filters > Graupel > Rain Runoff, Apply; File > Save
State. Then checks the saved state: one Terrain Surface below each output,
shown in the render view and coloured by the right array, the flat images
and the terrain's surface hidden, the legends visible with titles in units
and the vertical exaggeration."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gr_gui import APPLY, play_to_state, setup, write_events  # noqa: E402

scratch, plugin_dir, state, script = setup("gui_apply")

write_events(script, [
    ("pqClientMainWindow/menubar/menuSources/Graupel", "activate", "ProceduralTerrain"),
    (APPLY, "activate", ""),
    # The surface is added once the Apply has returned (a zero-time timer).
    ("pqClientMainWindow", "process_events", "1000"),
    # Enabled only if Procedural Terrain is still the active source.
    ("pqClientMainWindow/menubar/menuFilters/Graupel", "activate", "RainRunoff"),
    (APPLY, "activate", ""),
    ("pqClientMainWindow", "process_events", "1000"),
    ("pqClientMainWindow/menubar/menu_File", "activate", "actionFileSaveServerState"),
    ("pqClientMainWindow/FileSaveServerStateDialog", "filesSelected", state),
])
proc, S = play_to_state(script, plugin_dir, state)
names, proxies, prop, by_type, bar_for = S.names, S.proxies, S.prop, S.by_type, S.bar_for


def render_repr(source_id):
    """The representation of `source_id`'s first port in the render view."""
    for p in proxies.values():
        # Its helper proxies (selection, ...) have no Representation type.
        if (p.get("group") == "representations" and prop(p, "Input")[1] == [(source_id, "0")]
                and prop(p, "Representation")[0]):
            return p
    return None


terrain, rain = by_type("ProceduralTerrain"), by_type("RainRunoff")
surfaces = by_type("TerrainSurface")
print("sources: %s" % sorted(names.values()))
checks = [len(terrain) == 1, len(rain) == 1, len(surfaces) == 2]
expected = {}
if len(terrain) == 1 and len(rain) == 1:
    # The legends say the surfaces' vertical exaggeration (2, the default).
    expected = {terrain[0]: ("elevation", "elevation (m), heights \u00d72", "0"),
                rain[0]: ("water_depth_display", "water depth (m), heights \u00d72", "1")}
for source, (array, title, visible) in expected.items():
    below = [s for s in surfaces if prop(proxies[s], "Input")[1] == [(source, "0")]]
    flat = render_repr(source)
    print("%s: surfaces below %s, flat image visible %s" % (
        names[source], [names[s] for s in below], flat is not None and prop(flat, "Visibility")[0]))
    checks.append(len(below) == 1)
    checks.append(flat is not None and prop(flat, "Visibility")[0] == ["0"])
    if len(below) != 1:
        continue
    shown = render_repr(below[0])
    if shown is None:
        checks.append(False)
        continue
    color = prop(shown, "ColorArrayName")[0]
    bar = bar_for(shown)
    bar_title = prop(bar, "Title")[0] if bar is not None else None
    bar_visible = prop(bar, "Visibility")[0] if bar is not None else None
    print("  %s: visible %s, representation %s, colour %s, legend %r visible %s" % (
        names[below[0]], prop(shown, "Visibility")[0], prop(shown, "Representation")[0], color,
        bar_title, bar_visible))
    # The terrain's surface is hidden once Rain Runoff's is shown on it.
    checks.append(prop(shown, "Visibility")[0] == [visible])
    checks.append(prop(shown, "Representation")[0] == ["Surface"])
    checks.append(color[-1:] == [array])
    checks.append(bar_title == [title])
    checks.append(bar_visible == [visible])
ok = all(checks)
print("%d passed, %d failed" % (sum(checks), len(checks) - sum(checks)))
sys.exit(0 if ok else 1)
