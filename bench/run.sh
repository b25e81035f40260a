#!/usr/bin/env bash
# Build rocklab in Release and print the engine throughput (contact-updates/s, particle-steps/s)
# at 1 and 2 threads. Usage: bench/run.sh [extra Google Benchmark flags]
# The *Packing10k cases (a 10k bonded packing in given, Morton and shuffled order) and the
# *Kernel10k cases (the contact law alone over the same contacts) read another code's packing,
# ROCKLAB_BENCH_PACKING (x y z r per line; default /tmp/rocklab-race/packing.txt, which
# bench/race/race.sh makes with YADE); without it they are reported as skipped.
# bench/compare.sh alternates two builds on the same cases and prints medians.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-release -DCMAKE_BUILD_TYPE=Release -DROCKLAB_BUILD_TESTS=OFF > /dev/null
cmake --build build-release -j2 --target rocklab_bench > /dev/null
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
./build-release/bench/rocklab_bench --benchmark_counters_tabular=true "$@"
