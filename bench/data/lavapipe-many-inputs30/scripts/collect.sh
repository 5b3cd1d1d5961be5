#!/usr/bin/env bash
# collect.sh SEED OUTDIR PROFILE... (session 30): rigs no lavapipe log had timed, chosen for their many inputs:
# of the 80 random rigs of corpus SEED, the six whose instruction-slot plan declares the most vertex inputs
# (ties by name). Each timed on lavapipe as session 17's training group was (4 draws, 3 frames, 6 rounds, both
# meshes): its instruction-slot plan, the forced alternatives, the floors, and the plan of each profile given
# (--plans-under) with its alternatives, every program validated first; one log per rig, then each profile's
# own plans checked (`calibrate --evaluate PROFILE --check-log ...`: own-plans-NAME.txt).
set -euo pipefail
cd "$(git -C "$(dirname "$0")" rev-parse --show-toplevel)"
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp/xdg}
seed=$1; out=$2; shift 2; mkdir -p "$out"
under=(); for p in "$@"; do under+=(--plans-under "$p"); done
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
sg=build/generator/cli/shadergen
$sg calibrate --corpus 80 --seed "$seed" --write-corpus "$tmp" -r examples/dawn/rules.yaml > "$tmp/list.txt"
while read -r rig frag; do
  n=$(basename "$rig" .rig.yaml)
  $sg generate --rig "$rig" -f "$frag" -r examples/dawn/rules.yaml -o "$tmp/$n.vert" > /dev/null
  echo "$(grep -cE '^layout\(location *= *[0-9]+\) in ' "$tmp/$n.vert") $n"
done < "$tmp/list.txt" | sort -k1,1nr -k2,2 | head -6 > "$out/rigs.txt"
cat "$out/rigs.txt"
while read -r inputs r; do
  /usr/bin/time -f "$r ($inputs inputs): %e s" $sg calibrate --rig "$tmp/$r.rig.yaml" -f "$tmp/$r.frag" -r examples/dawn/rules.yaml \
    --templates templates --no-probes --no-check --no-validation-layers --meshes dawn,head --draws 4 --frames 3 --rounds 6 \
    "${under[@]}" > "$out/$r.log"
done < "$out/rigs.txt"
for p in "$@"; do
  checks=(); for f in "$out"/corpus-*.log; do checks+=(--check-log "$f"); done
  $sg calibrate --evaluate "$p" "${checks[@]}" > "$out/own-plans-$(basename "$p" .yaml).txt"
done
