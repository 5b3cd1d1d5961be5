#!/usr/bin/env bash
# choices.sh PROFILE_A PROFILE_B (session 29): every (rig, mesh) pair of the lavapipe held-out sets (session 17's
# verify set, session 20's unseen rigs, corpus seeds 2, 5, 6 and 31, the unseen and format rigs, the shared glTF
# models) whose plan differs between the two profiles, by the rules `explain` lists; prints each difference.
cd "$(git -C "$(dirname "$0")" rev-parse --show-toplevel)"
sg=build/generator/cli/shadergen
corpus=$(mktemp -d)
$sg calibrate --corpus 6 --seed 2 --write-corpus "$corpus/c2" > "$corpus/list.txt"
$sg calibrate --corpus 8 --seed 31 --write-corpus "$corpus/c31" -r examples/dawn/rules.yaml > "$corpus/list31.txt"
for sd in 5 6; do $sg calibrate --corpus 6 --seed $sd --write-corpus "$corpus/c$sd" -r examples/dawn/rules.yaml >> "$corpus/list31.txt"; done
H=tests/validate/data; std=(-r rules/standard.yaml); dawn=(-r examples/dawn/rules.yaml)
n=0
one() { n=$((n + 1)); name=$1; shift; a=$($sg explain "$@" --device-profile $A 2>&1 | grep -E " <- " | sed 's/(cost.*//' | sort); b=$($sg explain "$@" --device-profile $B 2>&1 | grep -E " <- " | sed 's/(cost.*//' | sort); [ "$a" != "$b" ] && { echo "DIFFERS: $name"; diff <(echo "$a") <(echo "$b") | grep "^[<>]" | tr -s ' '; }; }
A=$1; B=$2
for mesh in dawn head; do
  one "Dawn face on $mesh" --rig examples/dawn/face.rig.yaml -f examples/dawn/face.frag "${dawn[@]}" --mesh $mesh
  one "Dawn face packed on $mesh" --rig examples/dawn/face-packed.rig.yaml -f examples/dawn/face.frag "${dawn[@]}" --mesh $mesh
  one "pbr_character on $mesh" --rig $H/pbr_character.rig.yaml -f examples/threejs/standard_normalmap.frag "${std[@]}" --mesh $mesh
  for rig in limb16 limb8_palette300 face52 face52_sparse octahedral qtangent formats_a formats_b morph_scaled limb8 limb4_unorm8 octahedral_or_float qtangent_or_float bitpacked_or_separate; do one "$rig on $mesh" --rig $H/$rig.rig.yaml -f $H/world.frag "${std[@]}" --mesh $mesh; done
  one "threejs-mesh on $mesh" --rig $H/threejs-mesh.rig.yaml -f $H/world.frag "${std[@]}" --mesh $mesh
  one "body depth on $mesh" --rig examples/dawn/body.rig.yaml -f examples/dawn/depth.frag "${dawn[@]}" --mesh $mesh
  while read -r rig frag; do one "$(basename $rig .rig.yaml) on $mesh" --rig $rig -f $frag "${dawn[@]}" --mesh $mesh; done < "$corpus/list.txt"
  while read -r rig frag; do one "$(basename $rig .rig.yaml) on $mesh" --rig $rig -f $frag "${dawn[@]}" --mesh $mesh; done < "$corpus/list31.txt"
done
shared=$(pwd)/../shared/models
for m in AnimatedMorphSphere/AnimatedMorphSphere.gltf LeePerrySmith/LeePerrySmith.glb MorphStressTest/MorphStressTest.gltf CesiumMan/CesiumMan.glb Fox/Fox.glb RobotExpressive/RobotExpressive.glb; do
  for prim in 0/0 0/1 1/0 1/1 2/0 2/1 2/2 3/0 4/0 5/0 6/0 7/0 8/0 9/0 10/0 11/0 12/0 12/1 13/0 13/1; do
    [ -f $shared/$m ] || continue
    $sg explain --rig "$shared/$m#$prim" -f tests/gltf/data/lit.frag -r rules/standard.yaml >/dev/null 2>&1 || continue
    one "$m#$prim" --rig "$shared/$m#$prim" -f tests/gltf/data/lit.frag -r rules/standard.yaml
  done
done
echo "compared $n (rig, mesh) pairs"
