#!/usr/bin/env bash
# Session 18: under two profiles, does every held-out and unseen rig get the same plan? (bench/data/h200-draw-counts18: 104 of 104 YAML pairs and 25 of 25 model primitives for nvidia-h200-roofline.yaml and nvidia-h200-raster.yaml)
# Do two profiles choose the same plans? generate under each and compare the GLSL.
cd /work/main; sg=build/generator/cli/shadergen; A=$1; B=$2; d=$(mktemp -d); same=0; diff=0
H=tests/validate/data; std=(-r rules/standard.yaml --templates templates); dawnR=(-r examples/dawn/rules.yaml --templates templates)
one() { local name=$1; shift; $sg generate "$@" --device-profile $A --max-uniform-bytes 65536 --emit glsl -o $d/a >/dev/null 2>&1 || { echo "fail A $name"; return; }
  $sg generate "$@" --device-profile $B --max-uniform-bytes 65536 --emit glsl -o $d/b >/dev/null 2>&1 || { echo "fail B $name"; return; }
  if cmp -s <(grep -v "^ *//" $d/a) <(grep -v "^ *//" $d/b); then same=$((same+1)); else diff=$((diff+1)); echo "DIFFERENT: $name"; fi; }
for s in 1 2 3 4 5 6; do $sg calibrate --corpus 6 --seed $s --write-corpus $d/c$s -r examples/dawn/rules.yaml > $d/list$s.txt 2>/dev/null; done
for mesh in dawn head; do
  one "face $mesh" --rig examples/dawn/face.rig.yaml -f examples/dawn/face.frag "${dawnR[@]}" --mesh $mesh
  one "face-packed $mesh" --rig examples/dawn/face-packed.rig.yaml -f examples/dawn/face.frag "${dawnR[@]}" --mesh $mesh
  one "body-depth $mesh" --rig examples/dawn/body.rig.yaml -f examples/dawn/depth.frag "${dawnR[@]}" --mesh $mesh
  one "pbr $mesh" --rig $H/pbr_character.rig.yaml -f examples/threejs/standard_normalmap.frag "${std[@]}" --mesh $mesh
  for r in limb16 limb8_palette300 face52 octahedral qtangent limb8 limb4_unorm8 face52_sparse octahedral_or_float qtangent_or_float morph_scaled bitpacked_or_separate; do one "$r $mesh" --rig $H/$r.rig.yaml -f $H/world.frag "${std[@]}" --mesh $mesh; done
  for s in 1 2 3 4 5 6; do while read -r rig frag; do one "$(basename $rig) $mesh" --rig $rig -f $frag "${dawnR[@]}" --mesh $mesh; done < $d/list$s.txt; done
done
# Every model primitive the H200 logs timed, on its own mesh.
for r in $(cat bench/data/h200-bone-columns15/*/*.log bench/data/h200-draw-counts18/*.log | grep -oE "[A-Za-z.-]+\.(glb|gltf)#[0-9]+/[0-9]+" | sort -u); do
  f=${r%%#*}; p=$(find ../shared/models tests/gltf/data -name "$f" | head -1); [ -z "$p" ] && { echo "no $f"; continue; }
  case $f in Fox*) fr=tests/gltf/data/solid.frag ;; *) fr=tests/gltf/data/lit.frag ;; esac
  one "$r" --rig "$p#${r#*#}" -f $fr -r rules/standard.yaml
done
echo "same $same, different $diff"
