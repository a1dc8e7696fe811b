"""The look every Graupel picture shares, and the look Apply gives in the GUI:
a height field through the plugin's Terrain Surface filter (warped by its
topmost surface, lit, closed by walls at its edges), coloured by the
plugin's colour maps (the defaults of elevation, water_depth, snow_depth,
..., see Plugin/GraupelColorMaps.json), with a legend in units and the
vertical exaggeration written on the picture, seen from the south-east.
Used by the demo, the state files and the reference-image tests."""
import math

import paraview.simple as pvs
from paraview.simple import (GetActiveViewOrCreate, GetColorTransferFunction, GetScalarBar,
                             Render, Show, Text)

# Legend titles: the arrays' names in words, with units.
TITLES = {
    "elevation": "elevation (m)",
    "water_depth": "water depth (m)",
    "water_depth_display": "water depth (m)",
    "max_depth": "largest water depth (m)",
    "snow_depth": "snow depth (m)",
    "snow_density": "snow density (kg/m\u00b3)",
    "cover_class": "cover",
    "shadow": "sunlight (0 shadow, 1 sun)",
    "wave_height": "wave height (m)",
}
BACKGROUND = [0.32, 0.34, 0.43]


def TerrainSurface(**kw):
    """The plugin's Terrain Surface: LoadPlugin(..., ns=) adds the Graupel
    constructors to the caller's namespace only."""
    if not hasattr(pvs, "TerrainSurface"):
        pvs._add_functions(vars(pvs))
    return pvs.TerrainSurface(**kw)


def show_surface(source, size=(1024, 768), exaggeration=2.0, color="", height="", time=None,
                 bar=True, note=True, view=None):
    """Shows `source` (a Graupel terrain output) as Apply does: a Terrain
    Surface with `exaggeration`, coloured by `color` (empty: the filter's
    choice), in `view` (or the active render view) of `size` pixels at
    `time`; with `bar` a legend titled in units, with `note` the vertical
    exaggeration written in the upper right. Returns (view, display,
    surface)."""
    view = view or GetActiveViewOrCreate("RenderView")
    if time is not None:
        view.ViewTime = time
    view.ViewSize = list(size)
    view.OrientationAxesVisibility = 0
    view.Background = BACKGROUND
    if hasattr(view, "UseColorPaletteForBackground"):
        view.UseColorPaletteForBackground = 0
    surface = TerrainSurface(Input=source, VerticalExaggeration=exaggeration, ColorArray=color,
                             HeightArray=height)
    display = Show(surface, view)
    array = display.ColorArrayName[1]
    if array:
        lut = GetColorTransferFunction(array)
        display.SetScalarBarVisibility(view, bar)
        if bar:
            _legend(GetScalarBar(lut, view), array, lut)
    if note:
        text = Show(Text(Text="vertical exaggeration \u00d7%g" % exaggeration), view)
        text.WindowLocation = "Upper Right Corner"
        text.FontSize = 14
        text.Color = [1.0, 1.0, 1.0]
    _camera(view, surface)
    Render(view)
    return view, display, surface


def _legend(sb, array, lut=None):
    sb.Title = TITLES.get(array, array)
    sb.ComponentTitle = ""
    sb.TitleColor = sb.LabelColor = [1.0, 1.0, 1.0]
    sb.TitleFontSize = sb.LabelFontSize = 14
    sb.WindowLocation = "Any Location"
    sb.Orientation = "Horizontal"
    sb.Position = [0.30, 0.03]
    sb.ScalarBarLength = 0.40
    if array != "cover_class":
        fmt = "%.0f" if array in ("elevation", "snow_density") else "%.2g"
        sb.RangeLabelFormat = sb.LabelFormat = fmt
    else:
        sb.Position = [0.30, 0.10]
    if lut is not None and lut.UseLogScale:
        # On a log scale the automatic ticks crowd each decade's end: label
        # the ends, then whole decades, then 2s and 5s, each at least 0.45
        # of a decade from every label taken.
        lo, hi = lut.RGBPoints[0], lut.RGBPoints[-4]
        taken = [math.log10(lo), math.log10(hi)]
        labels = []
        for m in (1.0, 2.0, 5.0):
            for e in range(-6, 7):
                t = m * 10.0 ** e
                if lo < t < hi and all(abs(math.log10(t) - x) >= 0.45 for x in taken):
                    labels.append(t)
                    taken.append(math.log10(t))
        sb.UseCustomLabels = 1
        sb.CustomLabels = sorted(labels)
        sb.AddRangeLabels = 1


def _camera(view, surface):
    view.ResetCamera()
    cam = view.GetActiveCamera()
    b = surface.GetDataInformation().GetBounds()
    cx, cy = 0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3])
    span = max(b[1] - b[0], b[3] - b[2])
    cam.SetFocalPoint(cx, cy, 0.5 * (b[4] + b[5]))
    cam.SetPosition(cx + 0.9 * span, cy - 1.1 * span, b[5] + 0.9 * span)
    cam.SetViewUp(0, 0, 1)
    view.ResetCamera(False)
    cam.Dolly(1.3)


def show_terrain(source, size=(1024, 768), exaggeration=2.0, array="elevation", bar=True,
                 note=True):
    """Shows `source` (a 2-D image with `array`) as a terrain coloured by
    `array` and returns the view."""
    return show_surface(source, size, exaggeration, color=array, height="elevation", bar=bar,
                        note=note)[0]


def show_water(source, time, size=(1024, 768), exaggeration=2.0, deep=2.0, bar=True, note=True):
    """Shows the output of Rain Runoff at `time` (s): the terrain warped by
    its water surface, coloured by water_depth on a log scale from the 1 cm
    wetting depth (pale blue) to `deep` metres and more (dark blue), dry
    ground (under 1 cm) in the map's sand colour. Returns the view."""
    GetActiveViewOrCreate("RenderView").ViewTime = time
    lut = GetColorTransferFunction("water_depth_display")
    lut.ApplyPreset("Graupel Water Depth", False)
    lut.RescaleTransferFunction(0.01, deep)
    lut.UseLogScale = 1  # the preset's scale; applying it by name leaves it linear
    return show_surface(source, size, exaggeration, color="water_depth", time=time, bar=bar,
                        note=note)[0]
