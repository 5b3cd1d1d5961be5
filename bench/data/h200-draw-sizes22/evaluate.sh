#!/usr/bin/env bash
# Draw sizes (docs/device-profiles.md, "Draw sizes") fitted on session 18's H200 training log and
# checked on the 73 held-out pairs of sessions 18 and 19, beside the raster fit without them and
# with the constant cache alone. The logs get their palette footprints from
# ../h200-constant-cache21/augment.py. For each fit F: fit-F.txt (calibrate's report: the
# leave-one-rig-out table and the held-out check) and fit-F.yaml (the profile); summary.txt.
# Usage: bash evaluate.sh [shadergen]   (about 1 minute; no device)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$here/../../..
sg=${1:-$root/build/generator/cli/shadergen}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
A=$root/bench/data/h200-draw-counts18 U=$root/bench/data/h200-unseen19
held=(corpus-heldout world body-depth pbr models-fox models)
unseen=(unseen unseen-formats unseen-models)
logs=$A/train.log
for g in "${held[@]}"; do logs+=",$A/$g.log"; done
for g in "${unseen[@]}"; do logs+=",$U/$g.log"; done
python3 "$root/bench/data/h200-constant-cache21/augment.py" "$logs" "$tmp"
check=()
for g in "${held[@]}" "${unseen[@]}"; do check+=(--check-log "$tmp/$g.log"); done
: > "$here/summary.txt"
for fit in raster constant-cache draw-sizes draw-sizes+constant-cache; do
  flags=()
  [[ $fit == *constant-cache* ]] && flags+=(--constant-cache)
  [[ $fit == draw-sizes* ]] && flags+=(--draw-sizes)
  "$sg" calibrate --from-log "$tmp/train.log" "${check[@]}" --form raster --outside-pipes none --near-best-weight 0 "${flags[@]}" -o "$tmp/p.yaml" |
    grep -v ": device profile of" > "$here/fit-$fit.txt"
  grep -v '^# held-out' "$tmp/p.yaml" > "$here/fit-$fit.yaml"
  {
    echo "$fit: $(grep -E '^leave-one-rig-out over' "$here/fit-$fit.txt")"
    echo "$fit: $(grep -E '^held-out check over' "$here/fit-$fit.txt")"
    # The held-out pairs whose chosen plan is over 5 % slower than the fastest.
    awk '/^held-out check:/{h=1} h && /^\|/' "$here/fit-$fit.txt" | awk -F'|' -v f="$fit" '$6+0 > 1.05 {print f ": over 5 %:" $2 "|" $3 "|" $6}'
  } >> "$here/summary.txt"
done
cat "$here/summary.txt"
