#!/usr/bin/env bash
# Session 26's H100 collection (README.md), offline: every group timed with each rig in a fresh process
# (the default since session 25). The raster form fitted on this collection's training log and checked
# on every held-out log of it (the seed 3, 4, 5 and 7 random rigs, the suite's and the glTF models'),
# the same form fitted on session 25's one-process training log and checked on the same fresh logs, and
# the shipped H200 raster profile on them.   Usage: bash evaluate.sh [shadergen]   (a minute; no device)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$here/../../..
sg=${1:-$root/build/generator/cli/shadergen}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
check=()
for g in call1/s2/world call1/s2/body-depth call1/s2/pbr call1/s2/models call1/s2/models-fox call1/s2/unseen \
         call1/s2/unseen-formats call1/s2/unseen-models call1/s3/corpus-heldout-16 call2/s4/corpus-heldout \
         call1/s5/corpus-heldout call3/s7/corpus-heldout; do
  check+=(--check-log "$here/$g.log")
done
: > "$here/summary.txt"
summarize() {  # NAME FILE
  { grep -E '^leave-one-rig-out over' "$2" || true; } | sed "s/^/$1: /"
  grep -E '^held-out check over' "$2" | sed "s/^/$1: /"
  awk '/^held-out check:/{h=1} h && /^\|/' "$2" | awk -F'|' -v f="$1" '$6+0 > 1.05 {print f ": over 5 %:" $2 "|" $3 "|" $6}'
}
fit() {  # NAME TRAIN_LOG: the raster form fitted on TRAIN_LOG, checked on the fresh held-out logs
  (cd "$here" && "$sg" calibrate --from-log "$2" "${check[@]}" --form raster --outside-pipes none --near-best-weight 0 -o "$tmp/p.yaml") |
    grep -v ": device profile of" > "$here/fit-$1.txt"
  cp "$tmp/p.yaml" "$here/fit-$1.yaml"
}
fit raster call2/s2/train.log
summarize "raster fitted on the fresh train.log" "$here/fit-raster.txt" >> "$here/summary.txt"
fit raster-one-process-train "$here/../h100-order25/call2/s2/train.log"
summarize "raster fitted on session 25's one-process train.log" "$here/fit-raster-one-process-train.txt" >> "$here/summary.txt"
(cd "$here" && "$sg" calibrate --evaluate "$root/devices/nvidia-h200-raster.yaml" "${check[@]}") > "$here/shipped-h200-raster.txt"
summarize "shipped H200 raster profile" "$here/shipped-h200-raster.txt" >> "$here/summary.txt"
cat "$here/summary.txt"
