#!/usr/bin/env bash
# Alternate rocklab_bench binaries on the same cases and print each case's median and range of
# the time per cycle [ms], so that two builds are compared on a machine whose speed drifts (the
# 2-core KVM guests here: one busy core at times 40 % slower). Usage:
#   bench/compare.sh ROUNDS FILTER BENCH_BINARY...      e.g.
#   ROCKLAB_BENCH_PACKING=packing.txt bench/compare.sh 5 'Packing10k' old/rocklab_bench build-release/bench/rocklab_bench
set -euo pipefail
rounds=$1 filter=$2
shift 2
out=$(mktemp)
for ((r = 1; r <= rounds; r++)); do
  for b in "$@"; do
    "$b" --benchmark_filter="$filter" --benchmark_min_time=0.5 --benchmark_format=csv 2> /dev/null |
      awk -F, -v bin="$b" '/^"BM_/ {gsub(/"/, "", $1); sub(/\/min_time.*/, "", $1); print bin "," $1 "," $3}' >> "$out"
  done
done
python3 - "$out" "$@" <<'PY'
import sys, statistics, collections
rows = collections.defaultdict(list)
for line in open(sys.argv[1]):
    b, case, t = line.strip().split(",")
    rows[(case, b)].append(float(t))
bins = sys.argv[2:]
cases = sorted({c for c, _ in rows}, key=lambda c: list(dict.fromkeys(c2 for c2, _ in rows)).index(c))
print("| case | " + " | ".join(f"build {i + 1} median (min-max) ms" for i in range(len(bins))) + " |")
print("|---|" + "---|" * len(bins))
for c in cases:
    cells = []
    for b in bins:
        v = rows.get((c, b), [])
        cells.append(f"{statistics.median(v):.2f} ({min(v):.2f}-{max(v):.2f})" if v else "-")
    print(f"| {c} | " + " | ".join(cells) + " |")
PY
rm -f "$out"
