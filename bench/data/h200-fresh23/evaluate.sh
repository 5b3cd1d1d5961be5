#!/usr/bin/env bash
# Session 23's H200 collection (README.md), checked without a device:
#   shipped.txt          devices/nvidia-h200-raster.yaml on every fresh held-out log (117 pairs)
#   shipped-before.txt   the same profile on sessions 18-19's logs of the same groups (73 pairs)
#   repeat.txt           the groups timed in both collections: how far a program's time moved, and which pairs' choice did
#   public-models.txt    the profile on eight public models no run had drawn (public-models/*.log)
#   fit-F.txt, fit-F.yaml  the raster form fitted on this collection's train.log (F = raster, draw-sizes+constant-cache),
#                        and on it with session 18's (F = both-logs), each checked on every held-out log of both collections
#   summary.txt          the headline lines of each
# Usage: bash evaluate.sh [shadergen]   (about a minute; no device)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$here/../../..
sg=${1:-$root/build/generator/cli/shadergen}
O=$root/bench/data/h200-draw-counts18 U=$root/bench/data/h200-unseen19
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fresh=() before=() after=() specs=()
for g in world corpus-heldout-seed3 corpus-heldout-seed4 corpus-heldout-seed5 body-depth pbr models models-fox unseen unseen-formats unseen-models; do
  fresh+=(--check-log "$here/$g.log")
done
for g in world body-depth pbr models models-fox; do before+=(--check-log "$O/$g.log"); after+=(--check-log "$here/$g.log"); specs+=("$O/$g.log:$here/$g.log"); done
for g in unseen unseen-formats unseen-models; do before+=(--check-log "$U/$g.log"); after+=(--check-log "$here/$g.log"); specs+=("$U/$g.log:$here/$g.log"); done
models=(); for f in "$here"/public-models/*.log; do models+=(--check-log "$f"); done
P=$root/devices/nvidia-h200-raster.yaml
"$sg" calibrate --evaluate "$P" "${fresh[@]}" > "$here/shipped.txt"
"$sg" calibrate --evaluate "$P" "${before[@]}" > "$here/shipped-before.txt"
"$sg" calibrate --evaluate "$P" "${after[@]}" > "$tmp/after.txt"
python3 "$here/repeat.py" "$here/shipped-before.txt" "$tmp/after.txt" "${specs[@]}" > "$here/repeat.txt"
"$sg" calibrate --evaluate "$P" "${models[@]}" > "$here/public-models.txt"
# Fits: every held-out log of both collections (session 18-19's with their palette footprints).
python3 "$root/bench/data/h200-constant-cache21/augment.py" "$O/train.log,$O/corpus-heldout.log" "$tmp" > /dev/null
check=("${fresh[@]}" --check-log "$tmp/corpus-heldout.log")
for fit in raster draw-sizes+constant-cache both-logs; do
  flags=() logs=(--from-log "$here/train.log")
  [[ $fit == draw-sizes* ]] && flags+=(--draw-sizes --constant-cache)
  [[ $fit == both-logs ]] && logs+=(--from-log "$tmp/train.log")
  "$sg" calibrate "${logs[@]}" "${check[@]}" --form raster --outside-pipes none --near-best-weight 0 "${flags[@]}" -o "$tmp/p.yaml" |
    grep -v ": device profile of" > "$here/fit-$fit.txt"
  grep -v '^# held-out' "$tmp/p.yaml" > "$here/fit-$fit.yaml"
done
{
  for f in shipped shipped-before public-models fit-raster fit-draw-sizes+constant-cache fit-both-logs; do
    echo "$f: $(grep -E '^held-out check over' "$here/$f.txt")"
    awk '/^held-out check:/{h=1} h && /^\|/' "$here/$f.txt" | awk -F'|' -v f="$f" '$6+0 > 1.05 {print f ": over 5 %:" $2 "|" $3 "|" $6}'
  done
  head -1 "$here/repeat.txt"
} > "$here/summary.txt"
cat "$here/summary.txt"
