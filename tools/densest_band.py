#!/usr/bin/env python3
"""Is the post-peak cracking of a 3D UCS localized? (docs/results.md, "Crack maps").

    python3 tools/densest_band.py OUTDIR [--width W_m] [--after-stress F]
    pvbatch tools/densest_band.py OUTDIR --strained Q   # grains, not cracks (needs VTK's python)

Reads OUTDIR/results.json (peak time, specimen cylinder) and OUTDIR/cracks.csv. A broken contact
is placed where its first crack formed; those first broken after the peak (or, with
--after-stress F, after the axial stress fell below F times the peak, read from history.csv) are
counted. Over 3,000 plane orientations it finds the slab of width W (default 2e-3 m) holding the
most of them and prints that share beside the share the densest slab holds for as many points
drawn uniformly in the specimen's cylinder (mean and standard deviation of 5 draws, seeded). A
localized macro-fracture puts far more in its band than the uniform draw; distributed cracking
about the same. With --strained Q it counts instead the grains whose non-affine strain at the
end of the test (the last cells_NNNN.vtp, viz/README.md) is in the top fraction Q (e.g. 0.05):
where the rock came apart rather than where bonds broke. Units: SI (m, s, Pa). Needs numpy.
"""
import argparse
import csv
import json
import os

import numpy as np


def first_breaks(out):
    first = {}
    with open(os.path.join(out, "cracks.csv")) as f:
        for r in csv.DictReader(f):
            if r["contact"] not in first:
                first[r["contact"]] = (float(r["time_s"]), float(r["x_m"]), float(r["y_m"]),
                                       float(r["z_m"]))
    return np.array(list(first.values()))


def strained_grains(out, top):
    """Centres of the grains in the top fraction of non-affine strain at the last snapshot."""
    import glob
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
    files = sorted(glob.glob(os.path.join(out, "vtk", "cells_[0-9]*.vtp")))
    if not files:
        raise SystemExit("%s: no vtk/cells_NNNN.vtp (output.cells off?)" % out)
    r = vtkXMLPolyDataReader()
    r.SetFileName(files[-1])
    r.Update()
    cd = r.GetOutput().GetCellData()
    if cd.GetArray("nonaffine_strain") is None:
        raise SystemExit("%s has no nonaffine_strain: written by an older rocklab" % files[-1])
    grain = vtk_to_numpy(cd.GetArray("grain"))
    _, first = np.unique(grain, return_index=True)  # every face of a cell carries its grain's
    strain = vtk_to_numpy(cd.GetArray("nonaffine_strain"))[first]
    centre = vtk_to_numpy(cd.GetArray("grain_center"))[first].astype(float)
    return centre[strain >= np.quantile(strain, 1 - top)]


def start_time(out, res, fraction):
    if fraction is None:
        return res["peak_time_s"]
    peak = res["peak_stress_Pa"]
    with open(os.path.join(out, "history.csv")) as f:
        for r in csv.DictReader(f):
            t = float(r["time_s"])
            if t > res["peak_time_s"] and float(r["axial_stress_Pa"]) < fraction * peak:
                return t
    raise SystemExit("the axial stress never fell below %g of the peak" % fraction)


def directions(n=3000):
    """Fibonacci points on the upper hemisphere: slab normals."""
    i = np.arange(n) + 0.5
    polar = np.arccos(1 - i / n)
    azimuth = np.pi * (1 + 5 ** 0.5) * i
    return np.stack([np.cos(azimuth) * np.sin(polar), np.sin(azimuth) * np.sin(polar),
                     np.cos(polar)], 1)


def densest(points, width, normals):
    best, normal = 0, None
    for n in normals:
        s = np.sort(points @ n)
        inside = np.searchsorted(s, s + width, side="right") - np.arange(len(s))
        if inside.max() > best:
            best, normal = inside.max(), n
    return best / len(points), normal


def uniform_cylinder(rng, count, spec):
    d, h = spec["diameter_m"], spec["height_m"]
    c = np.array(spec["center_m"])
    pts = []
    while len(pts) < count:
        x, y = rng.uniform(-d / 2, d / 2, 2)
        if x * x + y * y <= d * d / 4:
            pts.append(c + (x, y, rng.uniform(-h / 2, h / 2)))
    return np.array(pts)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out")
    ap.add_argument("--width", type=float, default=2e-3, help="slab width [m]")
    ap.add_argument("--after-stress", type=float, default=None,
                    help="count contacts first broken after the stress fell below F x peak")
    ap.add_argument("--strained", type=float, default=None,
                    help="count the grains in this top fraction of non-affine strain instead")
    a = ap.parse_args()
    with open(os.path.join(a.out, "results.json")) as f:
        res = json.load(f)
    spec = res["specimen"]
    if spec.get("dimension") != 3 or "diameter_m" not in spec:
        raise SystemExit("%s: needs a 3D cylinder test (results.json 'specimen')" % a.out)
    if a.strained is not None:
        if not 0 < a.strained < 1:
            raise SystemExit("--strained must lie in (0, 1), not %g" % a.strained)
        pts = strained_grains(a.out, a.strained)
    else:
        t0 = start_time(a.out, res, a.after_stress)
        breaks = first_breaks(a.out)
        pts = breaks[breaks[:, 0] > t0, 1:]
        if len(pts) < 10:
            raise SystemExit("only %d contacts broke after t = %g s" % (len(pts), t0))
    normals = directions()
    share, n = densest(pts, a.width, normals)
    rng = np.random.default_rng(1)
    ref = [densest(uniform_cylinder(rng, len(pts), spec), a.width, normals)[0] for _ in range(5)]
    if a.strained is not None:
        print("grains counted (top %g of non-affine strain at the end) %d" % (a.strained, len(pts)))
    else:
        print("broken contacts %d, counted (first broken after t = %.6g s) %d" %
              (len(breaks), t0, len(pts)))
    print("densest %.3g m slab: %.1f %% of them (normal %.0f deg from the axis); uniform in the "
          "cylinder: %.1f +- %.1f %%" % (a.width, 100 * share, np.degrees(np.arccos(abs(n[2]))),
                                       100 * np.mean(ref), 100 * np.std(ref)))


if __name__ == "__main__":
    main()
