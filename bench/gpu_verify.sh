#!/usr/bin/env bash
# Runs on the GPU machine, from the unpacked bundle (bench/gpu_bundle.sh): benches held-out
# rigs under a device profile (every alternative, each validated on the device before it is
# timed), so the plan the profile chooses is itself timed, and each rig's portable plan (this
# device's profile and another's, below). Usage: bash gpu_verify.sh PROFILE [DEVICE=NVIDIA];
# on a CPU device SG_RASTER=off times by the clock its profile was fitted on (process CPU time).
# SG_ROUNDS passes over the programs (default 2); with two or more each summary states the
# chosen plan's ratio to the fastest within each round as well (its spread).
# SG_VERIFY_TABLES=FILE keeps every bench table (each alternative's time) beside the summary.
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
profile=$1
device=${2-NVIDIA}
source "$here/gpu_env.sh"
b=(--device "$device" --no-validation-layers --raster "${SG_RASTER:-on}" --draws "${SG_DRAWS:-32}" --frames "${SG_FRAMES:-7}" --rounds "${SG_ROUNDS:-2}" --no-floor)
data="$here/examples/heldout"
std=(-r "$here/rules/standard.yaml" --templates "$here/templates")
one() {  # one LABEL ARGS...: bench, then its summary lines
  echo "== $1"; shift
  timeout 120 "$sg" bench "${b[@]}" "$@" 2>&1 | tee -a "${SG_VERIFY_TABLES:-/dev/null}" |
    grep -E "generated|chosen|Spearman|FAIL|error" | grep -v "^| forced" | head -20
}
# SG_VERIFY_SET=unseen: instead, the rigs, random rigs and models of gpu_collect.sh's "unseen" groups
# and random seeds 5 and 6 (SG_UNSEEN_PART=rigs|corpus|models, default all: a device call's time limit).
if [ "${SG_VERIFY_SET:-heldout}" = unseen ]; then
  part=${SG_UNSEEN_PART:-all}
  models="$here/examples/models"
  if [ "$part" = all ] || [ "$part" = rigs ]; then
    for mesh in dawn head; do
      for rig in "${unseenRigs[@]}"; do
        one "$rig on $mesh" --rig "$data/$rig.rig.yaml" -f "$data/world.frag" "${std[@]}" --device-profile "$profile" --mesh "$mesh"
      done
      for rig in formats_a formats_b; do
        one "$rig on $mesh" --rig "$data/$rig.rig.yaml" -f "$data/formats.frag" "${std[@]}" --device-profile "$profile" --mesh "$mesh"
      done
    done
  fi
  if [ "$part" = all ] || [ "$part" = corpus ]; then
    corpus=$(mktemp -d)
    for seed in 5 6; do
      "$sg" calibrate --corpus 6 --seed "$seed" --write-corpus "$corpus/$seed" > "$corpus/$seed.txt" || exit 1
      for mesh in dawn head; do
        while read -r rig frag; do
          one "$(basename "$rig" .rig.yaml) on $mesh" --rig "$rig" -f "$frag" -r "$here/examples/dawn/rules.yaml" \
            --templates "$here/templates" --device-profile "$profile" --mesh "$mesh"
        done < "$corpus/$seed.txt"
      done
    done
  fi
  if [ "$part" = all ] || [ "$part" = models ]; then
    for m in "${unseenModels[@]}"; do
      one "$m" --rig "$models/$m#*" -f "$here/examples/gltf/lit.frag" "${std[@]}" --device-profile "$profile"
    done
  fi
  exit 0
fi
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
