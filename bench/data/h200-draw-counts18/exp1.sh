#!/usr/bin/env bash
# Session 18, experiment 1: is the head's extra cost per vertex on the fragment side? The face's
# generated plan and floor at three render-target sizes, raster on and off, on the head and at Dawn
# scale; two small real-model draws (the H200 misses) with their alternatives, the same.
set -u
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
mkdir -p /tmp/b && tar -xzf .bundle/sg.tar.gz -C /tmp/b
here=/tmp/b/sg; source $here/gpu_env.sh
dev=${DEV:-NVIDIA}
a=(--no-validation-layers --device $dev --draws ${DRAWS:-32} --min-frame-vertices 64000 --frames ${FRAMES:-7} --rounds ${ROUNDS:-2} --raster both --device-profile $here/devices/nvidia-h200-roofline.yaml)
std=(-f $here/examples/gltf/lit.frag -r $here/rules/standard.yaml --templates $here/templates)
for size in ${SIZES:-64x64 256x256 1024x1024}; do
  for mesh in head dawn; do
    echo "=== face $mesh $size"; $sg bench "${dawn[@]}" --mesh $mesh --size $size "${a[@]}" --no-alternatives 2>&1 | grep -E "^\||generated program|mesh:|counted"
  done
  for m in "RobotExpressive.glb#2/0" "AnimatedMorphSphere.meshopt-cc-kv.glb#0/0"; do
    echo "=== $m $size"; $sg bench --rig "$here/examples/models/$m" "${std[@]}" --size $size "${a[@]}" 2>&1 | grep -E "^\||generated program|mesh:|counted"
  done
done
# The two corpus misses, every alternative, raster on and off.
for size in ${SIZES:-64x64 256x256}; do
  echo "=== corpus-794921487 head $size"; $sg bench --rig .bundle/rigs/corpus-794921487.rig.yaml -f .bundle/rigs/corpus-794921487.frag -r $here/examples/dawn/rules.yaml --templates $here/templates --mesh head --size $size "${a[@]}" 2>&1 | grep -E "^\||generated program|mesh:|counted"
  echo "=== corpus-1562238070 dawn $size"; $sg bench --rig .bundle/rigs/corpus-1562238070.rig.yaml -f .bundle/rigs/corpus-1562238070.frag -r $here/examples/dawn/rules.yaml --templates $here/templates --mesh dawn --size $size "${a[@]}" 2>&1 | grep -E "^\||generated program|mesh:|counted"
done
