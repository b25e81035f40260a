#!/usr/bin/env python3
"""An external calibration loop: scipy's least squares fits the flat-joint modulus fj_emod and
tensile strength fj_ten of a small 2D card to a target E and UCS, calling rocklab in-process.

The same seeds are used for every candidate (common random numbers: only the parameters change
between evaluations), the parameters are fitted in log space, and the Jacobian is taken by
forward differences of 5 %: a bonded-particle UCS is not smooth at smaller steps. This is the loop a Bayesian
calibrator (GrainLearning and similar) drives; rocklab's own `rocklab calibrate` adds the staged
search, noise-aware seeds and validation on fresh seeds (docs/calibration.md). Units: SI.

    PYTHONPATH=build/python python3 examples/python/calibrate_scipy.py
"""
import argparse
import os
import sys

import numpy as np
from scipy.optimize import least_squares

import rocklab

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CARD = os.path.join(ROOT, "materials", "granite_fj_2d.json")
# The example study's small specimen: 16 mm x 32 mm, about 460 grains, porosity 0.19.
SMALL = {"specimen": {"shape": "rectangle", "width": 0.016, "height": 0.032}, "porosity": 0.19}


def measure(emod, ten, seeds):
    """Mean E [Pa] and UCS [Pa] over `seeds` of the small card with fj_emod and fj_ten set (the
    linear modulus follows fj_emod, the cohesion stays 10 x the tension)."""
    e, ucs = [], []
    for seed in seeds:
        over = dict(SMALL, **{"flatjoint.fj_emod": emod, "linear.emod": emod,
                              "flatjoint.fj_ten": ten, "flatjoint.fj_coh": 10 * ten})
        spec = rocklab.genesis(CARD, seed=seed, overrides=over)
        r = rocklab.test({"test": "ucs", "units": "SI", "stop": {"strain_limit": 0.02},
                          "output": {"vtk": False, "plots": False}}, specimen=spec)
        e.append(r.results["youngs_modulus_Pa"])
        ucs.append(r.results["peak_stress_Pa"])
    return np.mean(e), np.mean(ucs)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--E", type=float, default=60e9, help="target Young's modulus [Pa]")
    ap.add_argument("--ucs", type=float, default=150e6, help="target UCS [Pa]")
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--max-evaluations", type=int, default=8,
                    help="least_squares iterations' evaluations (each adds 2 for its Jacobian)")
    a = ap.parse_args(argv)
    log = []
    start = np.array([1e11, 3.5e7])  # the card's fj_emod and fj_ten [Pa]
    cache = {}

    def residuals(x):  # x: log of the parameters over their start values
        key = tuple(np.round(x, 12))
        if key not in cache:
            emod, ten = start * np.exp(x)
            e, ucs = measure(emod, ten, a.seeds)
            log.append((emod, ten, e, ucs))
            print("fj_emod %.4g Pa  fj_ten %.4g Pa  ->  E %.4g Pa (%+.1f %%)  UCS %.4g Pa "
                  "(%+.1f %%)" % (emod, ten, e, 100 * (e / a.E - 1), ucs,
                                  100 * (ucs / a.ucs - 1)), flush=True)
            cache[key] = np.array([e / a.E - 1, ucs / a.ucs - 1])
        return cache[key]

    def jacobian(x):
        # Forward differences of 5 % in each parameter (0.05 in x). scipy's own steps are relative
        # to x, which starts at 0, and fall back to 1e-8: a bonded-particle UCS changes by tens of
        # % for such a step (the packing's fracture path is chaotic), so that slope is noise.
        f0 = residuals(x)
        return np.column_stack([(residuals(x + 0.05 * np.eye(2)[i]) - f0) / 0.05
                                for i in range(2)])

    # x_scale: the first steps change a parameter by about 30 %, not by a factor e.
    fit = least_squares(residuals, np.zeros(2), jac=jacobian, x_scale=0.3,
                        max_nfev=a.max_evaluations, xtol=1e-3, ftol=1e-3)
    emod, ten = start * np.exp(fit.x)
    print("fitted fj_emod %.4g Pa, fj_ten %.4g Pa after %d runs (%s); residuals %s"
          % (emod, ten, len(log), fit.message, np.round(fit.fun, 4)))
    print("Check the fitted card on seeds it was not fitted on before trusting it.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
