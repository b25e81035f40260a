#!/usr/bin/env python3
"""Trial cards: a preset's strength tests (UCS, Brazilian, direct tension) on cards that differ from
the preset's card in a few keys, each on a few seeds, to map what the card's shape parameters can
reach (docs/results.md, issue 55 item 3: the reachable UCS/BTS and UCS/direct tension). Units SI.

  tools/trial_cards.py run --out DIR --preset granite --seeds 1-2 \\
      --trial base= --trial gap0.3=installation.gap_ratio:0.3,flatjoint.types.slit:0.4
  tools/trial_cards.py report --out DIR [--svg FILE]

A trial is NAME=KEY:VALUE,... (dotted card keys; an empty list is the card itself). A key written
A/B sets A to VALUE times B (e.g. flatjoint.fj_ten.sd/flatjoint.fj_ten.mean:0.45, a tension CoV).
Strength ratios (UCS/BTS, UCS/DT, CI/UCS) do not depend on the strengths' common scale (a bonded
packing with Coulomb friction is homogeneous of degree one in its strengths, materials/*.json), so
a trial's ratios are what a card of its shape reaches at any strength. Resumable: OUT/rows.csv
keeps one row per (trial, test, seed), appended as each run ends; rows already there are not run
again. The specimens and runs are kept under OUT (specimens/, runs/).
"""
import argparse
import csv
import json
import math
import os
import sys
from types import SimpleNamespace

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import paired_seeds as ps  # noqa: E402  (the run and specimen helpers)

COLUMNS = ["trial", "test", "seed", "strength_Pa", "youngs_modulus_Pa", "poisson_ratio",
           "ci_ratio", "ci_volumetric_ratio", "valid", "ledger_error", "steps", "wall_s",
           "stop_reason", "card_changes"]
# Lac du Bonnet (../shared/reference/rock-targets.md): the ratios a granite card aims at.
TARGET = {"ucs_over_bts": 21.5, "ucs_over_dt": 200 / 6.9, "nu": 0.26}


def parse_trial(text):
    name, _, rest = text.partition("=")
    changes = []
    for item in filter(None, rest.split(",")):
        key, _, value = item.rpartition(":")
        if not key:
            sys.exit("trial %s: '%s' is not KEY:VALUE" % (name, item))
        changes.append((key, ps.card_value(value)))
    return name, changes


def node_at(card, dotted, create=False):
    *path, last = dotted.split(".")
    node = card
    for k in path:
        if k not in node:
            if not create:
                sys.exit("card key '%s' not found" % dotted)
            node[k] = {}
        node = node[k]
    return node, last


def trial_card(out, material, name, changes):
    card = json.load(open(material))
    for key, value in changes:
        a, _, b = key.partition("/")
        if b:
            bn, bl = node_at(card, b)
            value *= float(bn[bl])
        n, last = node_at(card, a, create=True)
        n[last] = value
    # Relative paths in the card (none today) would break in the copy; keep the card's folder.
    path = os.path.join(out, "cards", "%s_%s.json" % (os.path.basename(material)[:-5], name))
    os.makedirs(os.path.dirname(path), exist_ok=True)
    json.dump(card, open(path, "w"), indent=1)
    return path


def cmd_run(args):
    os.makedirs(args.out, exist_ok=True)
    rows_path = os.path.join(args.out, "rows.csv")
    done = {}
    if os.path.exists(rows_path):
        done = {(r["trial"], r["test"], r["seed"]) for r in csv.DictReader(open(rows_path))}
    material, tests = ps.suite_tests(args.preset)
    run_args = SimpleNamespace(out=args.out, rocklab=args.rocklab, threads=args.threads,
                               card_key="trial", key="")
    for name, changes in map(parse_trial, args.trial):
        card = trial_card(args.out, material, name, changes)
        for seed in ps.seeds_of(args.seeds):
            for test in tests:
                if args.tests and test["name"] not in args.tests.split(","):
                    continue
                if (name, test["name"], str(seed)) in done:
                    continue
                spec = ps.specimen(run_args, card, test, seed)
                row = {"trial": name, "test": test["name"], "seed": seed,
                       "stop_reason": "genesis failed"}
                if spec:
                    r = ps.one_row(run_args, args.preset, test, seed, name, spec)
                    row.update({k: r.get(k, "") for k in COLUMNS if k in r})
                    row.update(crack_initiation(args.out, args.preset, test["name"], seed, name))
                row["card_changes"] = " ".join("%s=%g" % c for c in changes)
                ps.append_row(rows_path, COLUMNS, row, extras="ignore")
                print("%s %s seed %d: %s (%s s)" % (name, test["name"], seed,
                                                   row.get("strength_Pa", "-"), row.get("wall_s")),
                      flush=True)


def crack_initiation(out, preset, test, seed, name):
    tag = "%s_%s_%d_%s" % (preset.replace(":", "-"), test, seed, name)
    try:
        cs = json.load(open(os.path.join(out, "runs", tag, "results.json")))["crack_stresses"]
    except (OSError, KeyError, ValueError):
        return {}
    f = lambda v: "" if v is None else v
    return {"ci_ratio": f(cs.get("crack_initiation_ratio")),
            "ci_volumetric_ratio": f(cs.get("crack_initiation_volumetric_ratio"))}


def mean(xs):
    xs = [x for x in xs if math.isfinite(x)]
    return sum(xs) / len(xs) if xs else float("nan")


def per_seed(tests):
    """Each seed's own ratios and Poisson's ratio (the figure's bars), seeds with both tests only."""
    by = lambda test: {r["seed"]: r for r in tests.get(test, [])}
    ucs, bts, dt = by("ucs"), by("brazilian"), by("direct_tension")
    s = lambda rows, k: ps.num(rows[k]["strength_Pa"])
    return {"ucs_over_dt": [s(ucs, k) / s(dt, k) for k in ucs if k in dt],
            "ucs_over_bts": [s(ucs, k) / s(bts, k) for k in ucs if k in bts],
            "nu": [ps.num(r["poisson_ratio"]) for r in ucs.values()]}


def summarize(out):
    rows = list(csv.DictReader(open(os.path.join(out, "rows.csv"))))
    trials = {}
    for r in rows:
        t = trials.setdefault(r["trial"], {"changes": r["card_changes"], "tests": {}})
        t["tests"].setdefault(r["test"], []).append(r)
    summary = []
    for name, t in trials.items():
        g = lambda test, col: [ps.num(r[col]) for r in t["tests"].get(test, [])]
        ucs, bts, dt = mean(g("ucs", "strength_Pa")), mean(g("brazilian", "strength_Pa")), \
            mean(g("direct_tension", "strength_Pa"))
        valid = [r["valid"] for r in t["tests"].get("brazilian", [])]
        ci = mean(g("ucs", "ci_volumetric_ratio"))
        summary.append({"trial": name, "changes": t["changes"] or "(the card)",
                        "seeds": len(t["tests"].get("ucs", [])),
                        "E": mean(g("ucs", "youngs_modulus_Pa")), "nu": mean(g("ucs", "poisson_ratio")),
                        "ucs": ucs, "bts": bts, "dt": dt,
                        "valid": "%d of %d" % (valid.count("True"), len(valid)) if valid else "-",
                        "ucs_over_bts": ucs / bts, "ucs_over_dt": ucs / dt, "ci": ci,
                        "per_seed": per_seed(t["tests"])})
    return summary


def fmt(v, f="%.1f", scale=1.0):
    return f % (v / scale) if math.isfinite(v) else "-"


def step_of(span):
    """A round tick step giving 4-8 ticks over span."""
    base = 10 ** math.floor(math.log10(span / 5))
    return next(m * base for m in (1, 2, 5, 10) if span / (m * base) <= 8)


def nice_range(values):
    """The means' range padded to round ticks (bars reaching past it are clipped at the frame)."""
    lo, hi = min(values), max(values)
    step = step_of((hi - lo) * 1.2 or 1.0)
    return math.floor(lo / step - 0.3) * step, math.ceil(hi / step + 0.3) * step


def ticks_of(lo, hi):
    step = step_of(hi - lo)
    return [k * step for k in range(math.ceil(lo / step - 1e-9), math.floor(hi / step + 1e-9) + 1)]


def panel(e, box, pts, xlab, ylab, target, yticks="%g"):
    """One scatter panel in box (left, top, width, height): points (x, y, xlo, xhi, ylo, yhi, name)
    with their seeds' range as bars, the rock's pair as a red cross."""
    left, top, w, h = box
    (x0, x1), (y0, y1) = [nice_range([p[i] for p in pts] + [target[i]]) for i in (0, 1)]
    X = lambda x: left + (min(max(x, x0), x1) - x0) / (x1 - x0) * w
    Y = lambda y: top + h - (min(max(y, y0), y1) - y0) / (y1 - y0) * h
    e.append('<rect x="%d" y="%d" width="%d" height="%d" fill="none" stroke="black"/>'
             % (left, top, w, h))
    for v in ticks_of(x0, x1):
        e.append('<text x="%.0f" y="%d" text-anchor="middle">%g</text>' % (X(v), top + h + 16, v))
    for v in ticks_of(y0, y1):
        e.append('<text x="%d" y="%.0f" text-anchor="end">%s</text>' % (left - 6, Y(v) + 4, yticks % v))
    e.append('<text x="%d" y="%d" text-anchor="middle">%s</text>' % (left + w // 2, top + h + 36, xlab))
    cy = top + h // 2
    e.append('<text x="%d" y="%d" transform="rotate(-90 %d %d)" text-anchor="middle">%s</text>'
             % (left - 44, cy, left - 44, cy, ylab))
    tx, ty = X(target[0]), Y(target[1])
    e.append('<path d="M%.0f %.0f l12 12 m0 -12 l-12 12" stroke="#c00" stroke-width="2"/>'
             % (tx - 6, ty - 6))
    e.append('<text x="%.0f" y="%.0f" fill="#c00" text-anchor="end">Lac du Bonnet</text>'
             % (tx - 8, ty + 18))
    for x, y, xlo, xhi, ylo, yhi, name in pts:
        e.append('<path d="M%.1f %.1f H%.1f M%.1f %.1f V%.1f" stroke="#88a"/>'
                 % (X(xlo), Y(y), X(xhi), X(x), Y(ylo), Y(yhi)))
        e.append('<circle cx="%.1f" cy="%.1f" r="4" fill="#246"/>' % (X(x), Y(y)))
        e.append('<text x="%.1f" y="%.1f">%s</text>' % (X(x) + 6, Y(y) - 5, name))


def svg(summary, path):
    """Left: UCS/BTS against UCS/direct tension (the trials with a disk); right: Poisson's ratio
    against UCS/direct tension (every trial: what the shape keys cost in the elastic targets).
    One point per trial (its seeds' mean ratio), bars over its seeds' range."""
    def rng(s, key):
        v = [x for x in s["per_seed"][key] if math.isfinite(x)]
        return (min(v), max(v)) if v else (float("nan"),) * 2
    left, right = [], []
    for s in summary:
        if not math.isfinite(s["ucs_over_dt"]):
            continue
        xr = rng(s, "ucs_over_dt")
        right.append((s["ucs_over_dt"], s["nu"]) + xr + rng(s, "nu") + (s["trial"],))
        if math.isfinite(s["ucs_over_bts"]):
            left.append((s["ucs_over_dt"], s["ucs_over_bts"]) + xr + rng(s, "ucs_over_bts")
                        + (s["trial"],))
    W, H = 1100, 470
    e = ['<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" font-family="sans-serif" '
         'font-size="12"><rect width="100%%" height="100%%" fill="white"/>' % (W, H),
         '<text x="%d" y="22" text-anchor="middle" font-size="14">3D flat-jointed granite: what the '
         'card\'s shape keys reach (seeds\' mean, bars: their range)</text>' % (W // 2)]
    if left:
        panel(e, (80, 50, 420, 350), left, "UCS / direct tension [-]", "UCS / BTS [-]",
              (TARGET["ucs_over_dt"], TARGET["ucs_over_bts"]))
    panel(e, (630, 50, 420, 350), right, "UCS / direct tension [-]", "Poisson's ratio [-]",
          (TARGET["ucs_over_dt"], TARGET["nu"]), yticks="%.2f")
    e.append('<text x="80" y="%d" fill="#555">Bars reaching past a frame are cut at it. Trials: '
             'tools/trial_cards.py; rows: docs/data/issue55/shape_sweep_rows.csv. Units SI.</text>'
             % (H - 12))
    e.append("</svg>")
    open(path, "w").write("\n".join(e) + "\n")


def cmd_report(args):
    summary = summarize(args.out)
    print("| trial | card changes | seeds | E [GPa] | nu | UCS [MPa] | BTS [MPa] (valid) | DT [MPa] "
          "| UCS/BTS | UCS/DT | CI/UCS (volumetric) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for s in summary:
        print("| %s | %s | %d | %s | %s | %s | %s (%s) | %s | %s | %s | %s |" % (
            s["trial"], s["changes"], s["seeds"], fmt(s["E"], "%.1f", 1e9), fmt(s["nu"], "%.3f"),
            fmt(s["ucs"], "%.1f", 1e6), fmt(s["bts"], "%.2f", 1e6), s["valid"],
            fmt(s["dt"], "%.2f", 1e6), fmt(s["ucs_over_bts"]), fmt(s["ucs_over_dt"]),
            fmt(s["ci"], "%.2f")))
    print("| Lac du Bonnet | | | 69 | 0.26 | 200 | 9.3 | 6.9 | 21.5 | 29.0 | 0.42-0.47 |")
    if args.svg:
        svg(summary, args.svg)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run")
    r.add_argument("--out", required=True)
    r.add_argument("--preset", required=True, help="SUITE or SUITE:CARD (tools/paired_seeds.py)")
    r.add_argument("--seeds", default="1-2")
    r.add_argument("--trial", action="append", required=True, help="NAME=KEY:VALUE,...")
    r.add_argument("--tests", default="", help="only these suite test names")
    r.add_argument("--threads", default="1")
    r.add_argument("--rocklab", default=os.path.join(ps.ROOT, "build", "rocklab"))
    q = sub.add_parser("report")
    q.add_argument("--out", required=True)
    q.add_argument("--svg", default="")
    args = p.parse_args()
    return cmd_run(args) if args.cmd == "run" else cmd_report(args)


if __name__ == "__main__":
    sys.exit(main())
