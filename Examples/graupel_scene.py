"""The look every Graupel picture shares: a height field warped by its
elevation (or water surface), coloured with an elevation (or water depth)
map, seen from the south-east. Used by the demo and the reference-image
tests."""
from paraview.simple import (ColorBy, GetActiveViewOrCreate, GetColorTransferFunction,
                             Show, WarpByScalar, Render)


def show_terrain(source, size=(1024, 768), exaggeration=2.0, array="elevation"):
    """Shows `source` (a 2-D image with `array`) warped and coloured in a
    render view of `size` pixels and returns the view."""
    return _show(source, size, exaggeration, array)[0]


def _show(source, size, exaggeration, array):
    warp = WarpByScalar(Input=source, Scalars=["POINTS", array], ScaleFactor=exaggeration)
    view = GetActiveViewOrCreate("RenderView")
    view.ViewSize = list(size)
    view.OrientationAxesVisibility = 0
    view.Background = [0.32, 0.34, 0.43]
    if hasattr(view, "UseColorPaletteForBackground"):
        view.UseColorPaletteForBackground = 0
    display = Show(warp, view)
    display.Representation = "Surface"
    ColorBy(display, ("POINTS", array))
    lut = GetColorTransferFunction(array)
    lut.ApplyPreset("Blue Orange (divergent)", True)
    lo, hi = source.PointData[array].GetRange()
    lut.RescaleTransferFunction(lo, hi)
    display.SetScalarBarVisibility(view, False)
    view.ResetCamera()
    cam = view.GetActiveCamera()
    b = warp.GetDataInformation().GetBounds()
    cx, cy = 0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3])
    span = max(b[1] - b[0], b[3] - b[2])
    cam.SetFocalPoint(cx, cy, 0.5 * (b[4] + b[5]))
    cam.SetPosition(cx + 0.9 * span, cy - 1.1 * span, b[5] + 0.9 * span)
    cam.SetViewUp(0, 0, 1)
    view.ResetCamera(False)
    cam.Dolly(1.35)
    Render(view)
    return view, display


def show_water(source, time, size=(1024, 768), exaggeration=2.0, deep=1.0):
    """Shows the output of Rain Runoff at `time` (s): the terrain warped by
    its water surface, coloured by water_depth from dry ground (sand) through
    films of a centimetre (pale blue) to `deep` metres and more (dark blue).
    Returns the view."""
    GetActiveViewOrCreate("RenderView").ViewTime = time
    view, display = _show(source, size, exaggeration, "water_surface")
    ColorBy(display, ("POINTS", "water_depth"))
    lut = GetColorTransferFunction("water_depth")
    lut.RGBPoints = [0.0, 0.82, 0.76, 0.62, 0.002 * deep, 0.80, 0.78, 0.68,
                     0.01 * deep, 0.60, 0.78, 0.90, 0.1 * deep, 0.20, 0.50, 0.85,
                     deep, 0.02, 0.12, 0.45]
    lut.ColorSpace = "RGB"
    display.SetScalarBarVisibility(view, False)
    Render(view)
    return view
