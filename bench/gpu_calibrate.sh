#!/usr/bin/env bash
# Runs on the GPU machine, from the unpacked bundle of bench/gpu_bundle.sh: calibrates the
# device (shadergen calibrate: probes and the Dawn face's plans, each validated on the device
# before it is timed), then benches the Dawn face under the measured profile: predicted
# against measured time, and the chosen plan against the fastest alternative
# (docs/device-profiles.md). Usage: bash gpu_calibrate.sh [DEVICE=NVIDIA] [OUTDIR=.]
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
device=${1:-NVIDIA}
outdir=${2:-.}
draws=${SG_DRAWS:-64}
frames=${SG_FRAMES:-11}
meshes=${SG_MESHES:-dawn,head}
source "$here/gpu_env.sh"
profile="$outdir/profile.yaml"
echo "== calibrate (probes and the Dawn face's plans, Dawn scale and the cached head)"
"$sg" calibrate "${dawn[@]}" --device "$device" --no-validation-layers --meshes "$meshes" \
  --draws "$draws" --frames "$frames" --rounds 2 -o "$profile"
for mesh in ${meshes//,/ }; do
  for attrs in 16 8; do
    echo "== bench under the profile: mesh $mesh, --max-attributes $attrs"
    "$sg" bench "${dawn[@]}" --device-profile "$profile" --max-attributes "$attrs" --hand-port "$here/examples/dawn/listing-3-3.vert" \
      --device "$device" --no-validation-layers --mesh "$mesh" --raster on --draws "$draws" --frames "$frames" --rounds 2
  done
done
echo "== the plan under the profile"
"$sg" generate "${dawn[@]}" --device-profile "$profile" -o "$outdir/face-profile" --emit glsl
