#!/usr/bin/env bash
# The same-specimen race with YADE (issue 15). Usage: bench/race/race.sh [RADIUS_m] [YADE_STEPS]
# YADE (Debian package `yade`) makes a dense packing of a 16 mm x 32 mm cylinder (default mean
# radius 0.41 mm: about 10k spheres); rocklab imports exactly that packing (`packing.import`) with
# parallel bonds, 8-element flat joints and exact 3D flat joints, bonding the pairs YADE's JCFpm
# bonds (gap within 0.1 (R1 + R2): interaction factor 1.1); both run the elastic window of a UCS
# (top platen at 1/s axial strain rate to 0.02 % axial strain) at 1 and 2 threads. Prints
# contact-steps per second of each and the ratios to YADE, and the wall time each code needs for
# that window: rocklab's whole test (set-up, seating, loading, output) against YADE's measured time
# per step times the steps its own time step needs for 0.02 % at 1/s. Units SI. Quiet machine.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$here/../.."
radius="${1:-0.00041}"
steps="${2:-2000}"
out="${RACE_OUT:-/tmp/rocklab-race}"
command -v yade > /dev/null || { echo "race.sh: yade is not installed (apt-get install yade)" >&2; exit 1; }
rocklab="$root/build/rocklab"
[ -x "$rocklab" ] || { echo "race.sh: build rocklab first ($rocklab)" >&2; exit 1; }
mkdir -p "$out"
cd "$out"
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
# The packing and the specimens are kept in OUT and reused while the radius and cards are the same.
if [ "$(cat radius 2> /dev/null)" != "$radius" ] || [ ! -s packing.txt ]; then
  yade -n -x "$here/yade_packing.py" packing.txt "$radius" 2>&1 | grep '^spheres'
  echo "$radius" > radius
fi
for model in pb fj fjx; do
  if ! cmp -s "$here/race_$model.json" "card_$model.json" || [ ! -s "spec_$model.rlspec" ] ||
    [ packing.txt -nt "spec_$model.rlspec" ]; then
    cp "$here/race_$model.json" "card_$model.json"
    rm -f "spec_$model.rlspec"
    "$rocklab" genesis "card_$model.json" -o "spec_$model.rlspec" -q
  fi
  sed "s#SPECIMEN#$out/spec_$model.rlspec#" "$here/race_ucs.json" > "ucs_$model.json"
  for t in 1 2; do
    rm -rf "ucs_${model}_$t"
    "$rocklab" test "ucs_$model.json" -o "ucs_${model}_$t" --threads "$t" -q > /dev/null
  done
done
for t in 1 2; do
  yade -n -j "$t" -x "$here/yade_ucs.py" packing.txt "$steps" 2>&1 | grep '^RACE' > "yade_$t.txt"
done
python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
def yade(t):  # "RACE yade interactions N dt DT steps S wall W"
    w = open(f"{out}/yade_{t}.txt").read().split()
    n, dt, steps, wall = int(w[3]), float(w[5]), int(w[7]), float(w[9])
    # contact-steps per second, and the wall time of the same 0.02 % at 1/s at YADE's own dt
    return n * steps / wall, wall / steps * (2 + 0.0002 / dt)
def rocklab(model, t):  # contact-steps per second, contacts, steps, wall time of the whole test
    rep = json.load(open(f"{out}/spec_{model}.rlspec.report.json"))
    p = json.load(open(f"{out}/ucs_{model}_{t}/results.json"))["provenance"]
    n = rep["contacts"]["total"]
    return n * p["steps"] / p["wall_time_s"], n, p["steps"], p["wall_time_s"]
y = {t: yade(t) for t in (1, 2)}
models = (("pb", "rocklab parallel bond"), ("fj", "rocklab flat joint, 8 elements"),
          ("fjx", "rocklab flat joint, exact 3D"))
r = {(m, t): rocklab(m, t) for m, _ in models for t in (1, 2)}
print(f"YADE JCFpm: {y[1][0]/1e6:.2f} M contact-steps/s (1 thread), {y[2][0]/1e6:.2f} M (2 threads)")
print("| engine / model | contacts | steps | 1 thread M/s | x YADE | 2 threads M/s | x YADE | 2nd thread |")
print("|---|---|---|---|---|---|---|---|")
for m, name in models:
    (r1, n, s, _), r2 = r[m, 1], r[m, 2][0]
    print(f"| {name} | {n} | {s} | {r1/1e6:.2f} | {r1/y[1][0]:.2f} | {r2/1e6:.2f} | {r2/y[2][0]:.2f} | {r2/r1:.2f} |")
print()
print("Wall time of the window (0.02 % axial strain at 1/s) [s]; YADE: its time per step x its steps")
print("| engine / model | 1 thread | / YADE | 2 threads | / YADE |")
print("|---|---|---|---|---|")
print(f"| YADE JCFpm | {y[1][1]:.1f} | 1 | {y[2][1]:.1f} | 1 |")
for m, name in models:
    w1, w2 = r[m, 1][3], r[m, 2][3]
    print(f"| {name} | {w1:.1f} | {w1/y[1][1]:.2f} | {w2:.1f} | {w2/y[2][1]:.2f} |")
PY
