#!/usr/bin/env bash
# Session 24: the raster form with and without the pipes' sum share (calibrate --pipe-sum-share),
# each fitted on a device's training log and checked on every held-out log it has (README.md).
#   h200-F.txt, h200-F.yaml   F = raster, share: fitted on bench/data/h200-draw-counts18/train.log (as
#                             devices/nvidia-h200-raster.yaml), checked on sessions 18-19's held-out logs
#   h200-F-fresh.txt          the same profile on session 23's fresh collection (117 pairs)
#   h200-F-models.txt         and on its eight public models
#   h100-F.txt, h100-F.yaml   fitted on bench/data/h100-calibrate22/train.log, checked on its held-out logs
#   lavapipe-F.txt            F = additive (the shipped form), roofline, roofline+share: fitted on
#                             bench/data/lavapipe-rounds17/train.log, checked on its held-out logs
#   summary.txt               the headline lines and every pair over 5 % (lavapipe: over 10 %)
# Usage: bash evaluate.sh [shadergen]   (under a minute; no device)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$here/../../..
sg=${1:-$root/build/generator/cli/shadergen}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
D=$root/bench/data/h200-draw-counts18 U=$root/bench/data/h200-unseen19 N=$root/bench/data/h200-fresh23 C=$root/bench/data/h100-calibrate22
old=() fresh=() models=() h100=()
for g in world corpus-heldout body-depth pbr models models-fox; do old+=(--check-log "$D/$g.log"); done
for g in unseen unseen-formats unseen-models; do old+=(--check-log "$U/$g.log"); done
for g in world corpus-heldout-seed3 corpus-heldout-seed4 corpus-heldout-seed5 body-depth pbr models models-fox unseen unseen-formats unseen-models; do
  fresh+=(--check-log "$N/$g.log")
done
for f in "$N"/public-models/*.log; do models+=(--check-log "$f"); done
for g in world corpus-heldout corpus-heldout-seed4 body-depth pbr models models-fox unseen unseen-formats unseen-models; do h100+=(--check-log "$C/$g.log"); done
for fit in raster share; do
  flags=(--form raster --outside-pipes none --near-best-weight 0)
  [[ $fit == share ]] && flags+=(--pipe-sum-share)
  "$sg" calibrate --from-log "$D/train.log" "${old[@]}" "${flags[@]}" -o "$here/h200-$fit.yaml" | grep -v ": device profile of" > "$here/h200-$fit.txt"
  "$sg" calibrate --evaluate "$here/h200-$fit.yaml" "${fresh[@]}" > "$here/h200-$fit-fresh.txt"
  "$sg" calibrate --evaluate "$here/h200-$fit.yaml" "${models[@]}" > "$here/h200-$fit-models.txt"
  "$sg" calibrate --from-log "$C/train.log" "${h100[@]}" "${flags[@]}" -o "$here/h100-$fit.yaml" | grep -v ": device profile of" > "$here/h100-$fit.txt"
done
L=$root/bench/data/lavapipe-rounds17 lava=()
for g in world corpus-heldout body-depth pbr; do lava+=(--check-log "$L/$g.log"); done
for fit in additive roofline roofline+share; do
  flags=(--form "${fit%+share}")
  [[ $fit == *+share ]] && flags+=(--pipe-sum-share)
  "$sg" calibrate --from-log "$L/train.log" "${lava[@]}" "${flags[@]}" -o "$tmp/l.yaml" | grep -v ": device profile of" > "$here/lavapipe-$fit.txt"
  echo "pipe_sum_share of lavapipe-$fit: $(grep '^pipe_sum_share' "$tmp/l.yaml" | cut -d' ' -f2)" >> "$here/lavapipe-$fit.txt"
done
{
  for f in h200-raster h200-share h200-raster-fresh h200-share-fresh h200-raster-models h200-share-models h100-raster h100-share; do
    echo "$f: $(grep -E '^held-out check over' "$here/$f.txt")"
    awk '/^held-out check:/{h=1} h && /^\|/' "$here/$f.txt" | awk -F'|' -v f="$f" '$6+0 > 1.05 {print f ": over 5 %:" $2 "|" $3 "|" $6}'
  done
  for f in h200-share h100-share; do echo "$f.yaml: $(grep '^pipe_sum_share' "$here/$f.yaml")"; done
  for f in lavapipe-additive lavapipe-roofline lavapipe-roofline+share; do
    echo "$f: $(grep -E '^held-out check over' "$here/$f.txt")"
    awk '/^held-out check:/{h=1} h && /^\|/' "$here/$f.txt" | awk -F'|' -v f="$f" '$6+0 > 1.10 {print f ": over 10 %:" $2 "|" $3 "|" $6}'
  done
  grep -h '^pipe_sum_share of' "$here"/lavapipe-*.txt
} > "$here/summary.txt"
cat "$here/summary.txt"
