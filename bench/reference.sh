#!/usr/bin/env bash
# Runs BM_Definitions of bench_validate (the Dawn face's definitions compiled and evaluated
# on the 180,000-vertex mesh, against the lavapipe run they check, the hand-written GLM
# reference and the tree walker, measured in the same iterations) and prints the markdown
# table of docs/validation.md ("Cost of the reference"). With --update-docs, also replaces
# the table there.
#
#   bench/reference.sh [build-dir] [--update-docs]
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
cmake --build "$build" --target bench_validate >&2
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp/shadergen-xdg}"
mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"
json="$build/bench_reference.json"
"$build/bench/bench_validate" --benchmark_filter=BM_Definitions --benchmark_repetitions=3 \
  --benchmark_report_aggregates_only=true --benchmark_out="$json" --benchmark_out_format=json >&2
python3 - "$json" "$here/docs/validation.md" "$update" <<'PY'
import json, sys, re
data = json.load(open(sys.argv[1]))
ctx = data["context"]
load = ", ".join(f"{x:.1f}" for x in ctx.get("load_avg", []))
lines = [f"Machine: {ctx['num_cpus']} CPUs at {ctx['mhz_per_cpu']} MHz, load average at start {load}; medians of 3 "
         "repetitions, one pose, 180,000 vertices.", "",
         "| threads | reference ms | lavapipe run ms | reference / run | / GLM reference | / tree walker |",
         "|---|---:|---:|---:|---:|---:|"]
for b in data["benchmarks"]:
    if b.get("aggregate_name") != "median": continue
    threads = b["name"].split("/")[1]
    threads = "every core" if threads == "0" else threads
    lines.append(f"| {threads} | {b['ms']:.1f} | {b['run_ms']:.1f} | {b['ref_vs_run']:.2f} | {b['vs_glm']:.2f} | "
                 f"{b['vs_tree']:.4f} |")
table = "\n".join(lines)
print(table)
if sys.argv[3] == "1":
    doc = open(sys.argv[2]).read()
    new = re.sub(r"(<!-- bench_reference table begin -->\n).*?(<!-- bench_reference table end -->)",
                 lambda m: m.group(1) + table + "\n" + m.group(2), doc, flags=re.S)
    open(sys.argv[2], "w").write(new)
PY
