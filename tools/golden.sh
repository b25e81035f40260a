#!/usr/bin/env bash
# Golden outputs: run every shipped scene, protocol, preset and suite with one rocklab binary and
# record a digest of every output file, so that a restructuring can be shown to change no result
# (byte-identical results.json, history.csv, cracks.csv, VTK files, specimens).
#
#   tools/golden.sh run BINARY OUTDIR [scenes|quick|full]   run the inputs, write OUTDIR/manifest.txt
#   tools/golden.sh compare MANIFEST_A MANIFEST_B    list the files whose digests differ
#   tools/golden.sh digest OUTDIR [SUBFOLDER...]     rewrite OUTDIR/manifest.txt from its files
#
# scenes: the scenes only (a minute). quick: scenes (examples/, examples/verification/), every preset's genesis, the lab protocols
# (lab/*.json, lab/drops/*.json) - about 30 minutes on 2 cores. full: also the suites
# (lab/suites/*.json) - about 1.5 hours more. Run from any folder; inputs are read from this
# checkout. What is left out of a digest: wall-clock times ("wall_time_s", "seconds", the
# suite's tests.csv time column), the absolute paths of the checkout and of OUTDIR, the process id
# in a suite's staging-folder name, and logs.
# Digests are comparable between two builds of the same type on the same machine.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)

normalize() { # FILE ROOT OUT -> normalized bytes on stdout
  python3 - "$1" "$2" "$3" <<'EOF'
import json, sys
path, root, out = sys.argv[1], sys.argv[2].encode(), sys.argv[3].encode()
data = open(path, 'rb').read().replace(out, b'<OUT>').replace(root, b'<ROOT>')
# a suite's staging folder is named by its process id (.partial-PID); results.json records it
import re
data = re.sub(rb'/\.partial-[0-9]+', b'/.partial', data)
def strip(j):
    if isinstance(j, dict):
        return {k: strip(v) for k, v in j.items() if k not in ('wall_time_s', 'seconds')}
    if isinstance(j, list):
        return [strip(v) for v in j]
    return j
if path.endswith('.json'):
    try:
        data = json.dumps(strip(json.loads(data)), sort_keys=True, indent=1).encode()
    except ValueError:
        pass
elif path.endswith('tests.csv'):
    rows = [r.split(b',') for r in data.split(b'\n')]
    data = b'\n'.join(b','.join(r[:-1]) for r in rows)
sys.stdout.buffer.write(data)
EOF
}

run() {
  local bin out mode
  bin=$(realpath "$1")
  out=$(realpath -m "$2")
  mode=${3:-quick}
  mkdir -p "$out"
  cd "$root"
  local log="$out/golden.log"
  : >"$log"
  step() { # NAME CMD...
    local name=$1
    shift
    local t0=$SECONDS
    if "$@" >>"$log" 2>&1; then
      echo "ok    $name ($((SECONDS - t0)) s)" | tee -a "$log"
    else
      echo "FAIL  $name (status $?)" | tee -a "$log"
    fi
  }
  for f in examples/*.json examples/verification/*.json; do
    n=${f%.json}
    step "run $f" "$bin" run "$f" -o "$out/run/${n//\//_}" -q
  done
  if [ "$mode" = scenes ]; then
    :
  else
  for f in materials/*.json; do
    n=$(basename "${f%.json}")
    mkdir -p "$out/genesis"
    step "genesis $f" "$bin" genesis "$f" -o "$out/genesis/$n.rlspec" -q
    rm -f "$out/genesis/$n.rlspec.report.json.tmp"
  done
  for f in lab/*.json lab/drops/*.json; do
    n=${f%.json}
    step "test $f" "$bin" test "$f" -o "$out/test/${n//\//_}" -q
  done
  fi
  if [ "$mode" = full ]; then
    for f in lab/suites/*.json; do
      n=$(basename "${f%.json}")
      step "suite $f" "$bin" suite "$f" -o "$out/suite/$n" -q
    done
  fi
  digest "$out"
}

digest() { # OUTDIR [SUBFOLDER...]: (re)write OUTDIR/manifest.txt from the files there
  local out
  out=$(realpath "$1")
  shift
  local parts=("${@:-run genesis test suite}")
  (cd "$out" && find ${parts[*]} -type f ! -path '*/logs/*' 2>/dev/null | sort) |
    while read -r rel; do
      printf '%s  %s\n' "$(normalize "$out/$rel" "$root" "$out" | sha256sum | cut -c1-64)" "$rel"
    done >"$out/manifest.txt"
  echo "wrote $out/manifest.txt ($(wc -l <"$out/manifest.txt") files)"
}

compare() {
  local a=$1 b=$2
  if diff <(sort -k2 "$a") <(sort -k2 "$b") >/dev/null; then
    echo "identical: $(wc -l <"$a") files"
    return 0
  fi
  join -j2 -a1 -a2 -e MISSING -o 0,1.1,2.1 <(sort -k2 "$a") <(sort -k2 "$b") |
    awk '$2 != $3 {print "differs: " $1}'
  return 1
}

case "${1:-}" in
run) shift && run "$@" ;;
compare) shift && compare "$@" ;;
digest) shift && digest "$@" ;;
*)
  sed -n '2,18p' "$0"
  exit 2
  ;;
esac
