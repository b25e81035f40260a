"""Checks a picture written by viz/rocklab_paraview.py (run with pvbatch or pvpython):

    pvbatch tests/render/check_png.py PICTURE.png

- not empty: at least 15 % of the pixels differ from the white background;
- the specimen fills a good part of the frame: the drawn region (the bounding box of the
  non-background pixels, legends excluded by looking at the middle 60 % of the width) spans at
  least half the picture's height;
- cracks are visible: at least 0.5 % of the pixels are saturated crack colours (the Inferno
  palette's reds/oranges/yellows or the mode palette), not greys;
- legends are drawn: dark text pixels in the lower-left legend region.
Exit status 1 with the reason when a check fails.
"""
import sys

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOImage import vtkPNGReader


def main(path):
    r = vtkPNGReader()
    r.SetFileName(path)
    r.Update()
    img = r.GetOutput()
    w, h, _ = img.GetDimensions()
    if w == 0 or h == 0:
        raise SystemExit("%s: not a PNG picture" % path)
    a = vtk_to_numpy(img.GetPointData().GetScalars()).reshape(h, w, -1)[:, :, :3].astype(int)
    bg = np.all(a >= 250, axis=2)
    drawn = 1.0 - bg.mean()
    mid = ~bg[:, int(0.2 * w):int(0.8 * w)]
    rows = np.where(mid.any(axis=1))[0]
    height = (rows.max() - rows.min() + 1) / h if rows.size else 0.0
    rgb = a.reshape(-1, 3)
    sat = rgb.max(axis=1) - rgb.min(axis=1)
    crack = (sat > 80).mean()
    legend = a[int(0.45 * h):, : int(0.3 * w)]
    text = np.all(legend < 90, axis=2).mean()
    print("%s: %dx%d, drawn %.1f %%, specimen height %.1f %% of the frame, crack colours %.2f %%,"
          " legend text %.2f %%" % (path, w, h, 100 * drawn, 100 * height, 100 * crack, 100 * text))
    failures = []
    if drawn < 0.15:
        failures.append("less than 15 % of the picture is drawn")
    if height < 0.5:
        failures.append("the specimen spans less than half the picture's height")
    if crack < 0.005:
        failures.append("no visible cracks (saturated colours < 0.5 %)")
    if text < 0.001:
        failures.append("no legend text in the lower left")
    if failures:
        raise SystemExit("%s: %s" % (path, "; ".join(failures)))


if __name__ == "__main__":
    main(sys.argv[1])
