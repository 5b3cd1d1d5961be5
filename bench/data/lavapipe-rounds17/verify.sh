#!/usr/bin/env bash
# verify.sh PROFILE OUT (session 17, from the repository's build): on lavapipe, raster off, 6 rounds, bench
# the plan PROFILE chooses and every alternative (each validated first) for the held-out rigs: the Dawn
# face, the PBR character, the suite's world-space rigs, Dawn's body depth pass and the 6 random rigs of
# seed 2; OUT gets each bench's summary line (chosen / fastest, and within one round).
cd "$(git -C "$(dirname "$0")" rev-parse --show-toplevel)"
export XDG_RUNTIME_DIR=/tmp/xdg
p=$1; out=$2; : > "$out"
corpus=$(mktemp -d)
build/generator/cli/shadergen calibrate --corpus 6 --seed 2 --write-corpus "$corpus/c2" > "$corpus/list.txt" || exit 1
b=(--no-validation-layers --raster off --draws 2 --frames 3 --rounds 6 --no-floor --device-profile $p)
one() { echo "== $1" >> $out; shift; timeout 300 build/generator/cli/shadergen bench "${b[@]}" "$@" 2>&1 | grep -E "device profile:|FAIL|error" >> $out; }
H=tests/validate/data; std=(-r rules/standard.yaml --templates templates); dawn=(-r examples/dawn/rules.yaml --templates templates)
for mesh in dawn head; do
  one "Dawn face on $mesh" --rig examples/dawn/face.rig.yaml -f examples/dawn/face.frag "${dawn[@]}" --mesh $mesh
  one "pbr_character on $mesh" --rig $H/pbr_character.rig.yaml -f examples/threejs/standard_normalmap.frag "${std[@]}" --mesh $mesh
  for rig in limb16 limb8_palette300 face52 octahedral qtangent; do one "$rig on $mesh" --rig $H/$rig.rig.yaml -f $H/world.frag "${std[@]}" --mesh $mesh; done
  one "body depth on $mesh" --rig examples/dawn/body.rig.yaml -f examples/dawn/depth.frag "${dawn[@]}" --mesh $mesh
  while read -r rig frag; do one "$(basename $rig .rig.yaml) on $mesh" --rig $rig -f $frag "${dawn[@]}" --mesh $mesh; done < "$corpus/list.txt"
done
