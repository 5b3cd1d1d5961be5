#!/usr/bin/env bash
# Runs bench_search (Dawn face + synthetic libraries of 100-3,000 rules, every engine and
# heuristic, the GLPK integer program as oracle and baseline) and prints the markdown
# tables of docs/search.md. With --update-docs, also replaces the tables there.
#
#   bench/search_table.sh [build-dir] [--update-docs]
#
# Takes ~4 minutes on the 2-core machine (the weak configurations run into their per-search
# limits on purpose). JSON results: <build-dir>/bench_search.json. Needs python3.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="$here/build"
update=0
for a in "$@"; do
  case "$a" in
    --update-docs) update=1 ;;
    *) build="$a" ;;
  esac
done
if [[ ! -f "$build/CMakeCache.txt" ]]; then
  cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo
fi
cmake --build "$build" --target bench_search
json="$build/bench_search.json"
"$build/bench/bench_search" --benchmark_out="$json" --benchmark_out_format=json >&2
python3 - "$json" "$here/docs/search.md" "$update" <<'PY'
import json, sys, re
data = json.load(open(sys.argv[1]))
ctx = data["context"]
rows_dawn, rows_lib = [], []
def fmt(v):
    return f"{v:.3g}" if v < 100 else f"{v:,.0f}"
for b in data["benchmarks"]:
    name = b["name"].split("/iterations")[0].removesuffix("/real_time")
    err = " (error: %s)" % b["error_message"] if b.get("error_occurred") else ""
    if name.startswith("BM_Dawn/"):
        us = b["real_time"] if b["time_unit"] == "us" else b["real_time"] * 1000
        rows_dawn.append(f"| {name[8:]}{err} | {us:,.1f} | {int(b['expanded'])} | {b['peak_KiB']:.1f} |")
    elif name.startswith("BM_Library/"):
        _, rules, solver = name.split("/", 2)
        hits = int(b["limit_hits"])
        worst = fmt(b["worst_ms"]) if hits == 0 else f"≥ {b['limit_s'] * 1000:,.0f} (limit)"
        med = fmt(b["median_ms"]) if hits * 2 < 10 else f"≥ {b['limit_s'] * 1000:,.0f} (limit)"
        solved = "all" if hits == 0 else f"{10 - hits}/10"
        rows_lib.append(f"| {rules} | {solver}{err} | {med} | {worst} | {b['vs_ip']:.3g} | {fmt(b['median_expanded'])} | "
                        f"{fmt(b['max_expanded'])} | {b['peak_KiB']:,.0f} | {solved} |")
out = []
out.append(f"Machine: {ctx['num_cpus']} CPUs at {ctx['mhz_per_cpu']} MHz, load average at start "
           f"{', '.join('%.1f' % x for x in ctx.get('load_avg', []))}; times are wall clock.\n")
out.append("Dawn face, search alone (`BM_Dawn`):\n")
out.append("| solver | time (µs) | expanded | peak memory (KiB) |")
out.append("|---|---:|---:|---:|")
out += rows_dawn
out.append("\nSynthetic libraries, 10 seeds per size (`BM_Library`; expansions and memory over the solved seeds; "
           "vs IP = median time / the integer program's median time on the same instances):\n")
out.append("| rules | solver | median ms | worst ms | vs IP | median expanded | max expanded | peak KiB | solved |")
out.append("|---:|---|---:|---:|---:|---:|---:|---:|---|")
out += rows_lib
table = "\n".join(out)
print(table)
if sys.argv[3] == "1":
    doc = open(sys.argv[2]).read()
    begin, end = "<!-- bench_search table begin -->", "<!-- bench_search table end -->"
    doc = re.sub(re.escape(begin) + ".*?" + re.escape(end), lambda m: begin + "\n" + table + "\n" + end, doc, flags=re.S)
    open(sys.argv[2], "w").write(doc)
PY
