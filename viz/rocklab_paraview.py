"""ParaView set-up for a rocklab test folder. All quantities SI: m, s, Pa.

    pvpython viz/rocklab_paraview.py OUTDIR                      # interactive view
    pvbatch  viz/rocklab_paraview.py OUTDIR --png crack.png      # headless picture of the end
    pvbatch  viz/rocklab_paraview.py OUTDIR --frames DIR         # one PNG per snapshot
    (inside ParaView: View > Python Shell > Run Script, with ROCKLAB_OUT=OUTDIR)

Options: --at end|peak|N (the snapshot shown; default end), --color time|mode|event|damage
(what colours the cracks; default time of formation), --grains (draw the grains as spheres or
disks instead of their faced cells), --section (the faced grains behind a vertical plane through
the specimen's axis, seen straight on and coloured by their non-affine strain: where the rock has
come apart), --azimuth DEG (the section plane's turn about the axis; default 0: the camera looks
along +y), --walls (show the platens), --events (the acoustic-emission events instead of the cracks: a
sphere per event at its cracks' centroid, its diameter growing as 10^(Mw/2) -- a source's size at
a constant stress drop -- with the median event half a grain diameter, coloured by source type:
tensile, shear, implosive), --size WxH (pixels).

What it draws (rocklab test writes the series, viz/README.md):
- the grains' power cells (cells.pvd): 3D the specimen's skin, faded, so the fracture inside
  shows through; 2D every cell, coloured by its grain's von Mises stress [Pa] with the range over
  the whole series;
- one crack per broken contact (contact_cracks.pvd), each the face its two grains' cells share,
  so broken contacts join into fracture surfaces, coloured by the time they formed [s] (or mode:
  tension orange, shear blue; event; damage) in a palette distinct from the grains';
- legends with units and a caption with the test, material, axial strain and stress of the frame.
With --section, instead: the cells of the grains whose centres lie behind the plane through the
axis facing the camera (whole grains, so the cut shows their faces), coloured by the non-affine
strain since loading began [-] (viz/nonaffine.hpp): intact rock dark, however strained, and the
fracture zone bright where grains moved apart or slid past their neighbours.
The camera frames the specimen (not the platens, which are metres wide); a Brazilian disk is seen
face-on (its axis towards the camera, the loaded diameter vertical), so the split runs up the
picture between the platens.
"""
import json
import math
import os
import sys

from paraview import servermanager  # noqa: F401  (ParaView's own modules)
from paraview.simple import (
    ColorBy, GetActiveViewOrCreate, GetAnimationScene, GetColorTransferFunction, GetScalarBar,
    Calculator, Glyph, Hide, PVDReader, Render, SaveScreenshot, Show, Text, Threshold)


def parse(argv):
    opts = {"out": os.environ.get("ROCKLAB_OUT", "."), "png": None, "frames": None, "at": "end",
            "color": "time", "grains": False, "walls": False, "section": False, "events": False,
            "azimuth": 0.0, "size": (1600, 1200)}
    args = list(argv)
    positional = []
    while args:
        a = args.pop(0)
        if a in ("--png", "--frames", "--at", "--color", "--size", "--azimuth"):
            if not args:
                raise SystemExit("%s needs a value" % a)
            v = args.pop(0)
            if a == "--size":
                w, h = v.lower().split("x")
                opts["size"] = (int(w), int(h))
            elif a == "--azimuth":
                opts["azimuth"] = float(v)
            else:
                opts[a[2:]] = v
        elif a in ("--grains", "--walls", "--section", "--events"):
            opts[a[2:]] = True
        elif a.startswith("--"):
            raise SystemExit("unknown option %s (see the top of %s)" % (a, __file__))
        else:
            positional.append(a)
    if positional:
        opts["out"] = positional[0]
    if opts["color"] not in ("time", "mode", "event", "damage"):
        raise SystemExit("--color must be time, mode, event or damage, not %s" % opts["color"])
    return opts


def series_range(source, association, array, times):
    """The range of an array over every time step of a series (not just the first)."""
    lo, hi = float("inf"), float("-inf")
    for t in times or [None]:
        if t is None:
            source.UpdatePipeline()
        else:
            source.UpdatePipeline(t)
        info = source.GetCellDataInformation() if association == "CELLS" else \
            source.GetPointDataInformation()
        a = info.GetArray(array)
        if a is None:
            continue
        r = a.GetRange(-1 if a.GetNumberOfComponents() > 1 else 0)
        lo, hi = min(lo, r[0]), max(hi, r[1])
    if lo > hi:
        return 0.0, 1.0
    return (lo, hi) if hi > lo else (lo, lo + 1.0)


def frame_fields(source, t):
    """step, axial strain and stress of the frame at time t (the files' field data)."""
    source.UpdatePipeline(t)
    data = servermanager.Fetch(source)
    out = {}
    fd = data.GetFieldData() if data is not None else None
    for name in ("step", "axial_strain", "axial_stress", "time"):
        arr = fd.GetArray(name) if fd is not None else None
        if arr is not None and arr.GetNumberOfTuples() > 0:
            out[name] = arr.GetValue(0)
    return out


def legend(view, lut, title, position):
    bar = GetScalarBar(lut, view)
    bar.Title = title
    bar.ComponentTitle = ""
    bar.Visibility = 1
    bar.WindowLocation = "Any Location"
    bar.Position = position
    bar.ScalarBarLength = 0.33
    bar.TitleColor = bar.LabelColor = [0.1, 0.1, 0.1]
    bar.TitleFontSize = bar.LabelFontSize = 16
    bar.RangeLabelFormat = "%.3g"
    return bar


def threshold(source, array, lo, hi, association="CELLS"):
    t = Threshold(Input=source)
    t.Scalars = [association, array]
    try:
        t.LowerThreshold, t.UpperThreshold = lo, hi
    except AttributeError:  # ParaView < 5.10
        t.ThresholdRange = [lo, hi]
    return t


def show_cracks(view, cracks, field, results, times, dim):
    """One crack per broken contact, in a palette the grains do not use. A 3D test with many
    cracks and a post-peak part: the cracks formed after the peak (where the macro-fracture
    grows) opaque and coloured by their time, the earlier, scattered microcracks faint grey."""
    if times:
        cracks.UpdatePipeline(times[-1])
    t0, t1 = series_range(cracks, "CELLS", "time", times)
    tp = results.get("peak_time_s")
    split = (field == "time" and dim == 3 and tp is not None and t0 < tp < t1 and
             cracks.GetDataInformation().GetNumberOfCells() > 400)
    shown = cracks
    if split:
        early = threshold(cracks, "time", t0, tp)
        ed = Show(early, view)
        ed.ColorArrayName = ["POINTS", ""]
        ed.AmbientColor = ed.DiffuseColor = [0.45, 0.45, 0.5]
        ed.Opacity = 0.07
        shown = Calculator(Input=threshold(cracks, "time", tp, t1))
        shown.AttributeType = "Cell Data"
        shown.ResultArrayName = "after_peak_ms"
        shown.Function = "(time - %.17g) * 1000" % tp
        field = "after_peak_ms"
    cd = Show(shown, view)
    ColorBy(cd, ("CELLS", field))
    lut = GetColorTransferFunction(field)
    if field == "mode":
        lut.InterpretValuesAsCategories = 1
        lut.Annotations = ["1", "tension", "2", "shear"]
        lut.IndexedColors = [0.93, 0.45, 0.0, 0.12, 0.3, 0.85]
        title = "crack mode"
    else:
        lut.ApplyPreset("Viridis (matplotlib)" if field in ("event", "damage") else
                        "Inferno (matplotlib)", True)
        lut.RescaleTransferFunction(*((0.0, 1000 * (t1 - tp)) if split else
                                      series_range(cracks, "CELLS", field, times)))
        title = {"time": "crack formed at time [s]", "event": "fracture event [-]",
                 "damage": "contact damage: broken / bonded parts [-]",
                 "after_peak_ms": "crack formed after the peak [ms]\n(earlier ones: faint grey)"
                 }[field]
    legend(view, lut, title, [0.03, 0.08])
    cd.LineWidth = 3.0
    try:
        view.UseDepthPeeling = 1
    except AttributeError:
        pass


# Source types of events.csv / events.pvd (Feignier & Young's classes) and their colours.
SOURCE_TYPES = [("0", "tensile", (0.89, 0.35, 0.05)), ("1", "shear", (0.12, 0.35, 0.85)),
                ("2", "implosive", (0.15, 0.6, 0.2))]


def point_values(source, array, t):
    """A point array at time t as a numpy array (empty where missing)."""
    import numpy as np
    from vtkmodules.util.numpy_support import vtk_to_numpy
    source.UpdatePipeline(t)
    data = servermanager.Fetch(source)
    a = data.GetPointData().GetArray(array) if data is not None else None
    return vtk_to_numpy(a) if a is not None else np.zeros(0)


def show_events(view, events, grains, times):
    """The acoustic-emission events with a source, as spheres sized by their moment magnitude
    and coloured by their source type."""
    import numpy as np
    t = times[-1] if times else None
    mw = point_values(events, "moment_magnitude", t)
    mw = mw[np.isfinite(mw)]
    if mw.size == 0:
        print("no events with a moment tensor in this folder")
        return
    radius = point_values(grains, "radius", t)
    diameter = float(np.median(radius)) if radius.size else 5e-4  # the median event: half a grain
    size = Calculator(Input=threshold(events, "source_type", 0, 2, "POINTS"))
    size.AttributeType = "Point Data"
    size.ResultArrayName = "event_diameter_m"
    size.Function = "%.17g * 10^((moment_magnitude - %.17g) / 2)" % (diameter, np.median(mw))
    glyph = Glyph(Input=size, GlyphType="Sphere")
    glyph.ScaleArray = ["POINTS", "event_diameter_m"]
    glyph.ScaleFactor = 1.0
    glyph.GlyphMode = "All Points"
    gd = Show(glyph, view)
    ColorBy(gd, ("POINTS", "source_type"))
    lut = GetColorTransferFunction("source_type")
    lut.InterpretValuesAsCategories = 1
    lut.Annotations = [x for v, name, _ in SOURCE_TYPES for x in (v, name)]
    lut.IndexedColors = [c for _, _, rgb in SOURCE_TYPES for c in rgb]
    legend(view, lut, "event source type\n(sphere size: Mw, median = half a grain)", [0.12, 0.08])


# The section's colour scale ends at this percentile of the grains' faces: the few grains spalled
# off the surface (non-affine strain 5-10 times the fracture zone's) would otherwise leave the
# rest of the picture dark.
SECTION_CAP = 95


def upper_percentile(source, array, t, q):
    """The q-th percentile of a cell array at time t (a colour scale that a few outlying grains
    do not wash out)."""
    import numpy as np
    from vtkmodules.util.numpy_support import vtk_to_numpy
    source.UpdatePipeline(t)
    data = servermanager.Fetch(source)
    a = data.GetCellData().GetArray(array) if data is not None else None
    if a is None or a.GetNumberOfTuples() == 0:
        return 1.0
    v = float(np.percentile(vtk_to_numpy(a), q))
    return v if v > 0 else 1.0


def section_view(azimuth_deg):
    """The direction a section is seen along: +y turned by the azimuth about the axis (z)."""
    a = math.radians(azimuth_deg)
    return (-math.sin(a), math.cos(a), 0.0)


def show_section(view, cells, times, dim, azimuth_deg):
    """3D: the faced grains behind the vertical plane through the axis that faces the camera
    (the camera looks along section_view(azimuth)); 2D: every cell. Coloured by their non-affine
    strain since loading began."""
    half = cells
    if dim == 3:
        b = cells.GetDataInformation().GetBounds()
        d = section_view(azimuth_deg)
        side = Calculator(Input=cells)
        side.AttributeType = "Cell Data"
        side.ResultArrayName = "behind_axis_m"
        side.Function = "(grain_center_X - %.17g) * %.17g + (grain_center_Y - %.17g) * %.17g" % (
            0.5 * (b[0] + b[1]), d[0], 0.5 * (b[2] + b[3]), d[1])
        half = threshold(side, "behind_axis_m", 0.0, 1e30)
    sd = Show(half, view)
    ColorBy(sd, ("CELLS", "nonaffine_strain"))
    lut = GetColorTransferFunction("nonaffine_strain")
    lut.ApplyPreset("Inferno (matplotlib)", True)
    top = upper_percentile(cells, "nonaffine_strain", times[-1] if times else None, SECTION_CAP)
    lut.RescaleTransferFunction(0.0, top)
    sd.SetRepresentationType("Surface With Edges")
    sd.EdgeColor = [0.35, 0.35, 0.35]
    legend(view, lut, "non-affine strain since loading [-]\n(scale ends at the %dth percentile)"
           % SECTION_CAP, [0.03, 0.08])


def show_grains(view, grains, cells, times, dim, as_spheres):
    """The grains: faced cells (3D: the skin, faded; 2D: coloured by von Mises stress) or
    spheres/disks coloured by displacement."""
    if cells is not None and not as_spheres:
        if dim == 3:
            skin = threshold(cells, "boundary", 0.5, 1.5)
            gd = Show(skin, view)
            gd.ColorArrayName = ["POINTS", ""]
            gd.AmbientColor = gd.DiffuseColor = [0.62, 0.62, 0.62]
            gd.Opacity = 0.12
        else:
            gd = Show(cells, view)
            ColorBy(gd, ("CELLS", "von_mises_stress"))
            glut = GetColorTransferFunction("von_mises_stress")
            glut.ApplyPreset("Grayscale", True)
            glut.InvertTransferFunction()
            glut.RescaleTransferFunction(*series_range(cells, "CELLS", "von_mises_stress", times))
            legend(view, glut, "grain von Mises stress [Pa]", [0.86, 0.08])
            gd.SetRepresentationType("Surface With Edges")
            gd.EdgeColor = [0.55, 0.55, 0.55]
    else:
        glyph = Glyph(Input=grains, GlyphType="Sphere")
        glyph.ScaleArray = ["POINTS", "radius"]
        glyph.ScaleFactor = 2.0  # the unit-diameter sphere scaled to 2 R
        glyph.GlyphMode = "All Points"
        gd = Show(glyph, view)
        ColorBy(gd, ("POINTS", "displacement", "Magnitude"))
        glut = GetColorTransferFunction("displacement")
        glut.ApplyPreset("Grayscale", True)
        glut.RescaleTransferFunction(*series_range(grains, "POINTS", "displacement", times))
        legend(view, glut, "grain displacement [m]", [0.86, 0.08])
        gd.Opacity = 0.25 if dim == 3 else 1.0


def main(argv):
    o = parse(argv)
    vtk_dir = os.path.join(o["out"], "vtk")
    if not os.path.isfile(os.path.join(vtk_dir, "grains.pvd")):
        raise SystemExit("no %s/grains.pvd: give the output folder of `rocklab test`" % vtk_dir)
    results = {}
    if os.path.isfile(os.path.join(o["out"], "results.json")):
        with open(os.path.join(o["out"], "results.json")) as f:
            results = json.load(f)
    dim = results.get("specimen", {}).get("dimension", 3)
    disk = results.get("test") == "brazilian"

    view = GetActiveViewOrCreate("RenderView")
    view.ViewSize = list(o["size"])
    view.Background = [1, 1, 1]
    try:  # ParaView >= 5.10 keeps the background in the view's own palette unless told
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass
    view.OrientationAxesVisibility = 0  # the loading axis is vertical; the caption says so

    def reader(name):
        path = os.path.join(vtk_dir, name + ".pvd")
        return PVDReader(FileName=path) if os.path.isfile(path) else None

    grains, cells, cracks = reader("grains"), reader("cells"), reader("contact_cracks")
    if cracks is None:  # an older output: every crack record
        cracks = reader("cracks")
    times = list(grains.TimestepValues) if grains.TimestepValues else []
    scene = GetAnimationScene()
    scene.UpdateAnimationUsingDataTimeSteps()

    section = o["section"]
    if section and cells is None:
        raise SystemExit("--section needs the faced cells (%s/cells.pvd)" % vtk_dir)
    if section:
        cells.UpdatePipeline(times[-1] if times else None)
        if cells.GetCellDataInformation().GetArray("nonaffine_strain") is None:
            raise SystemExit("--section: %s/cells.pvd has no nonaffine_strain (an older rocklab"
                             " wrote it; run the test again)" % vtk_dir)
        show_section(view, cells, times, dim, o["azimuth"])
    else:
        show_grains(view, grains, cells, times, dim, o["grains"])
    Hide(grains, view)

    if o["events"]:
        events = reader("events")
        if events is None:
            raise SystemExit("--events needs %s/events.pvd (rocklab test with output.vtk)"
                             % vtk_dir)
        show_events(view, events, grains, times)
    elif cracks is not None and not section:
        show_cracks(view, cracks, o["color"], results, times, dim)

    if o["walls"]:
        walls = reader("walls")
        if walls is not None:
            Show(walls, view).Opacity = 0.15

    caption = Text()
    cap = Show(caption, view)
    cap.WindowLocation = "Upper Left Corner"
    cap.FontSize = 18
    cap.Color = [0.1, 0.1, 0.1]

    def show_frame(t):
        scene.AnimationTime = t
        f = frame_fields(cells or grains, t)
        name = results.get("test", "test")
        material = results.get("provenance", {}).get("material", "")
        caption.Text = ("%s test  %s  (%s)\n"
                        "%s %.3f %%   %s %.1f MPa   step %d%s") % (
            name.upper(), material,
            "disk face-on, loaded diameter vertical" if disk else "loading axis vertical",
            "platen displacement / D" if disk else "axial strain",
            100 * f.get("axial_strain", 0.0), "2F/(pi D t)" if disk else "axial stress",
            1e-6 * f.get("axial_stress", 0.0), int(f.get("step", 0)),
            "\nsection through the axis (azimuth %g deg): the grains behind it" % o["azimuth"]
            if section and dim == 3 else "")
        # A Brazilian disk (axis z, loaded along y) is seen face-on: its split runs up the picture.
        frame_specimen(view, cells or grains, t, 2 if section or disk else dim,
                       facing=tuple(-c for c in section_view(o["azimuth"]))
                       if section and dim == 3 and not disk else (0, 0, 1))
        Render(view)

    if o["frames"]:
        os.makedirs(o["frames"], exist_ok=True)
        for i, t in enumerate(times):
            show_frame(t)
            SaveScreenshot(os.path.join(o["frames"], "frame_%04d.png" % i), view,
                           ImageResolution=list(o["size"]))
    at = times[-1] if times else 0.0
    if o["at"] == "peak":
        peak = results.get("peak_time_s")
        at = min(times, key=lambda t: abs(t - peak)) if peak is not None and times else at
    elif o["at"] not in ("end", "peak"):
        at = times[int(o["at"])]
    show_frame(at)
    if o["png"]:
        SaveScreenshot(o["png"], view, ImageResolution=list(o["size"]))
        print("wrote %s" % o["png"])


def frame_specimen(view, source, t, dim, facing=(0, 0, 1)):
    """Point the camera at the specimen's bounds. dim 2: a flat view from the `facing` side
    (+z: the 2D plane; horizontal: a 3D section, z up), parallel projection."""
    source.UpdatePipeline(t)
    b = source.GetDataInformation().GetBounds()
    cx, cy, cz = 0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3]), 0.5 * (b[4] + b[5])
    span = max(b[1] - b[0], b[3] - b[2], b[5] - b[4])
    cam = view.GetActiveCamera()
    view.CameraFocalPoint = [cx, cy, cz]
    if dim == 2:
        up = 1 if facing[2] else 2  # the picture's vertical axis: y (2D) or z (a section)
        # across the picture: x in 2D; a section's plane turns about z, so the wider of x and y
        across = b[1] - b[0] if up == 1 else max(b[1] - b[0], b[3] - b[2])
        h = max(b[2 * up + 1] - b[2 * up], 0.8 * across)
        shift = [0.0, 0.0, 0.0]
        shift[up] = 0.05 * h  # the specimen a little low: the caption above
        focal = [cx + shift[0], cy + shift[1], cz + shift[2]]
        eye = [focal[k] + 4 * span * facing[k] for k in range(3)]
        view.CameraPosition = eye
        view.CameraViewUp = [0, 1, 0] if up == 1 else [0, 0, 1]
        view.CameraParallelProjection = 1
        Render(view)  # the first render resets the camera; set the scale after it
        cam.SetFocalPoint(*focal)
        cam.SetPosition(*eye)
        cam.SetParallelScale(0.6 * h)
    else:  # an oblique view from the side, z (the loading axis) up
        view.CameraPosition = [cx + 2.2 * span, cy - 1.6 * span, cz + 0.5 * span]
        view.CameraViewUp = [0, 0, 1]
        view.CameraParallelProjection = 0
        cam.SetViewAngle(30)
        view.ResetCamera(b[0], b[1], b[2], b[3], b[4], b[5])
        cam.Zoom(1.25)


if __name__ == "__main__":
    main(sys.argv[1:])
