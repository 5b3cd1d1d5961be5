#!/usr/bin/env bash
# Session 29, offline (no device; about a minute): lavapipe's profile with a price past a threshold on the
# vertex inputs (`--threshold locations`), fitted without bench's floors (`--no-floors`), against the
# additive fit as shipped before (with floors, no threshold) and the two halves of the change alone. Each is
# fitted on session 17's training log and checked on every lavapipe held-out log timed with 6 rounds or
# more: session 17's four groups and session 13's three unseen collections (a, b, c).
#   Usage: bash evaluate.sh [shadergen]   (writes fit-*.yaml, fit-*.txt and summary.txt here)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$here/../../..
sg=${1:-$root/build/generator/cli/shadergen}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
D=$root/bench/data
# The held-out logs under names of their own: a check groups a rig's rows by rig and log name.
checks=()
for g in world corpus-heldout body-depth pbr; do cp "$D/lavapipe-rounds17/$g.log" "$tmp/r17-$g.log"; checks+=(--check-log "$tmp/r17-$g.log"); done
for run in a b c; do
  for f in "$D"/lavapipe-unseen13/$run/*.log; do cp "$f" "$tmp/u13$run-$(basename "$f")"; checks+=(--check-log "$tmp/u13$run-$(basename "$f")"); done
done
over() { awk -F'|' -v lim="$2" '/^held-out check/{h=1} h && /^\| / && $6 ~ /[0-9]/ {split($6,a," "); if (a[1]+0 > lim) {n++; s=s sprintf("%s%s %s; ", $2, $3, a[1])}} END{printf "%d over %s: %s\n", n+0, lim, s}' "$1" | tr -s ' '; }
: > "$here/summary.txt"
fit() {  # NAME ARGS...
  local name=$1; shift
  "$sg" calibrate --from-log "$D/lavapipe-rounds17/train.log" --form additive --near-best-weight 0 "$@" -o "$here/fit-$name.yaml" "${checks[@]}" > "$here/fit-$name.txt"
  {
    echo "== $name ($*)"
    grep -E "^(leave-one-rig-out over|held-out check over)" "$here/fit-$name.txt" | cut -d';' -f1
    grep -A1 "^thresholds:" "$here/fit-$name.yaml" | tail -n +2 || true
    echo "held out: $(over "$here/fit-$name.txt" 1.10)"
    echo "held out: $(over "$here/fit-$name.txt" 1.05)"
    grep -E "^\| face(-packed)?\.rig\.yaml \|" "$here/fit-$name.txt" | head -4 | awk -F'|' '{printf "leave-one-rig-out %s%s: %s\n", $2, $3, $6}'
  } >> "$here/summary.txt"
}
fit shipped-form
fit no-floors --no-floors
fit threshold --threshold locations
fit threshold-no-floors --threshold locations --no-floors
cat "$here/summary.txt"
