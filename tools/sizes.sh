#!/usr/bin/env bash
# Files over 500 lines and functions over 100 lines in src/, app/, lab/, materials/, viz/ and python/ (tests
# aside): the limits of docs/architecture.md. Needs Universal Ctags for the function lengths.
set -euo pipefail
cd "$(dirname "$0")/.."
echo "files over 500 lines:"
find src app lab materials viz python -name '*.cpp' -o -name '*.hpp' | xargs wc -l | awk '$2 != "total" && $1 > 500 {print "  " $1, $2}'
echo "functions over 100 lines:"
ctags -R --languages=C++ --kinds-C++=f --fields=+ne -x --_xformat="%{line} %{end} %N %F" \
  src app lab materials viz python | awk '{n = $2 - $1 + 1; if (n > 100) print "  " n, $3, $4}' | sort -rn
