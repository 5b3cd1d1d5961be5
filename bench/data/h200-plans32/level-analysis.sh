#!/usr/bin/env bash
# Session 32, offline (seconds): writes level-analysis.txt here from the logs already in bench/data.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd); R=$here/../../..
sg=${1:-$R/build/generator/cli/shadergen}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
h100=("$R"/bench/data/h200-plans29/s[3457]/corpus-heldout.log "$R"/bench/data/h200-plans3[012]*/s*/corpus-heldout.log)
h23=(); for f in "$R"/bench/data/h200-fresh23/*.log; do [ "$(basename "$f")" = train.log ] || h23+=("$f"); done
checks() { for f in "$@"; do echo --check-log "$f"; done; }
"$sg" calibrate --evaluate "$R/devices/nvidia-h200-raster.yaml" $(checks "${h100[@]}") > "$tmp/h100.txt"
"$sg" calibrate --evaluate "$R/devices/nvidia-h200-raster.yaml" $(checks "${h23[@]}") > "$tmp/h23.txt" 2> /dev/null
cd "$here"
{
  echo "== repeat.py: the same slot-plan programs of corpus seed 3 timed on H100s in sessions 26-29 (each rig in a fresh process)"
  python3 repeat.py "$R"/bench/data/h100-fresh26/call3/s3/corpus-heldout.log "$R"/bench/data/h100-plans27/s3/corpus-heldout.log \
    "$R"/bench/data/h200-plans28/s3/corpus-heldout.log "$R"/bench/data/h200-plans29/s3/corpus-heldout.log
  echo "== floorlevel.py: the floors' error against the pair's level (shipped profile, session 31's evaluate.txt)"
  python3 floorlevel.py "$R"/bench/data/gpu-levels31/evaluate.txt "$R"/bench/data/h200-plans29/s[3457]/corpus-heldout.log "$R"/bench/data/h200-plans30/s4[345]/corpus-heldout.log
  echo "== jpwlevel.py: log(level) against joints per warp, pairs with >= 8 palette loads (shipped profile)"
  echo "H100 own-plan logs, sessions 29-32:"
  python3 jpwlevel.py "$tmp/h100.txt" "${h100[@]}"
  echo "H200 held-out logs, session 23:"
  python3 jpwlevel.py "$tmp/h23.txt" "${h23[@]}"
  echo "== bytype.py: each own plan's log(predicted / measured) against joints per warp, by where it reads the palette"
  python3 bytype.py "${h100[@]}"
} > level-analysis.txt
cat level-analysis.txt
