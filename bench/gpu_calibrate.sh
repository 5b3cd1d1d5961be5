#!/usr/bin/env bash
# Runs on the GPU machine, from the unpacked bundle of bench/gpu_bundle.sh: calibrates the
# device (shadergen calibrate: probes, the Dawn face's plans in its float and packed layouts,
# and bench's floors, each plan validated on the device before it is timed; then the check:
# both layouts' plans under the fitted profile, which the fit never saw), then benches the
# Dawn face under the measured profile with buffer-fed plans (--max-attributes 8) and the hand
# port: predicted against measured time, and the chosen plan against the fastest alternative
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
face=(-f "$here/examples/dawn/face.frag" -r "$here/examples/dawn/rules.yaml" --templates "$here/templates")
echo "== calibrate (probes, both layouts' plans and floors at Dawn scale and on the cached head; then the check)"
"$sg" calibrate --rig "$here/examples/dawn/face.rig.yaml" --rig "$here/examples/dawn/face-packed.rig.yaml" "${face[@]}" \
  --device "$device" --no-validation-layers --meshes "$meshes" --draws "$draws" --frames "$frames" --rounds 2 -o "$profile"
[ "${SG_BENCH:-1}" = 1 ] || exit 0
for mesh in ${meshes//,/ }; do
  echo "== bench under the profile: mesh $mesh, --max-attributes 8"
  "$sg" bench "${dawn[@]}" --device-profile "$profile" --max-attributes 8 --hand-port "$here/examples/dawn/listing-3-3.vert" \
    --device "$device" --no-validation-layers --mesh "$mesh" --raster on --draws "$draws" --frames "$frames" --rounds 2
done
echo "== the plan under the profile"
"$sg" generate "${dawn[@]}" --device-profile "$profile" -o "$outdir/face-profile" --emit glsl
"$sg" explain --rig "$here/examples/dawn/face.rig.yaml" -f "$here/examples/dawn/face.frag" -r "$here/examples/dawn/rules.yaml" \
  --device-profile "$profile" | tail -14
