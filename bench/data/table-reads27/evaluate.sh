#!/usr/bin/env bash
# Session 27, offline (no device; about three minutes): the logs of session 23's H200 collection and
# session 26-27's H100 collections with their table reads counted apart (augment.py), the raster form
# fitted on each device's training log and checked on its held-out logs, before and after, and the
# H200 fit (devices/nvidia-h200-raster.yaml since session 27) checked on the H100's logs too.
#   Usage: bash evaluate.sh [shadergen]     (from anywhere; writes the *.txt and fit-*.yaml here)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$here/../../..
sg=${1:-$root/build/generator/cli/shadergen}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
H2=$root/bench/data/h200-fresh23 H1=$root/bench/data/h100-plans27
h200=(world body-depth pbr models models-fox unseen unseen-formats unseen-models corpus-heldout-seed3 corpus-heldout-seed4 corpus-heldout-seed5)
h100=(s2/world s2/body-depth s2/pbr s2/models s2/models-fox s2/unseen s2/unseen-formats s2/unseen-models s3/corpus-heldout s4/corpus-heldout s5/corpus-heldout s7/corpus-heldout)
mkdir -p "$tmp/h200" "$tmp/h100"
{
  python3 "$here/augment.py" "$H2/train.log" "$tmp/h200/train.log"
  for g in "${h200[@]}"; do python3 "$here/augment.py" "$H2/$g.log" "$tmp/h200/$g.log"; done
  python3 "$here/augment.py" "$root/bench/data/h100-fresh26/call2/s2/train.log" "$tmp/h100/train.log"
  for g in "${h100[@]}"; do python3 "$here/augment.py" "$H1/$g.log" "$tmp/h100/${g//\//-}.log"; done
} 2> "$here/augment.txt"
check() {  # DIR LOG...: --check-log arguments (an augmented copy's name has '-' for '/')
  local d=$1; shift
  for g in "$@"; do [ -f "$d/$g.log" ] && echo "--check-log $d/$g.log" || echo "--check-log $d/${g//\//-}.log"; done
}
fit() {  # NAME TRAIN CHECKS...
  local name=$1 train=$2; shift 2
  "$sg" calibrate --from-log "$train" "$@" --form raster --outside-pipes none --near-best-weight 0 -o "$here/fit-$name.yaml" | grep -v ": device profile of" > "$here/fit-$name.txt"
}
fit h200 "$tmp/h200/train.log" $(check "$tmp/h200" "${h200[@]}")
fit h200-before "$H2/train.log" $(check "$H2" "${h200[@]}")
fit h100 "$tmp/h100/train.log" $(check "$tmp/h100" "${h100[@]}")
fit h100-before "$root/bench/data/h100-fresh26/call2/s2/train.log" $(check "$H1" "${h100[@]}")
"$sg" calibrate --evaluate "$here/nvidia-h200-raster-before.yaml" $(check "$H2" "${h200[@]}") > "$here/h200-by-before.txt"
# The H200 fit on the H100's logs (under another name: the logs' own plans were searched under the
# profile shipped before, so they are not this one's).
"$sg" calibrate --evaluate "$here/fit-h200.yaml" $(check "$tmp/h100" "${h100[@]}") > "$here/h100-by-fit-h200.txt"
"$sg" calibrate --evaluate "$here/nvidia-h200-raster-before.yaml" $(check "$H1" "${h100[@]}") > "$here/h100-by-before.txt"
for f in fit-h200 fit-h200-before h200-by-before fit-h100 fit-h100-before h100-by-fit-h200 h100-by-before; do
  echo "== $f"
  grep -E '^held-out check over' "$here/$f.txt" || true
  awk '/^held-out check:/{h=1} h && /^\|/' "$here/$f.txt" | awk -F'|' '$6+0 > 1.05 {print "  over 5 %:" $2 "|" $3 "|" $6}'
done | tee "$here/summary.txt"
