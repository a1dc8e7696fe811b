"""The look every Graupel picture shares: a height field warped by its
elevation, coloured with an elevation map, lit from the north-west, seen from
the south-east. Used by the demo and by the reference-image test."""
from paraview.simple import (ColorBy, GetActiveViewOrCreate, GetColorTransferFunction,
                             Show, WarpByScalar, Render)


def show_terrain(source, size=(1024, 768), exaggeration=2.0, array="elevation"):
    """Shows `source` (a 2-D image with `array`) warped and coloured in a
    render view of `size` pixels and returns the view."""
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
    return view
