#!/usr/bin/env bash
# verify.sh PROFILE OUT (session 29, from the repository's build): on lavapipe, raster off, bench the plan
# PROFILE chooses and every alternative (each validated first) for the pairs whose plan the threshold
# changes (the Dawn face and the PBR character; scripts/choices.sh finds them), the Dawn face at 20 rounds
# of 5 frames at 4 draws (fewer do not settle it on this machine: ../lavapipe-unseen20), the PBR character at 10.
cd "$(git -C "$(dirname "$0")" rev-parse --show-toplevel)"
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp/xdg}
p=$1; out=$2; : > "$out"
b=(--no-validation-layers --raster off --draws 4 --frames 5 --no-floor --device-profile $p)
one() { echo "== $1" >> $out; shift; /usr/bin/time -f "%e s" timeout 1200 build/generator/cli/shadergen bench "${b[@]}" "$@" 2>&1 | grep -E "device profile:|FAIL|error| s$" >> $out; }
std=(-r rules/standard.yaml --templates templates); dawn=(-r examples/dawn/rules.yaml --templates templates)
for mesh in dawn head; do
  one "Dawn face on $mesh" --rig examples/dawn/face.rig.yaml -f examples/dawn/face.frag "${dawn[@]}" --mesh $mesh --rounds 20
done
for mesh in dawn head; do
  one "pbr_character on $mesh" --rig tests/validate/data/pbr_character.rig.yaml -f examples/threejs/standard_normalmap.frag "${std[@]}" --mesh $mesh --rounds 10
done
