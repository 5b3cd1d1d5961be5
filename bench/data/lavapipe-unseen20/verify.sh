#!/usr/bin/env bash
# verify.sh PROFILE OUT (session 20, from the repository's build): lavapipe, as session 17's
# verify.sh (raster off, 6 rounds, each program validated first), on rigs no lavapipe profile or
# check has seen: the first 8 random rigs of corpus seed 31 and the suite rigs first timed on the
# H200 after the fits (limb8, limb4_unorm8, formats_a, formats_b, morph_scaled), at Dawn scale and
# on the head. OUT gets each bench's summary line (chosen / fastest, and within one round).
cd "$(git -C "$(dirname "$0")" rev-parse --show-toplevel)"
export XDG_RUNTIME_DIR=/tmp/xdg
p=$1; out=$2; : > "$out"
corpus=$(mktemp -d)
build/generator/cli/shadergen calibrate --corpus 8 --seed 31 --write-corpus "$corpus/c31" -r examples/dawn/rules.yaml > "$corpus/list.txt" || exit 1
b=(--no-validation-layers --raster off --draws 2 --frames 3 --rounds 6 --no-floor --device-profile $p)
one() { echo "== $1" >> $out; shift; timeout 300 build/generator/cli/shadergen bench "${b[@]}" "$@" 2>&1 | grep -E "device profile:|FAIL|error" >> $out; }
H=tests/validate/data; std=(-r rules/standard.yaml --templates templates); dawn=(-r examples/dawn/rules.yaml --templates templates)
for mesh in dawn head; do
  for rig in limb8 limb4_unorm8 formats_a formats_b morph_scaled; do one "$rig on $mesh" --rig $H/$rig.rig.yaml -f $H/world.frag "${std[@]}" --mesh $mesh; done
  while read -r rig frag; do one "$(basename $rig .rig.yaml) on $mesh" --rig $rig -f $frag "${dawn[@]}" --mesh $mesh; done < "$corpus/list.txt"
done
