#!/usr/bin/env bash
# portable-face.sh (session 30), on the GPU machine from the repository root, the bundle unpacked in /tmp/b:
# the Dawn face's two-device plan (the H200 roofline profile + lavapipe's) under the lavapipe profile refitted in
# session 30 and under session 29's, on both meshes, with every alternative, each validated on the device before
# it is timed (bench's "chosen" line: the portable plan over the fastest alternative on this GPU).
set -uo pipefail
here=/tmp/b/sg
source "$here/gpu_env.sh"
b=(--device NVIDIA --no-validation-layers --raster on --draws 32 --frames 7 --rounds 2 --no-floor)
for lavapipe in "$here/devices/llvmpipe-2core.yaml" "$PWD/bench/data/lavapipe-many-inputs30/llvmpipe-2core-session29.yaml"; do
  for mesh in head dawn; do
    echo "== Dawn face, portable (nvidia-h200-roofline + $(basename "$lavapipe" .yaml)) on $mesh"
    timeout 150 "$sg" bench "${b[@]}" "${dawn[@]}" --device-profile "$here/devices/nvidia-h200-roofline.yaml" \
      --device-profile "$lavapipe" --mesh "$mesh" 2>&1
  done
done
