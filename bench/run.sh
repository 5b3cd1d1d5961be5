#!/usr/bin/env bash
# Builds and runs the benchmarks, printing Google Benchmark's table (counters as columns).
#
#   bench/run.sh [build-dir] [extra benchmark flags...]
#
# build-dir defaults to ./build (configured RelWithDebInfo with Ninja if it has no CMakeCache).
# Each benchmark is repeated 3 times and only the mean/median/stddev rows are printed (set
# REPS=1 for a single quick pass). The JSON results go to <build-dir>/bench_validate.json.
# Needs Google Benchmark (libbenchmark-dev) and lavapipe; results: docs/validation.md.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$here/build}"
shift || true
reps="${REPS:-3}"
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"

if [[ ! -f "$build/CMakeCache.txt" ]]; then
  cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo
fi
cmake --build "$build" --target bench_validate
if [[ ! -x "$build/bench/bench_validate" ]]; then
  echo "bench_validate was not built (is Google Benchmark installed?)" >&2
  exit 1
fi
agg=()
if [[ "$reps" -gt 1 ]]; then agg=(--benchmark_repetitions="$reps" --benchmark_report_aggregates_only=true); fi
"$build/bench/bench_validate" --benchmark_counters_tabular=true "${agg[@]}" \
  --benchmark_out="$build/bench_validate.json" --benchmark_out_format=json "$@"
