#!/usr/bin/env bash
# The variant-build benchmark (docs/variants.md): bench/variants/dawn.variants.yaml
# (1,008 variants of the Dawn face and body) built by one `shadergen build` with an empty
# cache (cold) and again (warm), and the same variants as separate `shadergen generate`
# processes, nproc at a time as a build system would run them. Every separate output is
# compared byte for byte with the build's. Prints a Markdown table.
#
#   bench/variants.sh [build-dir] [count]
#
# count: how many separate processes to time (default: all); the per-variant time is
# scaled to the whole manifest, so CI can run a few (e.g. 50) in seconds.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$here/build}"
count="${2:-0}"
sg="$build/generator/cli/shadergen"
[[ -x "$sg" ]] || { echo "build shadergen first: $sg" >&2; exit 1; }
manifest="$here/bench/variants/dawn.variants.yaml"
jobs="$(nproc)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

now() { date +%s%N; }
secs() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", (b - a) / 1e9 }'; }

t0=$(now); "$sg" build "$manifest" -o "$work/batch" --cache-dir "$work/cache" -q; t1=$(now)
"$sg" build "$manifest" -o "$work/batch" --cache-dir "$work/cache" -q; t2=$(now)

# One `generate` command per variant, from the build's index.
python3 - "$work/batch/index.json" "$sg" "$work/sep" "$count" > "$work/commands" <<'PY'
import json, shlex, sys
index, sg, out, count = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
doc = json.load(open(index))
variants = doc["variants"]
if count > 0:  # spread over the manifest, not just its first rig and pass
    step = max(1, len(variants) // count)
    variants = variants[::step][:count]
for v in variants:
    cmd = [sg, "generate", "--rig", v["rig_file"], "-f", v["fragment_file"], "--emit", "glsl,spv,reflection", "-q",
           "-o", f"{out}/{v['name']}", "--target-env", doc["target_env"]]
    for r in doc["rules"]: cmd += ["-r", r]
    for k, val in v["parameters"].items(): cmd += ["--set", f"{k}={val}"]
    if doc["optimize"]: cmd.append("-O")
    print(shlex.join(cmd))
PY
total=$(python3 -c 'import json,sys; print(len(json.load(open(sys.argv[1]))["variants"]))' "$work/batch/index.json")
n=$(wc -l < "$work/commands")
mkdir -p "$work/sep"
t3=$(now); xargs -P "$jobs" -d '\n' -I CMD sh -c CMD < "$work/commands"; t4=$(now)

# Byte-identical outputs.
python3 - "$work/batch" "$work/sep" <<'PY'
import json, os, sys
batch, sep = sys.argv[1], sys.argv[2]
doc = json.load(open(os.path.join(batch, "index.json")))
checked = 0
for v in doc["variants"]:
    stem = os.path.join(sep, v["name"])
    if not os.path.exists(stem + ".vert"): continue
    pairs = [(v["outputs"]["glsl"], stem + ".vert"), (v["outputs"]["spv"], stem + ".spv"),
             (v["outputs"]["reflection"], stem + ".json")]
    for ours, theirs in pairs:
        if open(os.path.join(batch, ours), "rb").read() != open(theirs, "rb").read():
            sys.exit(f"DIFFERENT: {ours} vs {theirs}")
    checked += 1
print(f"byte-identical to generate: {checked} variants x 3 outputs")
PY

cold=$(secs "$t0" "$t1"); warm=$(secs "$t1" "$t2"); sep=$(secs "$t3" "$t4")
sepAll=$(awk -v s="$sep" -v n="$n" -v t="$total" 'BEGIN { printf "%.2f", s * t / n }')
echo
echo "| $total variants, $jobs cores | seconds | vs separate processes |"
echo "|---|---:|---:|"
echo "| \`shadergen build\`, cold cache | $cold | $(awk -v a="$cold" -v b="$sepAll" 'BEGIN { printf "%.3fx", a / b }') |"
echo "| \`shadergen build\`, warm cache | $warm | $(awk -v a="$warm" -v b="$sepAll" 'BEGIN { printf "%.4fx", a / b }') |"
if [[ "$n" -eq "$total" ]]; then
  echo "| $n separate \`shadergen generate\` ($jobs at a time) | $sep | 1x |"
else
  echo "| separate \`shadergen generate\` ($n timed: $sep s, scaled to $total) | $sepAll | 1x |"
fi
