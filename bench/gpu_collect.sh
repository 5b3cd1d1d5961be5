#!/usr/bin/env bash
# Runs on the GPU machine, from the unpacked bundle (bench/gpu_bundle.sh): times every plan and
# forced alternative of many (rig, request) pairs at Dawn scale and on the cached head, each
# validated on the device first, and the probes once: the samples of `calibrate`, written as
# one log per group, for fits and held-out checks made offline (docs/device-profiles.md,
# "Held-out check"). Usage: bash gpu_collect.sh [DEVICE=NVIDIA] [OUTDIR=.]
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
device=${1:-NVIDIA}
outdir=${2:-.}
source "$here/gpu_env.sh"
t=(--device "$device" --no-validation-layers --meshes "${SG_MESHES:-dawn,head}" --draws "${SG_DRAWS:-32}"
   --frames "${SG_FRAMES:-7}" --rounds "${SG_ROUNDS:-2}" --refits 0 --no-check)
dawnRules=(-r "$here/examples/dawn/rules.yaml" --templates "$here/templates")
std=(-r "$here/rules/standard.yaml" --templates "$here/templates")
data="$here/examples/heldout"
group() {  # group NAME ARGS...: one calibrate run, its log in OUTDIR/NAME.log
  local name=$1; shift
  echo "== $name"
  local t0=$SECONDS
  "$sg" calibrate "${t[@]}" "$@" -o "$outdir/$name.yaml" > "$outdir/$name.log" 2>&1
  echo "   exit $?, $((SECONDS - t0)) s"
}
group face --rig "$here/examples/dawn/face.rig.yaml" --rig "$here/examples/dawn/face-packed.rig.yaml" \
  -f "$here/examples/dawn/face.frag" "${dawnRules[@]}"
group body-depth --no-probes --rig "$here/examples/dawn/body.rig.yaml" --rig "$here/examples/dawn/face.rig.yaml" \
  -f "$here/examples/dawn/depth.frag" "${dawnRules[@]}"
group world --no-probes --rig "$data/limb16.rig.yaml" --rig "$data/limb8_palette300.rig.yaml" --rig "$data/face52.rig.yaml" \
  --rig "$data/octahedral.rig.yaml" --rig "$data/qtangent.rig.yaml" -f "$data/world.frag" "${std[@]}"
group pbr --no-probes --rig "$data/pbr_character.rig.yaml" --rig "$data/limb16.rig.yaml" --rig "$data/limb8_palette300.rig.yaml" \
  -f "$data/standard_normalmap.frag" "${std[@]}"
