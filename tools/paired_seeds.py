#!/usr/bin/env python3
"""Paired-seed comparison of a change of the dynamics (docs/results.md, "The rule for a change of
the dynamics"): each preset's suite tests (UCS, Brazilian) on the same specimens, once per
setting (e.g. loading.timestep_safety 0.8 and 1.2), one CSV row per (preset, test, seed, setting);
the tests are the suite's strength tests (UCS, Brazilian, direct tension).
Resumable: rows already in OUT/rows.csv are not run again, and each finished row is appended at
once, so a run longer than a session continues where it stopped (the rows are small: commit them).

  tools/paired_seeds.py run    --out DIR --presets granite_2d,berea --seeds 1-6 --set 0.8,1.2
  tools/paired_seeds.py report --out DIR [--rule]       (paired mean shifts, 95 % intervals)

Each specimen is made once by `rocklab genesis` (DIR/specimens/) and both settings load it, so the
pair differs only in the loading; with --card-key the setting is a card key instead and each
setting has its own specimen of the same seed (a genesis rule). Units SI throughout (Pa, -, s).
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
COLUMNS = ["preset", "test", "seed", "setting", "youngs_modulus_Pa", "poisson_ratio", "strength_Pa",
           "valid", "ledger_error", "loading_steps", "steps", "wall_s", "stop_reason", "warnings"]
# Half the calibration tolerance of each strength (docs/calibration.md; the rule's bound).
HALF_TOLERANCE = {"ucs": 0.025, "brazilian": 0.04, "direct_tension": 0.04}


def suite_tests(preset):
    """SUITE (lab/suites/SUITE.json) or SUITE:CARD (that suite's tests on materials/CARD.json, for
    a preset without a suite of its own, e.g. granite_2d:berea_fj_2d)."""
    name, _, card = preset.partition(":")
    suite = json.load(open(os.path.join(ROOT, "lab", "suites", name + ".json")))
    material = os.path.normpath(os.path.join(ROOT, "lab", "suites", suite["material"]))
    if card:
        material = os.path.join(ROOT, "materials", card + ".json")
    return material, [t for t in suite["tests"] if t["test"] in HALF_TOLERANCE]


def seeds_of(text):
    out = []
    for part in text.split(","):
        a, _, b = part.partition("-")
        out += list(range(int(a), int(b or a) + 1))
    return out


def done_rows(path):
    if not os.path.exists(path):
        return {}
    with open(path) as f:
        return {(r["preset"], r["test"], r["seed"], r["setting"]): r for r in csv.DictReader(f)}


def append_row(path, columns, row, extras="raise"):
    """One finished row appended to a rows CSV (its header first when the file is new); keys
    outside `columns` raise, or with extras="ignore" are left out."""
    new = not os.path.exists(path)
    with open(path, "a", newline="") as f:
        w = csv.DictWriter(f, columns, extrasaction=extras)
        if new:
            w.writeheader()
        w.writerow(row)


def run(cmd, log):
    with open(log, "w") as out:
        return subprocess.call(cmd, stdout=out, stderr=subprocess.STDOUT)


def card_value(text):
    """A setting or card value as written: an integer stays an integer (the card refuses 1.0 for
    an integer key such as flatjoint.fj_Nr or installation.stiffness_ramp)."""
    return int(text) if text.lstrip("-").isdigit() else float(text)


def card_for(args, material, setting):
    """With --card-key (a genesis setting, e.g. packing.equilibrium_ratio): a copy of the card
    with that key set, so that each setting has its own specimen; else the card itself."""
    if not args.card_key:
        return material
    card = json.load(open(material))
    *path, last = args.card_key.split(".")
    node = card
    for k in path:
        node = node.setdefault(k, {})
    node[last] = card_value(setting)
    out = os.path.join(args.out, "cards", "%s_%s.json" % (os.path.basename(material)[:-5],
                                                           setting))
    os.makedirs(os.path.dirname(out), exist_ok=True)
    json.dump(card, open(out, "w"), indent=1)
    return out


def specimen(args, material, test, seed):
    # Tests on the card's own specimen shape (UCS, direct tension) share one specimen per seed.
    shaped = "shape" in test or "cut" in test
    name = "%s_%s_%d.rlspec" % (os.path.basename(material)[:-5], test["name"] if shaped else "ucs",
                                seed)
    path = os.path.join(args.out, "specimens", name)
    if not os.path.exists(path):
        os.makedirs(os.path.dirname(path), exist_ok=True)
        cmd = [args.rocklab, "genesis", material, "-o", path, "--seed", str(seed), "-q",
               "--threads", str(args.threads)]
        if "shape" in test:
            cmd += ["--shape", json.dumps(test["shape"])]
        if "cut" in test:
            cmd += ["--cut", json.dumps(test["cut"])]
        if run(cmd, path + ".log") != 0:
            return None
    return path


def one_row(args, preset, test, seed, setting, spec):
    proto = {k: v for k, v in test.items() if k not in ("name", "shape", "cut")}
    proto.update({"units": "SI", "specimen": {"file": spec}, "output": {"vtk": False,
                                                                         "plots": False}})
    if not args.card_key:
        proto.setdefault("loading", {})[args.key] = float(setting)
    tag = "%s_%s_%d_%s" % (preset.replace(":", "-"), test["name"], seed, setting)
    work = os.path.join(args.out, "runs", tag)
    os.makedirs(os.path.dirname(work), exist_ok=True)
    pfile = work + ".json"
    json.dump(proto, open(pfile, "w"), indent=1)
    t0 = time.time()
    status = run([args.rocklab, "test", pfile, "-o", work, "-q", "--threads", str(args.threads)],
                 work + ".log")
    row = {"preset": preset, "test": test["name"], "seed": seed, "setting": setting,
           "wall_s": "%.0f" % (time.time() - t0)}
    if status < 0:  # killed (the session ended): no row, so that a later run repeats it
        sys.exit("rocklab was killed by signal %d: stopped without a row" % -status)
    if status != 0:
        row["stop_reason"] = "exit %d" % status
        return row
    r = json.load(open(os.path.join(work, "results.json")))
    strength = r.get("peak_stress_Pa") if test["test"] == "ucs" else r.get("tensile_strength_Pa")
    valid = r.get("fracture_origin", {}).get("valid", "") if test["test"] == "brazilian" else ""
    row.update({"youngs_modulus_Pa": r.get("youngs_modulus_Pa", ""),
                "poisson_ratio": r.get("poisson_ratio", ""),
                "strength_Pa": "" if strength is None else strength, "valid": valid,
                "ledger_error": abs(r.get("energy_J", {}).get("balance_error_relative", 0)),
                "loading_steps": r["provenance"]["steps"] - r.get("load_start_step", 0),
                "steps": r["provenance"]["steps"], "stop_reason": r.get("stop_reason", ""),
                "warnings": " | ".join(r.get("warnings", []))[:300]})
    return row


def cmd_run(args):
    os.makedirs(args.out, exist_ok=True)
    rows_path = os.path.join(args.out, "rows.csv")
    done = done_rows(rows_path)
    for preset in args.presets.split(","):
        material, tests = suite_tests(preset)
        for seed in seeds_of(args.seeds):
            for test in tests:
                if args.tests and test["name"] not in args.tests.split(","):
                    continue
                todo = [s for s in args.set.split(",")
                        if (preset, test["name"], str(seed), s) not in done]
                if not todo:
                    continue
                for setting in todo:
                    spec = specimen(args, card_for(args, material, setting), test, seed)
                    row = one_row(args, preset, test, seed, setting, spec) if spec else {
                        "preset": preset, "test": test["name"], "seed": seed,
                        "setting": setting, "stop_reason": "genesis failed"}
                    append_row(rows_path, COLUMNS, row)
                    print("%s %s seed %d %s: %s (%s s)" % (preset, test["name"], seed, setting,
                                                           row.get("strength_Pa", "-"),
                                                           row.get("wall_s")), flush=True)


def t95(n):
    table = {1: 12.71, 2: 4.303, 3: 3.182, 4: 2.776, 5: 2.571, 6: 2.447, 7: 2.365, 8: 2.306,
             9: 2.262, 10: 2.228, 11: 2.201, 12: 2.179, 14: 2.145, 19: 2.093, 29: 2.045}
    return table.get(n, table[max(k for k in table if k <= n)] if n < 30 else 1.96)


def num(x):
    try:
        return float(x)
    except (TypeError, ValueError):
        return float("nan")


def mean_ci(xs):
    """The mean of paired differences and the half-width of its 95 % Student-t interval."""
    n = len(xs)
    if n == 0:
        return float("nan"), float("nan")
    m = sum(xs) / n
    if n == 1:
        return m, float("nan")
    sd = math.sqrt(sum((x - m) ** 2 for x in xs) / (n - 1))
    return m, t95(n - 1) * sd / math.sqrt(n)


def spread(xs, scale, fmt):
    """A property's paired shift: mean +- 95 % half-width, and the largest single pair."""
    fin = [x for x in xs if math.isfinite(x)]
    if not fin:
        return "-"
    m, h = mean_ci(fin)
    largest = max(fin, key=abs)
    if len(fin) == 1:
        return (fmt % (scale * m)) + " (one pair)"
    return "%s +- %s (largest %s)" % (fmt % (scale * m), (fmt % (scale * h)).lstrip("+"),
                                      fmt % (scale * largest))


def window_fit(run_dir, window):
    """E and nu by least squares over the loading branch between two deviator levels [Pa] (the
    base run's elastic window), from history.csv: the same stresses in both runs of a pair, so a
    crack onset that comes a little earlier or later (chaotic) does not move the window."""
    path = os.path.join(run_dir, "history.csv")
    if not os.path.exists(path) or not window:
        return float("nan"), float("nan")
    xs, ys, ls = [], [], []
    with open(path) as f:
        for r in csv.DictReader(f):
            if r["phase"] != "2":
                continue
            q = float(r["deviator_Pa"])
            if q > window[1]:
                break
            if q >= window[0]:
                xs.append(float(r["axial_strain"]))
                ys.append(q)
                ls.append(float(r["lateral_strain"]))
    if len(xs) < 3:
        return float("nan"), float("nan")
    def slope(a, b):
        ma, mb = sum(a) / len(a), sum(b) / len(b)
        return sum((x - ma) * (y - mb) for x, y in zip(a, b)) / sum((x - ma) ** 2 for x in a)
    return slope(xs, ys), -slope(xs, ls)


def cmd_report(args):
    rows = list(done_rows(os.path.join(args.out, "rows.csv")).values())
    base = args.base
    groups = {}
    for r in rows:
        groups.setdefault((r["preset"], r["test"]), {}).setdefault(r["seed"], {})[r["setting"]] = r
    print("| preset | test | setting | seeds | E shift, mean +- 95 % (same window) | nu shift, mean "
          "+- 95 % | strength shift, mean "
          "[95 % interval] | within +-half tolerance | largest ledger error (at the base) | loading steps |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for (preset, test), by_seed in sorted(groups.items()):
        settings = sorted({s for d in by_seed.values() for s in d if s != base}, key=float)
        for s in settings:
            de, dn, ds, ledger, ledger0, steps = [], [], [], [], [], []
            for seed, d in by_seed.items():
                if base not in d or s not in d:
                    continue
                a, b = d[base], d[s]
                ledger.append(num(b["ledger_error"]))
                ledger0.append(num(a["ledger_error"]))
                if num(a["loading_steps"]) > 0:
                    steps.append(num(b["loading_steps"]) / num(a["loading_steps"]) - 1)
                if num(a["youngs_modulus_Pa"]) > 0:
                    # over the base run's window in both (history.csv), where the runs are kept
                    runs = os.path.join(args.out, "runs")
                    tag = lambda r: "%s_%s_%s_%s" % (preset.replace(":", "-"), test, r["seed"],
                                                     r["setting"])
                    try:
                        w = json.load(open(os.path.join(runs, tag(a), "results.json")))[
                            "elastic_fit"]["window_Pa"]
                    except (OSError, KeyError, ValueError):
                        w = None
                    ea, na = window_fit(os.path.join(runs, tag(a)), w)
                    eb, nb = window_fit(os.path.join(runs, tag(b)), w)
                    if math.isfinite(ea) and math.isfinite(eb):
                        de.append(eb / ea - 1)
                        dn.append(nb - na)
                    else:
                        de.append(num(b["youngs_modulus_Pa"]) / num(a["youngs_modulus_Pa"]) - 1)
                        dn.append(num(b["poisson_ratio"]) - num(a["poisson_ratio"]))
                if num(a["strength_Pa"]) > 0 and num(b["strength_Pa"]) > 0:
                    ds.append(num(b["strength_Pa"]) / num(a["strength_Pa"]) - 1)
            n = len(ds)
            if n == 0:
                continue
            m, h = mean_ci(ds)
            half = HALF_TOLERANCE.get(test, 0.025)
            ok = n >= 6 and abs(m) + h <= half
            interval = "[%+.2f, %+.2f]" % (100 * (m - h), 100 * (m + h)) if n > 1 else "(one pair)"
            print("| %s | %s | %s | %d | %s | %s | %+.2f %% %s | %s | %.3f %% (%.3f %%) | %s |" % (
                preset, test, s, n,
                spread(de, 100, "%+.3f %%"), spread(dn, 1, "%+.4f"),
                100 * m, interval,
                ("yes" if ok else "no") + ("" if n >= 6 else " (fewer than 6 seeds)"),
                100 * max(ledger) if ledger else float("nan"),
                100 * max(ledger0) if ledger0 else float("nan"),
                "%+.0f %%" % (100 * sum(steps) / len(steps)) if steps else "-"))


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run")
    r.add_argument("--out", required=True)
    r.add_argument("--presets", required=True, help="suite names in lab/suites, comma-separated")
    r.add_argument("--seeds", default="1-6")
    r.add_argument("--set", default="0.8,1.2", help="the settings, comma-separated")
    r.add_argument("--key", default="timestep_safety", help="the loading key the setting sets")
    r.add_argument("--card-key", default="",
                   help="set the setting on this card key instead (genesis: each setting its own "
                        "specimen), e.g. packing.equilibrium_ratio")
    r.add_argument("--tests", default="", help="only these suite test names")
    r.add_argument("--threads", default="1")
    r.add_argument("--rocklab", default=os.path.join(ROOT, "build", "rocklab"))
    q = sub.add_parser("report")
    q.add_argument("--out", required=True)
    q.add_argument("--base", default="0.8")
    args = p.parse_args()
    return cmd_run(args) if args.cmd == "run" else cmd_report(args)


if __name__ == "__main__":
    sys.exit(main())
