#!/usr/bin/env bash
# For the next device session (not yet run): which state carries a part's times over from the parts
# timed before it (README.md, order23.sh)? BrainStem's and RobotExpressive's parts timed
#   all-<model>.log        the whole model in one calibrate run, inputs mapped (as order23.sh's all.log)
#   staged-<model>.log     the same with the inputs in device-local memory, through a staging copy
#                          (session 24's default: docs/device-profiles.md, "Where the inputs live")
#   nocache-<model>.log    mapped, with the driver's shader disk cache off
#   parts-<model>/*.log    mapped, one calibrate process per part
# Needs a bundle made at session 24 or later (bench/gpu_bundle.sh): --input-memory is new there.
# Compare each part's plans across the three (order-h100/order.py's U/B, or calibrate --evaluate).
# Run from the repository root on the device machine, as the other scripts here; DEVICE=llvmpipe
# runs it on lavapipe (a dry run). Models under .bundle/unseen/ (BrainStem) or the bundle's own.
set -u
if [ "${DEVICE:-NVIDIA}" = NVIDIA ]; then for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig; fi
mkdir -p /tmp/b "$OUT" && tar -xzf .bundle/sg.tar.gz -C /tmp/b
here=/tmp/b/sg; source $here/gpu_env.sh > $OUT/gpu.txt 2>&1
std=(-f $here/examples/gltf/lit.frag -r $here/rules/standard.yaml --templates $here/templates)
t=(--no-validation-layers --draws 32 --min-frame-vertices 64000 --frames ${SG_FRAMES:-7} --rounds 2 --refits 0 --no-check --no-probes --device "${DEVICE:-NVIDIA}")
for model in ${SG_MODELS:-.bundle/unseen/BrainStem.glb $here/examples/models/RobotExpressive.glb}; do
  name=$(basename "$model" .glb)
  $sg calibrate "${t[@]}" --input-memory mapped --rig "$model#*" "${std[@]}" -o /tmp/p.yaml > "$OUT/all-$name.log" 2>&1
  $sg calibrate "${t[@]}" --input-memory device-local --rig "$model#*" "${std[@]}" -o /tmp/p.yaml > "$OUT/staged-$name.log" 2>&1
  __GL_SHADER_DISK_CACHE=0 $sg calibrate "${t[@]}" --input-memory mapped --rig "$model#*" "${std[@]}" -o /tmp/p.yaml > "$OUT/nocache-$name.log" 2>&1
  mkdir -p "$OUT/parts-$name"
  $sg rig import "$model#*" -o "/tmp/parts-$name" > /dev/null
  for part in $(grep -o '"rig": "[^"]*"' "/tmp/parts-$name/index.json" | sed 's/.*#//; s/"$//'); do
    $sg calibrate "${t[@]}" --input-memory mapped --rig "$model#$part" "${std[@]}" -o /tmp/p.yaml > "$OUT/parts-$name/${part//\//-}.log" 2>&1
  done
  echo "== $name: $(ls "$OUT/parts-$name" | wc -l) parts timed alone"
done
