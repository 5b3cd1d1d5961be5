#!/usr/bin/env bash
# Runs on the GPU machine, from the unpacked bundle of bench/gpu_bundle.sh: the Dawn face's
# vertex layouts timed at Dawn scale (docs/performance.md, "Vertex layouts on the H200"). The
# float layout (face.rig.yaml, 220 B in 16 locations) and the packed one (face-packed.rig.yaml,
# 112 B in 15 locations: bounds-relative unorm16 positions, the frame as a QTangent, halves,
# bytes) and the bit-packed one (face-bitpacked.rig.yaml: the same values in the words of two
# uint32x4 attributes, 12 locations), each planned by instruction slots and under the H200 profile; every program
# validated on the device before it is timed (and both layouts' plans under the profile with
# --cross-check first), the hand port of listing 3-3 and the floors beside them.
# Usage: bash gpu_layouts.sh [DEVICE=NVIDIA]   (SG_MESH, SG_DRAWS, SG_FRAMES: a quick local try)
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
device=${1:-NVIDIA}
mesh=${SG_MESH:-dawn}
draws=${SG_DRAWS:-64}
frames=${SG_FRAMES:-11}
source "$here/gpu_env.sh"
face=(-f "$here/examples/dawn/face.frag" -r "$here/examples/dawn/rules.yaml" --templates "$here/templates")
for rig in face face-packed face-bitpacked; do
  echo "== validate $rig.rig.yaml under the H200 profile, $mesh mesh, cross-check"
  "$sg" validate --rig "$here/examples/dawn/$rig.rig.yaml" "${face[@]}" --device-profile "$here/devices/nvidia-h200.yaml" \
    --device "$device" --no-validation-layers --mesh "$mesh" --cross-check | grep -E '^(PASS|FAIL)|: PASS|: FAIL'
done
common=("${face[@]}" --device "$device" --no-validation-layers --mesh "$mesh" --raster on --draws "$draws" --frames "$frames" --rounds 2)
for rig in face face-packed face-bitpacked; do
  # The hand port reads the float layout's attributes as they are: only that layout has it.
  hand=()
  [ "$rig" = face ] && hand=(--hand-port "$here/examples/dawn/listing-3-3.vert")
  for profile in "" nvidia-h200; do
    echo "== $rig.rig.yaml, ${profile:-instruction slots}"
    prof=()
    [ -n "$profile" ] && prof=(--device-profile "$here/devices/$profile.yaml")
    "$sg" bench --rig "$here/examples/dawn/$rig.rig.yaml" "${common[@]}" "${prof[@]}" "${hand[@]}" --no-alternatives
  done
done
