#!/usr/bin/env bash
# Runs on the GPU machine, from the unpacked bundle (bench/gpu_bundle.sh): benches held-out
# rigs under a device profile (every alternative, each validated on the device before it is
# timed), so the plan the profile chooses is itself timed, and each rig's portable plan (this
# device's profile and another's, below). Usage: bash gpu_verify.sh PROFILE [DEVICE=NVIDIA];
# on a CPU device SG_RASTER=off times by the clock its profile was fitted on (process CPU time).
# SG_VERIFY_TABLES=FILE keeps every bench table (each alternative's time) beside the summary.
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
  timeout 120 "$sg" bench "${b[@]}" "$@" 2>&1 | tee -a "${SG_VERIFY_TABLES:-/dev/null}" |
    grep -E "generated|chosen|Spearman|FAIL|error" | grep -v "^| forced" | head -6
}
# The portable plans: this device's profile and another's (default lavapipe's; on lavapipe, pass
# SG_PORTABLE_WITH=devices/nvidia-h200-roofline.yaml for the two-device choice).
other=${SG_PORTABLE_WITH:-$here/devices/llvmpipe-2core.yaml}
for mesh in dawn head; do
  for rig in limb16 limb8_palette300 face52; do
    one "$rig on $mesh" --rig "$data/$rig.rig.yaml" -f "$data/world.frag" "${std[@]}" --device-profile "$profile" --mesh "$mesh"
    one "$rig, portable (this device + $(basename "$other" .yaml)) on $mesh" --rig "$data/$rig.rig.yaml" -f "$data/world.frag" \
      "${std[@]}" --device-profile "$profile" --device-profile "$other" --mesh "$mesh"
  done
  one "Dawn face on $mesh" "${dawn[@]}" --device-profile "$profile" --mesh "$mesh"
  one "Dawn face, portable (this device + $(basename "$other" .yaml)) on $mesh" "${dawn[@]}" --device-profile "$profile" \
    --device-profile "$other" --mesh "$mesh"
done
