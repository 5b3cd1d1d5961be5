#!/usr/bin/env bash
# The constant cache's capacity fitted on session 18's H200 training log and checked on the
# held-out logs of sessions 18 and 19, once the logs carry palette footprints (augment.py):
#   fit-capacity.txt   calibrate --form raster --outside-pipes none --constant-cache   (the profile: fit-capacity.yaml)
#   fit-without.txt    the same logs, the same form, no capacity   (fit-without.yaml)
#   fit-blind.txt      the footprints removed (augment.py blind): what --constant-cache can do without them
#   shipped.txt        devices/nvidia-h200-raster.yaml on the augmented held-out logs
# Usage: bash evaluate.sh [shadergen]   (about 30 s; no device)
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
mkdir -p "$tmp/aug" "$tmp/blind"
python3 "$here/augment.py" "$logs" "$tmp/aug"
python3 "$here/augment.py" "$A/train.log" "$tmp/blind" blind
check=()
for g in "${held[@]}" "${unseen[@]}"; do check+=(--check-log "$tmp/aug/$g.log"); done
fit=(--form raster --outside-pipes none --near-best-weight 0)
"$sg" calibrate --from-log "$tmp/aug/train.log" "${check[@]}" "${fit[@]}" --constant-cache -o "$tmp/c.yaml" | grep -v ": device profile of" > "$here/fit-capacity.txt"
"$sg" calibrate --from-log "$tmp/aug/train.log" "${check[@]}" "${fit[@]}" -o "$tmp/w.yaml" | grep -v ": device profile of" > "$here/fit-without.txt"
"$sg" calibrate --from-log "$tmp/blind/train.log" "${check[@]}" "${fit[@]}" --constant-cache -o "$tmp/b.yaml" | grep -v ": device profile of" > "$here/fit-blind.txt"
"$sg" calibrate --evaluate "$root/devices/nvidia-h200-raster.yaml" "${check[@]}" > "$here/shipped.txt"
grep -v '^# held-out' "$tmp/c.yaml" > "$here/fit-capacity.yaml"
grep -v '^# held-out' "$tmp/w.yaml" > "$here/fit-without.yaml"
for f in fit-capacity fit-without fit-blind; do echo "$f: $(grep -E '^leave-one-rig-out over' "$here/$f.txt")"; echo "$f: $(grep -E '^held-out check over' "$here/$f.txt")"; done
echo "shipped: $(grep -E '^held-out check over' "$here/shipped.txt")"
# Level errors by mesh and pipe, over the training and held-out logs of the two fits.
set -- "$tmp/aug/train.log" "$tmp/aug/corpus-heldout.log" "$tmp/aug/world.log" "$tmp/aug/pbr.log" "$tmp/aug/unseen.log"
python3 "$here/residuals.py" "$here/fit-without.yaml" "$@" > "$here/residuals-without.txt"
python3 "$here/residuals.py" "$here/fit-capacity.yaml" "$@" > "$here/residuals-capacity.txt"
