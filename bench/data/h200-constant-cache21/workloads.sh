#!/usr/bin/env bash
# rig mesh joints-per-warp palette-entries-per-warp for every (rig, mesh) pair of session 18/19's H200 logs
# (explain's workload line). Usage: C1=DIR C2=DIR bash workloads.sh > workloads.txt
cd "$(dirname "$0")/../../.."
S=${SG:-build/generator/cli/shadergen} C1=${C1:?corpus of seed 1 (calibrate --corpus 16 --seed 1 --write-corpus)} C2=${C2:?corpus of seed 2 (--corpus 6 --seed 2)}
wl() {  # rig frag rules mesh(or own)
  local m=()
  [ "$4" != own ] && m=(--mesh $4)
  $S explain --rig "$1" -f "$2" -r "$3" --device-profile devices/nvidia-h200-raster.yaml "${m[@]}" 2>/dev/null | awk '/workload:/ && !n { print; n = 1 }' |
    perl -ne '$j = /([0-9.]+) distinct joints per warp/ ? $1 : 0; $e = /\(([0-9.]+) over all/ ? $1 : 0; print "$j $e\n"'
}
D=examples/dawn/rules.yaml; T=rules/standard.yaml; V=tests/validate/data
for r in $C1/*.rig.yaml $C2/*.rig.yaml; do for m in dawn head; do echo "$(basename $r) $m $(wl $r ${r%.rig.yaml}.frag $D $m)"; done; done
for r in face face-packed; do for m in dawn head; do echo "$r.rig.yaml $m $(wl examples/dawn/$r.rig.yaml examples/dawn/face.frag $D $m)"; done; done
for m in dawn head; do echo "body.rig.yaml $m $(wl examples/dawn/body.rig.yaml examples/dawn/depth.frag $D $m)"; done
for r in limb16 limb8_palette300 face52 octahedral qtangent limb8 limb4_unorm8 face52_sparse octahedral_or_float qtangent_or_float morph_scaled bitpacked_or_separate; do
  for m in dawn head; do echo "$r.rig.yaml $m $(wl $V/$r.rig.yaml $V/world.frag $T $m)"; done; done
for m in dawn head; do echo "pbr_character.rig.yaml $m $(wl $V/pbr_character.rig.yaml examples/threejs/standard_normalmap.frag $T $m)"; done
for r in formats_a formats_b; do for m in dawn head; do echo "$r.rig.yaml $m $(wl $V/$r.rig.yaml $V/formats.frag $T $m)"; done; done
for m in dawn head; do echo "threejs-mesh.rig.yaml $m $(wl examples/threejs/mesh.rig.yaml examples/threejs/$(ls examples/threejs | grep frag | head -1) $T $m)"; done
M=../shared/models
echo "Fox.glb#0/0 own $(wl $M/Fox/Fox.glb#0/0 tests/gltf/data/solid.frag $T own)"
echo "CesiumMan.glb#0/0 own $(wl $M/CesiumMan/CesiumMan.glb#0/0 tests/gltf/data/lit.frag $T own)"
for p in 0/0 1/0 1/1 2/0 2/1 2/2 3/0 4/0 5/0 6/0 7/0 8/0 9/0 10/0 11/0 12/0 12/1 13/0 13/1; do
  echo "RobotExpressive.glb#$p own $(wl $M/RobotExpressive/RobotExpressive.glb#$p tests/gltf/data/lit.frag $T own)"; done
echo "AnimatedMorphSphere.meshopt-cc-kv.glb#0/0 own $(wl tests/gltf/data/gltfpack/AnimatedMorphSphere.meshopt-cc-kv.glb#0/0 tests/gltf/data/lit.frag $T own)"
echo "LeePerrySmith.glb#0/0 own $(wl $M/LeePerrySmith/LeePerrySmith.glb#0/0 tests/gltf/data/lit.frag $T own)"
