"""ParaView set-up for a rocklab test folder (all quantities SI: m, s, Pa).

Run inside ParaView (View > Python Shell > Run Script, or `pvpython`/`paraview --script=`):

    pvpython viz/rocklab_paraview.py OUTDIR          # or set OUTDIR below / ROCKLAB_OUT

It opens OUTDIR/vtk/{grains,bonds,cracks,walls}.pvd, draws grains as spheres (3D) or disks (2D)
scaled by their radius and coloured by displacement magnitude, bonds as lines coloured by
broken-element fraction, cracks coloured by mode (1 tension = red, 2 shear = blue) and the
platens as a translucent surface, then jumps to the last time step.
"""
import os
import sys

from paraview.simple import (  # noqa: F401  (ParaView's own module)
    ColorBy, GetActiveViewOrCreate, GetAnimationScene, GetColorTransferFunction, Glyph,
    Hide, PVDReader, Render, ResetCamera, Show)

out = os.environ.get("ROCKLAB_OUT") or (sys.argv[1] if len(sys.argv) > 1 else ".")
vtk_dir = os.path.join(out, "vtk")
if not os.path.isdir(vtk_dir):
    raise SystemExit("no %s: give the output folder of `rocklab test`" % vtk_dir)

view = GetActiveViewOrCreate("RenderView")

grains = PVDReader(FileName=os.path.join(vtk_dir, "grains.pvd"))
glyph = Glyph(Input=grains, GlyphType="Sphere")
glyph.ScaleArray = ["POINTS", "radius"]
glyph.ScaleFactor = 2.0  # the sphere source has unit diameter: scale by 2 R
glyph.GlyphMode = "All Points"
glyph.GlyphType.ThetaResolution = 16
glyph.GlyphType.PhiResolution = 12
gd = Show(glyph, view)
ColorBy(gd, ("POINTS", "displacement", "Magnitude"))
gd.RescaleTransferFunctionToDataRange(True)
gd.Opacity = 0.35
Hide(grains, view)

bonds = PVDReader(FileName=os.path.join(vtk_dir, "bonds.pvd"))
bd = Show(bonds, view)
ColorBy(bd, ("CELLS", "broken_fraction"))
bd.LineWidth = 1.5
Hide(bonds, view)  # switch on in the pipeline browser

cracks = PVDReader(FileName=os.path.join(vtk_dir, "cracks.pvd"))
cd = Show(cracks, view)
ColorBy(cd, ("CELLS", "mode"))
lut = GetColorTransferFunction("mode")
lut.InterpretValuesAsCategories = 1
lut.Annotations = ["1", "tension", "2", "shear"]
lut.IndexedColors = [0.84, 0.15, 0.16, 0.12, 0.25, 0.75]
cd.LineWidth = 3.0

walls = PVDReader(FileName=os.path.join(vtk_dir, "walls.pvd"))
wd = Show(walls, view)
wd.Opacity = 0.2

scene = GetAnimationScene()
scene.UpdateAnimationUsingDataTimeSteps()
scene.AnimationTime = scene.EndTime
ResetCamera(view)
Render(view)
