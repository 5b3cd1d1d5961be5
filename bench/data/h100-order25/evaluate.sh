#!/usr/bin/env bash
# Session 25's H100 collections (README.md), offline: the raster form fitted on the staged training log,
# checked on every staged held-out log (seed 7's random rigs are new), and the shipped H200 raster
# profile on the same logs; BrainStem's and RobotExpressive's parts timed alone and as a whole model.
#   Usage: bash evaluate.sh [shadergen]   (about a minute; no device)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$here/../../..
sg=${1:-$root/build/generator/cli/shadergen}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
check=()
for g in call1/s2/world call1/s2/body-depth call1/s2/pbr call1/s2/models call1/s2/models-fox call2/s2/unseen \
         call2/s2/unseen-formats call2/s2/unseen-models call2/s7/corpus-heldout; do
  check+=(--check-log "$here/$g.log")
done
public=()
for m in Base_Man Ely Saxon Soldier Flamingo Mannequin Xbot BrainStem; do public+=(--check-log "$here/call1/public/$m.log"); done
: > "$here/summary.txt"
summarize() {  # NAME FILE
  { grep -E '^leave-one-rig-out over' "$2" || true; } | sed "s/^/$1: /"
  grep -E '^held-out check over' "$2" | sed "s/^/$1: /"
  awk '/^held-out check:/{h=1} h && /^\|/' "$2" | awk -F'|' -v f="$1" '$6+0 > 1.05 {print f ": over 5 %:" $2 "|" $3 "|" $6}'
}
(cd "$here" && "$sg" calibrate --from-log call2/s2/train.log "${check[@]}" --form raster --outside-pipes none --near-best-weight 0 -o "$tmp/p.yaml") |
  grep -v ": device profile of" > "$here/fit-raster.txt"
cp "$tmp/p.yaml" "$here/fit-raster.yaml"
summarize "raster refitted on the staged H100 train.log" "$here/fit-raster.txt" >> "$here/summary.txt"
(cd "$here" && "$sg" calibrate --evaluate "$here/fit-raster.yaml" "${public[@]}") > "$here/fit-raster-public.txt"
summarize "the same on the public models" "$here/fit-raster-public.txt" >> "$here/summary.txt"
(cd "$here" && "$sg" calibrate --evaluate "$root/devices/nvidia-h200-raster.yaml" "${check[@]}") > "$here/shipped-h200-raster.txt"
summarize "shipped H200 raster profile" "$here/shipped-h200-raster.txt" >> "$here/summary.txt"
# BrainStem and RobotExpressive, each part timed in a process of its own (order-next.sh's parts-*/),
# against the same parts timed as a whole model in one process (all-*.log), under both profiles.
for model in BrainStem RobotExpressive; do
  parts=()
  for f in "$here"/call1/order/parts-$model/*.log; do parts+=(--check-log "$f"); done
  for p in fit-raster:"$here/fit-raster.yaml" shipped-h200-raster:"$root/devices/nvidia-h200-raster.yaml"; do
    (cd "$here" && "$sg" calibrate --evaluate "${p#*:}" "${parts[@]}") > "$here/${p%%:*}-$model-alone.txt"
    summarize "${p%%:*}, $model, one process per part" "$here/${p%%:*}-$model-alone.txt" >> "$here/summary.txt"
    (cd "$here" && "$sg" calibrate --evaluate "${p#*:}" --check-log "$here/call1/order/all-$model.log") > "$here/${p%%:*}-$model-whole.txt"
    summarize "${p%%:*}, $model, the whole model in one process" "$here/${p%%:*}-$model-whole.txt" >> "$here/summary.txt"
  done
done
cat "$here/summary.txt"
