#!/usr/bin/env bash
# Runs on the GPU machine, from the unpacked bundle of bench/gpu_bundle.sh: the Dawn face's
# vertex layouts timed at Dawn scale (docs/performance.md, "Layouts"). The float layout
# (face.rig.yaml, 220 B in 16 locations) and the packed one (face-packed.rig.yaml, 116 B in
# 16 locations: bounds-relative unorm16 positions, octahedral frame, halves, bytes), each
# planned by instruction slots and under the H200 profile; every program validated on the
# device before it is timed, the hand port of listing 3-3 and the floors beside them.
# Usage: bash gpu_layouts.sh [DEVICE=NVIDIA]   (SG_MESH, SG_DRAWS, SG_FRAMES: a quick local try)
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
device=${1:-NVIDIA}
mesh=${SG_MESH:-dawn}
draws=${SG_DRAWS:-64}
frames=${SG_FRAMES:-11}
source "$here/gpu_env.sh"
common=(-f "$here/examples/dawn/face.frag" -r "$here/examples/dawn/rules.yaml" --templates "$here/templates"
        --device "$device" --no-validation-layers --mesh "$mesh" --raster on --draws "$draws" --frames "$frames" --rounds 2)
for rig in face face-packed; do
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
