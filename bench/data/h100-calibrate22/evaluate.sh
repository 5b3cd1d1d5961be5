#!/usr/bin/env bash
# The H100 collections of session 22 (README.md): the raster form fitted on train.log with and
# without the constant cache and draw sizes, each checked on every held-out log, and the shipped
# H200 raster profile on the same held-out logs.
#   fit-F.txt / fit-F.yaml   calibrate's report and profile for each fit F; summary.txt
# Usage: bash evaluate.sh [shadergen]   (about a minute; no device)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$here/../../..
sg=${1:-$root/build/generator/cli/shadergen}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
check=()
for g in corpus-heldout world corpus-heldout-seed4 body-depth pbr models models-fox unseen unseen-formats unseen-models; do
  check+=(--check-log "$here/$g.log")
done
: > "$here/summary.txt"
for fit in raster constant-cache draw-sizes draw-sizes+constant-cache; do
  flags=()
  [[ $fit == *constant-cache* ]] && flags+=(--constant-cache)
  [[ $fit == draw-sizes* ]] && flags+=(--draw-sizes)
  (cd "$here" && "$sg" calibrate --from-log train.log "${check[@]}" --form raster --outside-pipes none --near-best-weight 0 "${flags[@]}" -o "$tmp/p.yaml") |
    grep -v ": device profile of" > "$here/fit-$fit.txt"
  cp "$tmp/p.yaml" "$here/fit-$fit.yaml"
  {
    echo "$fit: $(grep -E '^leave-one-rig-out over' "$here/fit-$fit.txt")"
    echo "$fit: $(grep -E '^held-out check over' "$here/fit-$fit.txt")"
    awk '/^held-out check:/{h=1} h && /^\|/' "$here/fit-$fit.txt" | awk -F'|' -v f="$fit" '$6+0 > 1.05 {print f ": over 5 %:" $2 "|" $3 "|" $6}'
  } >> "$here/summary.txt"
done
(cd "$here" && "$sg" calibrate --evaluate "$root/devices/nvidia-h200-raster.yaml" "${check[@]}") > "$here/shipped-h200-raster.txt"
{
  echo "shipped H200 raster profile: $(grep -E '^held-out check over' "$here/shipped-h200-raster.txt")"
  awk -F'|' '$6+0 > 1.05 {print "shipped H200 raster profile: over 5 %:" $2 "|" $3 "|" $6}' "$here/shipped-h200-raster.txt"
} >> "$here/summary.txt"
cat "$here/summary.txt"
