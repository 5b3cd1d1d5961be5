#!/usr/bin/env bash
# Runs bench_buffers (lavapipe time per vertex and SPIR-V size of the 52-target face, dense
# and sparse, and of the Dawn face's targets as attributes and from a buffer, all in one
# run on the same 180,000-vertex mesh) and prints the markdown table of docs/buffers.md.
# With --update-docs, also replaces the table there.
#
#   bench/buffers.sh [build-dir] [--update-docs]
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
cmake --build "$build" --target bench_buffers >&2
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp/shadergen-xdg}"
mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"
json="$build/bench_buffers.json"
"$build/bench/bench_buffers" --benchmark_out="$json" --benchmark_out_format=json >&2
python3 - "$json" "$here/docs/buffers.md" "$update" <<'PY'
import json, sys, re
data = json.load(open(sys.argv[1]))
ctx = data["context"]
load = ", ".join(f"{x:.1f}" for x in ctx.get("load_avg", []))
lines = [f"Machine: {ctx['num_cpus']} CPUs at {ctx['mhz_per_cpu']} MHz, load average at start {load}; lavapipe, "
         "validation layer off; mean of 2 runs of one 180,000-vertex draw per plan.", "",
         "| plan | attributes | storage buffers | plan cost | SPIR-V bytes | run ms | ns / vertex | vs Dawn attributes |",
         "|---|---:|---:|---:|---:|---:|---:|---:|"]
for b in data["benchmarks"]:
    if b.get("run_type") == "aggregate": continue
    name = b["name"].split("/")[1]
    lines.append(f"| {name} | {int(b['attributes'])} | {int(b['storage_buffers'])} | {int(b['plan_cost'])} | "
                 f"{int(b['spirv_bytes']):,} | {b['real_time']:.1f} | {b['ns_per_vertex']:.1f} | {b['vs_dawn_attributes']:.2f} |")
table = "\n".join(lines)
print(table)
if sys.argv[3] == "1":
    doc = open(sys.argv[2]).read()
    new = re.sub(r"(<!-- bench_buffers table begin -->\n).*?(<!-- bench_buffers table end -->)",
                 lambda m: m.group(1) + table + "\n" + m.group(2), doc, flags=re.S)
    open(sys.argv[2], "w").write(new)
PY
