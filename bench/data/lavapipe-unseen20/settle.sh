#!/usr/bin/env bash
# settle.sh PROFILE OUT: the pairs verify.sh put over 10 % in either of its two runs (and the Dawn
# face, as a baseline of the same machine state), timed again with more repetitions: 4 draws,
# 5 frames, 10 rounds.
cd "$(git -C "$(dirname "$0")" rev-parse --show-toplevel)"
export XDG_RUNTIME_DIR=/tmp/xdg
p=$1; out=$2; : > "$out"
corpus=$(mktemp -d)
build/generator/cli/shadergen calibrate --corpus 8 --seed 31 --write-corpus "$corpus/c31" -r examples/dawn/rules.yaml > /dev/null || exit 1
b=(--no-validation-layers --raster off --draws 4 --frames 5 --rounds 10 --no-floor --device-profile $p)
one() { echo "== $1" >> $out; shift; timeout 600 build/generator/cli/shadergen bench "${b[@]}" "$@" 2>&1 | grep -E "device profile:|FAIL|error" >> $out; }
H=tests/validate/data; std=(-r rules/standard.yaml --templates templates); dawn=(-r examples/dawn/rules.yaml --templates templates)
for mesh in dawn head; do
  for rig in formats_a formats_b morph_scaled; do one "$rig on $mesh" --rig $H/$rig.rig.yaml -f $H/world.frag "${std[@]}" --mesh $mesh; done
  for c in 1384409982 2626096791; do one "corpus-$c on $mesh" --rig $corpus/c31/corpus-$c.rig.yaml -f $corpus/c31/corpus-$c.frag "${dawn[@]}" --mesh $mesh; done
  one "Dawn face on $mesh" --rig examples/dawn/face.rig.yaml -f examples/dawn/face.frag "${dawn[@]}" --mesh $mesh
done
