#!/usr/bin/env bash
# Builds and runs bench_bake, then prints the Markdown tables of docs/bake.md.
#
#   bench/bake.sh [build-dir]
#
# build-dir defaults to ./build (configured RelWithDebInfo with Ninja if it has no
# CMakeCache). Needs Google Benchmark, Embree and the shared models (../shared/models or
# SHADERGEN_SHARED_DIR). The JSON results go to <build-dir>/bench_bake.json.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$here/build}"
if [[ ! -f "$build/CMakeCache.txt" ]]; then
  cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo
fi
cmake --build "$build" --target bench_bake
"$build/bench/bench_bake" --benchmark_out="$build/bench_bake.json" --benchmark_out_format=json >/dev/null
python3 - "$build/bench_bake.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
ctx = d["context"]
print(f"Machine: {ctx.get('num_cpus')} CPUs at {ctx.get('mhz_per_cpu')} MHz, load average {ctx.get('load_avg', [0])[0]:.1f} at the start.\n")
print("| triangles | Embree (Mrays/s, 1 thread) | brute force (Mrays/s, 1 thread) | speed-up | rays disagreeing |")
print("|---:|---:|---:|---:|---:|")
for b in d["benchmarks"]:
    if b["name"].startswith("BM_Rays/"):
        print(f"| {int(b['triangles'])} | {b['embree_Mrays_s']:.2f} | {b['brute_Mrays_s']:.4f} | {b['speedup']:.0f}× | {int(b['rays_disagreeing'])} |")
print()
print("| model | vertices | triangles | passes | rays | bake time (ms) | Mrays/s (all threads) |")
print("|---|---:|---:|---:|---:|---:|---:|")
for b in d["benchmarks"]:
    if b["name"].startswith("BM_BakeModel/"):
        if b.get("error_occurred"):
            continue
        name = b["name"].split("/")[1]
        print(f"| {name} | {int(b['vertices'])} | {int(b['triangles'])} | {int(b['passes'])} | {int(b['rays'])} | "
              f"{b['real_time']:.1f} | {b['Mrays_s']:.2f} |")
PY
