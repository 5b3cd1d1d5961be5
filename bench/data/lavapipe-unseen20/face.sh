#!/usr/bin/env bash
# face.sh PROFILE OUT: the Dawn face (and corpus-1384409982 of seed 31, the one unseen pair settle.sh
# left over 10 %) on lavapipe, 4 draws, 5 frames, 20 rounds, each program validated first.
cd "$(git -C "$(dirname "$0")" rev-parse --show-toplevel)"
export XDG_RUNTIME_DIR=/tmp/xdg
p=$1; out=$2; : > "$out"
corpus=$(mktemp -d)
build/generator/cli/shadergen calibrate --corpus 8 --seed 31 --write-corpus "$corpus/c31" -r examples/dawn/rules.yaml > /dev/null || exit 1
b=(--no-validation-layers --raster off --draws 4 --frames 5 --rounds 20 --no-floor --device-profile $p)
one() { echo "== $1" >> $out; shift; timeout 900 build/generator/cli/shadergen bench "${b[@]}" "$@" 2>&1 | grep -E "device profile:|fastest validated|FAIL|error" >> $out; }
dawn=(-r examples/dawn/rules.yaml --templates templates)
for mesh in dawn head; do
  one "Dawn face on $mesh" --rig examples/dawn/face.rig.yaml -f examples/dawn/face.frag "${dawn[@]}" --mesh $mesh
done
one "corpus-1384409982 on head" --rig $corpus/c31/corpus-1384409982.rig.yaml -f $corpus/c31/corpus-1384409982.frag "${dawn[@]}" --mesh head
