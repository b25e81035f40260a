#!/usr/bin/env python3
"""Parameter study: UCS and Young's modulus of the 2D flat-jointed granite against its flat-joint
tensile strength fj_ten and its slit fraction, over three seeds, as a matplotlib figure.

Each point is a genesis and a UCS test run in-process by rocklab.test; two run side by side on
two Python threads (rocklab releases the GIL), one OpenMP thread each. The specimen is the card's
25 mm x 50 mm rectangle shrunk to 16 mm x 32 mm (about 460 grains, porosity 0.19 instead of
0.18 for so narrow a vessel) so the study takes minutes;
its numbers are a small specimen's, not the calibrated card's (docs/results.md). Units: SI (the
figure shows MPa and GPa).

    PYTHONPATH=build/python python3 examples/python/param_study.py -o out/study
    PYTHONPATH=build/python python3 examples/python/param_study.py -o out/tiny --tiny   # seconds
"""
import argparse
import json
import os
import sys
import time
from concurrent.futures import ThreadPoolExecutor

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import rocklab  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def study_plan(tiny):
    """The card, the specimen override, the values of fj_ten [Pa] and of the slit fraction (each
    varied with the other at the card's value, the first of its list), the seeds and the strain
    at which a test stops."""
    if tiny:  # the unit tests' 2D card: a few seconds a point
        card = os.path.join(ROOT, "tests", "data", "lab_2d_fj.json")
        return card, {}, [2e6, 1.5e6], [0.1, 0.3], [1], 0.004
    card = os.path.join(ROOT, "materials", "granite_fj_2d.json")
    # 25 grains across: the walls loosen the packing, so porosity 0.19 (the card's 0.18 is below
    # what some seeds reach in so small a vessel; genesis says so and stops).
    specimen = {"specimen": {"shape": "rectangle", "width": 0.016, "height": 0.032},
                "porosity": 0.19}
    return card, specimen, [3.5e7, 2.5e7, 4.5e7], [0.1, 0.05, 0.2], [1, 2, 3], 0.02


def ucs_point(card, overrides, seed, strain_limit):
    """E [Pa] and UCS [Pa] of one specimen: the card with `overrides`, genesis with `seed`."""
    spec = rocklab.genesis(card, seed=seed, threads=1, overrides=overrides)
    protocol = {"test": "ucs", "units": "SI", "stop": {"strain_limit": strain_limit},
                "output": {"vtk": False, "plots": False}}
    r = rocklab.test(protocol, specimen=spec, threads=1)
    return r.results["youngs_modulus_Pa"], r.results["peak_stress_Pa"]


def run_study(tiny, jobs):
    card, base, tens, slits, seeds, strain_limit = study_plan(tiny)
    # (fj_ten, slit) pairs: the card's own pair is on both lines and runs once.
    pairs = sorted({(t, slits[0]) for t in tens} | {(tens[0], s) for s in slits})
    runs = [(pair, seed) for pair in pairs for seed in seeds]

    def one(run):
        (ten, slit), seed = run
        over = dict(base, **{"flatjoint.fj_ten": ten, "flatjoint.types.slit": slit})
        return ucs_point(card, over, seed, strain_limit)

    with ThreadPoolExecutor(max_workers=jobs) as pool:
        measured = dict(zip(runs, pool.map(one, runs)))
    rows = []
    for name, values in (("fj_ten", tens), ("slit", slits)):
        for value in values:
            pair = (value, slits[0]) if name == "fj_ten" else (tens[0], value)
            for seed in seeds:
                e, ucs = measured[(pair, seed)]
                rows.append(dict(parameter=name, value=value, seed=seed, youngs_modulus_Pa=e,
                                 ucs_Pa=ucs))
    return rows


def plot(rows, path):
    fig, axes = plt.subplots(2, 2, figsize=(8, 6.4), constrained_layout=True)
    for col, (param, label, scale) in enumerate([("fj_ten", "flat-joint tensile strength "
                                                  "fj_ten [MPa]", 1e-6),
                                                 ("slit", "slit fraction [-]", 1.0)]):
        sel = [r for r in rows if r["parameter"] == param]
        values = sorted({r["value"] for r in sel})
        for row, (key, ylabel, yscale) in enumerate([("ucs_Pa", "UCS [MPa]", 1e-6),
                                                     ("youngs_modulus_Pa", "E [GPa]", 1e-9)]):
            ax = axes[row][col]
            x = np.array([r["value"] for r in sel]) * scale
            y = np.array([r[key] for r in sel]) * yscale
            ax.plot(x, y, "o", color="0.6", ms=4, label="one seed")
            means = [np.mean([r[key] for r in sel if r["value"] == v]) * yscale for v in values]
            sds = [np.std([r[key] for r in sel if r["value"] == v], ddof=1) * yscale
                   if sum(r["value"] == v for r in sel) > 1 else 0 for v in values]
            ax.errorbar(np.array(values) * scale, means, yerr=sds, color="C0", marker="s",
                        capsize=3, label="mean ± sd over seeds")
            ax.set_xlabel(label)
            ax.set_ylabel(ylabel)
            ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=8)
    fig.suptitle("2D flat-jointed granite (16 mm × 32 mm, ~460 grains): UCS and E against "
                 "micro-parameters", fontsize=10)
    fig.savefig(path, dpi=110)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-o", "--out", required=True, help="output folder (study.json, study.png)")
    ap.add_argument("--tiny", action="store_true", help="the unit tests' tiny card, 4 points")
    ap.add_argument("--jobs", type=int, default=2, help="tests at once (default 2)")
    a = ap.parse_args(argv)
    os.makedirs(a.out, exist_ok=True)
    t0 = time.time()
    rows = run_study(a.tiny, a.jobs)
    with open(os.path.join(a.out, "study.json"), "w", encoding="utf-8") as f:
        json.dump({"units": "SI", "rows": rows}, f, indent=1)
    plot(rows, os.path.join(a.out, "study.png"))
    print("%d points in %.0f s; wrote %s/study.json, study.png" % (len(rows), time.time() - t0,
                                                                   a.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
