#!/usr/bin/env bash
# Build rocklab in Release and print the engine throughput (contact-updates/s, particle-steps/s)
# at 1 and 2 threads. Usage: bench/run.sh [extra Google Benchmark flags]
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-release -DCMAKE_BUILD_TYPE=Release -DROCKLAB_BUILD_TESTS=OFF > /dev/null
cmake --build build-release -j2 --target rocklab_bench > /dev/null
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
./build-release/bench/rocklab_bench --benchmark_counters_tabular=true "$@"
