#!/usr/bin/env bash
# Session 30, offline (no device; about a minute): lavapipe's profile fitted on more rigs of many inputs, and a
# second price past a threshold, on storage-buffer vec4 loads. Three additive fits without bench's floors, each
# checked on session 29's 172 held-out pairs (session 17's four groups, session 13's three unseen runs) and, apart,
# on the six many-input rigs of corpus seeds 43 and 47 (`seed43/`, `seed47/`: no fit below saw them):
#   locations:      session 17's training log, `--threshold locations` (the profile shipped in session 29)
#   locations+41:   the same with session 29's six many-input rigs of seed 41 (`../lavapipe-thresholds29/seed41/`)
#   two-thresholds: that, with `--threshold buffer_vec4_loads` besides (devices/llvmpipe-2core.yaml since session 30)
#   Usage: bash evaluate.sh [shadergen]   (writes fit-*.yaml, fit-*.txt and summary.txt here)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$here/../../..
sg=${1:-$root/build/generator/cli/shadergen}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
D=$root/bench/data
checks=()
for g in world corpus-heldout body-depth pbr; do cp "$D/lavapipe-rounds17/$g.log" "$tmp/r17-$g.log"; checks+=(--check-log "$tmp/r17-$g.log"); done
for run in a b c; do
  for f in "$D"/lavapipe-unseen13/$run/*.log; do cp "$f" "$tmp/u13$run-$(basename "$f")"; checks+=(--check-log "$tmp/u13$run-$(basename "$f")"); done
done
many=(); for f in "$here"/seed43/corpus-*.log "$here"/seed47/corpus-*.log; do many+=(--check-log "$f"); done
seed41=("$D"/lavapipe-thresholds29/seed41/corpus-*.log)
: > "$here/summary.txt"
fit() {  # NAME TRAINING-LOGS... -- FIT-ARGS...
  local name=$1; shift; local logs=()
  while [ "$1" != -- ]; do logs+=("$1"); shift; done; shift
  "$sg" calibrate --from-log "${logs[@]}" --form additive --near-best-weight 0 --no-floors "$@" -o "$here/fit-$name.yaml" "${checks[@]}" > "$here/fit-$name.txt"
  "$sg" calibrate --evaluate "$here/fit-$name.yaml" "${many[@]}" > "$here/fit-$name-many-inputs.txt"
  {
    echo "== $name ($*; ${#logs[@]} training logs)"
    grep -E "^(leave-one-rig-out over|held-out check over)" "$here/fit-$name.txt" | cut -d';' -f1
    grep -A3 "^thresholds:" "$here/fit-$name.yaml" | grep "{" || true
    grep -E "^\| face\.rig\.yaml \|" "$here/fit-$name.txt" | head -2 | awk -F'|' '{printf "leave-one-rig-out %s%s: %s\n", $2, $3, $6}'
    echo "seeds 43 and 47, chosen among the programs the logs timed: $(grep "^held-out check over" "$here/fit-$name-many-inputs.txt" | cut -d';' -f1)"
    grep -E "^\| corpus-(3444766145|45535460)" "$here/fit-$name-many-inputs.txt" | awk -F'|' '{printf "  %s%s: %s\n", $2, $3, $6}'
  } >> "$here/summary.txt"
}
fit locations "$D/lavapipe-rounds17/train.log" -- --threshold locations
fit locations+41 "$D/lavapipe-rounds17/train.log" "${seed41[@]}" -- --threshold locations
fit two-thresholds "$D/lavapipe-rounds17/train.log" "${seed41[@]}" -- --threshold locations --threshold buffer_vec4_loads
cat "$here/summary.txt"
