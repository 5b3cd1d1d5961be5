#!/usr/bin/env bash
# Runs on the GPU machine, from the unpacked bundle (bench/gpu_bundle.sh): benches held-out
# rigs under a device profile (every alternative, each validated on the device before it is
# timed), so the plan the profile chooses is itself timed, and the portable plan of the Dawn
# face (this device's profile and lavapipe's). Usage: bash gpu_verify.sh PROFILE [DEVICE=NVIDIA];
# on a CPU device SG_RASTER=off times by the clock its profile was fitted on (process CPU time).
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
profile=$1
device=${2-NVIDIA}
source "$here/gpu_env.sh"
b=(--device "$device" --no-validation-layers --raster "${SG_RASTER:-on}" --draws "${SG_DRAWS:-32}" --frames "${SG_FRAMES:-7}" --rounds 2 --no-floor)
data="$here/examples/heldout"
std=(-r "$here/rules/standard.yaml" --templates "$here/templates")
one() {  # one LABEL ARGS...: bench, then its summary lines
  echo "== $1"; shift
  timeout 120 "$sg" bench "${b[@]}" "$@" 2>&1 | grep -E "generated|chosen|Spearman|FAIL|error" | grep -v "^| forced" | head -6
}
for mesh in dawn head; do
  for rig in limb16 limb8_palette300 face52; do
    one "$rig on $mesh" --rig "$data/$rig.rig.yaml" -f "$data/world.frag" "${std[@]}" --device-profile "$profile" --mesh "$mesh"
  done
  one "Dawn face on $mesh" "${dawn[@]}" --device-profile "$profile" --mesh "$mesh"
  one "Dawn face, portable (this device + lavapipe) on $mesh" "${dawn[@]}" --device-profile "$profile" \
    --device-profile "$here/devices/llvmpipe-2core.yaml" --mesh "$mesh"
done
