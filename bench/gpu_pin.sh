#!/usr/bin/env bash
# Runs on the GPU machine, from the unpacked bundle (bench/gpu_bundle.sh): a measured choice
# (docs/performance.md, "A measured choice") on rigs no profile was fitted on. For each (rig,
# request, mesh): `bench --candidates K --pin-out` times the K plans cheapest under the profile,
# each validated on the device first (widened to the 3K cheapest, or SG_MAX_CANDIDATES, where the
# device does not show the profile's differences between the K), and pins the fastest (tune/, pins/); then, with
# SG_PIN_CHECK=N (default 12), a second, independent bench times the N cheapest (check/), the
# figures the pin is judged by. bench/pin_table.py makes the table from OUTDIR.
# Usage: bash gpu_pin.sh [DEVICE=NVIDIA] [OUTDIR=.] ; SG_SEEDS="68 69" (corpus seeds, 6 rigs each),
# SG_PROFILE (default the bundle's devices/nvidia-h200-raster.yaml; several, space-separated: a portable choice), SG_CANDIDATES (4),
# SG_MESHES ("dawn head"), SG_SUITE=1 also the Dawn face, its body's depth pass and the suite's held-out
# rigs, SG_MODELS=1 the shared glTF models' skinned and morphed parts on their own meshes, SG_RASTER (on; off on lavapipe: its clock is then the process's CPU time, as calibrate's), SG_ROUNDS (3),
# SG_PROCESSES (1): each bench, the tune and the check, in that many fresh processes, their rounds merged (3 on lavapipe,
# where one process in seven ran one program 25 % slower in every round).
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
device=${1-NVIDIA}
outdir=${2:-.}
source "$here/gpu_env.sh"
# Several profiles (space-separated): the portable objective, the same on every device, whose pins
# `shadergen pin merge` weighs together (docs/performance.md, "Several devices").
profiles=()
for p in ${SG_PROFILE:-$here/devices/nvidia-h200-raster.yaml}; do profiles+=(--device-profile "$p"); done
t=(--no-validation-layers --raster "${SG_RASTER:-on}" --no-floor --draws 32 --min-frame-vertices 64000 --frames 7 --rounds "${SG_ROUNDS:-3}"
   --device "$device" "${profiles[@]}" --processes "${SG_PROCESSES:-1}")
dawnRules=(-r "$here/examples/dawn/rules.yaml" --templates "$here/templates")
std=(-r "$here/rules/standard.yaml" --templates "$here/templates")
mkdir -p "$outdir/pins" "$outdir/tune" "$outdir/check" "$outdir/corpus"
pair() {  # pair NAME RIG FRAG RULES...: every mesh of SG_MESHES
  local name=$1 rig=$2 frag=$3; shift 3
  for mesh in ${SG_MESHES:-dawn head}; do
    local t0=$SECONDS
    "$sg" bench "${t[@]}" --mesh "$mesh" --rig "$rig" -f "$frag" "$@" --candidates "${SG_CANDIDATES:-4}" \
      ${SG_MAX_CANDIDATES:+--max-candidates "$SG_MAX_CANDIDATES"} --pin-out "$outdir/pins/$name-$mesh.pin.yaml" > "$outdir/tune/$name-$mesh.log" 2>&1
    local rc=$?
    if [ "${SG_PIN_CHECK:-12}" -gt 0 ]; then
      "$sg" bench "${t[@]}" --mesh "$mesh" --rig "$rig" -f "$frag" "$@" --candidates "${SG_PIN_CHECK:-12}" \
        --max-candidates "${SG_PIN_CHECK:-12}" > "$outdir/check/$name-$mesh.log" 2>&1
    fi
    echo "== $name $mesh: tune exit $rc, $((SECONDS - t0)) s"
  done
}
model() {  # model NAME RIG FRAG RULES...: a glTF primitive, drawn on its own mesh
  local name=$1 rig=$2 frag=$3; shift 3
  local t0=$SECONDS
  "$sg" bench "${t[@]}" --rig "$rig" -f "$frag" "$@" --candidates "${SG_CANDIDATES:-4}" \
    ${SG_MAX_CANDIDATES:+--max-candidates "$SG_MAX_CANDIDATES"} --pin-out "$outdir/pins/$name-own.pin.yaml" > "$outdir/tune/$name-own.log" 2>&1
  local rc=$?
  if [ "${SG_PIN_CHECK:-12}" -gt 0 ]; then
    "$sg" bench "${t[@]}" --rig "$rig" -f "$frag" "$@" --candidates "${SG_PIN_CHECK:-12}" --max-candidates "${SG_PIN_CHECK:-12}" \
      > "$outdir/check/$name-own.log" 2>&1
  fi
  echo "== $name own mesh: tune exit $rc, $((SECONDS - t0)) s"
}
if [ "${SG_MODELS:-0}" = 1 ]; then  # the shared glTF models' skinned and morphed parts, on their own meshes
  m="$here/examples/models"
  model fox "$m/Fox.glb#0/0" "$here/examples/gltf/solid.frag" "${std[@]}"
  model cesiumman "$m/CesiumMan.glb#0/0" "$here/examples/gltf/lit.frag" "${std[@]}"
  for part in 1/0 2/0 12/0; do
    model "robot-${part/\//_}" "$m/RobotExpressive.glb#$part" "$here/examples/gltf/lit.frag" "${std[@]}"
  done
fi
for seed in ${SG_SEEDS-68}; do
  "$sg" calibrate --corpus 6 --seed "$seed" -f "$here/examples/dawn/face.frag" "${dawnRules[@]}" \
    --write-corpus "$outdir/corpus/s$seed" > /dev/null
  for rig in "$outdir/corpus/s$seed"/*.rig.yaml; do
    name=$(basename "$rig" .rig.yaml)
    pair "s$seed-$name" "$rig" "${rig%.rig.yaml}.frag" "${dawnRules[@]}"
  done
done
if [ "${SG_SUITE:-0}" = 1 ]; then
  data="$here/examples/heldout"
  pair dawn-face "$here/examples/dawn/face.rig.yaml" "$here/examples/dawn/face.frag" "${dawnRules[@]}"
  pair body-depth "$here/examples/dawn/body.rig.yaml" "$here/examples/dawn/depth.frag" "${dawnRules[@]}"
  for r in limb16 limb8_palette300 face52 octahedral qtangent; do pair "world-$r" "$data/$r.rig.yaml" "$data/world.frag" "${std[@]}"; done
  for r in pbr_character limb8_palette300; do pair "pbr-$r" "$data/$r.rig.yaml" "$data/standard_normalmap.frag" "${std[@]}"; done
fi
