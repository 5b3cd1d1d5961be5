#!/usr/bin/env bash
# Session 23: BrainStem's parts where the uniform palette and the storage-buffer palette differ most,
# every alternative, at two render-target sizes: is the difference the vertex program's or the fragment side's?
set -u
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
mkdir -p /tmp/b && tar -xzf .bundle/sg.tar.gz -C /tmp/b
here=/tmp/b/sg; source $here/gpu_env.sh > $OUT/gpu.txt 2>&1
a=(--no-validation-layers --device NVIDIA --draws 32 --min-frame-vertices 64000 --frames 7 --rounds ${ROUNDS:-3} --raster on --device-profile $here/devices/nvidia-h200-raster.yaml)
std=(-f $here/examples/gltf/lit.frag -r $here/rules/standard.yaml --templates $here/templates)
for size in ${SIZES:-64x64 256x256}; do
  for m in $SG_PARTS; do
    echo "=== $m $size"; timeout 60 $sg bench --rig ".bundle/unseen/$m" "${std[@]}" --size $size "${a[@]}" 2>&1 | grep -E "^\||generated program|mesh:|counted|within one round"
  done
done 2>&1 | tee $OUT/bs.txt
