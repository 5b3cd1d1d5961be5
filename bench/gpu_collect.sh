#!/usr/bin/env bash
# Runs on the GPU machine, from the unpacked bundle (bench/gpu_bundle.sh): times every plan and
# forced alternative of many (rig, request) pairs, each validated on the device first, as
# `calibrate` samples, one log per group (docs/device-profiles.md, "Held-out check"):
#   train     the probes, the Dawn face's two layouts and a random corpus (the fit's data)
#   train-models  RiggedFigure on its own meshes (the fit's data too)
#   world, corpus-heldout, body-depth, pbr, models   rigs and requests the fit never sees (the check's data)
#   unseen, unseen-formats, unseen-models   rigs and models first timed after the profiles were fitted (session 12)
# Fits and the held-out check are made offline from the logs (shadergen calibrate --from-logs).
# Usage: bash gpu_collect.sh [DEVICE=NVIDIA] [OUTDIR=.]; SG_BUDGET scales every group's time limit,
# SG_GROUPS="train world ..." runs only those groups (a device call's time limit), SG_HELDOUT_SEED picks
# another random held-out set (default 2; the H200 has timed seeds 1-6 by session 23), SG_MESHES the
# procedural meshes (dawn,head; limb: 825 vertices, a small draw), SG_MIN_FRAME_VERTICES the least
# vertices a timed frame draws (64000: the head at 32 draws).
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
device=${1-NVIDIA}
outdir=${2:-.}
source "$here/gpu_env.sh"
t=(--no-validation-layers --meshes "${SG_MESHES:-dawn,head}" --draws "${SG_DRAWS:-32}" --min-frame-vertices "${SG_MIN_FRAME_VERTICES:-64000}"
   --frames "${SG_FRAMES:-7}" --rounds "${SG_ROUNDS:-2}" --refits 0 --no-check)
[ -n "$device" ] && t+=(--device "$device")
# SG_PLANS_UNDER=PROFILE (a path, e.g. "$here/devices/nvidia-h200-raster.yaml"): each rig's plan under that
# profile is timed too, with its alternatives (calibrate --plans-under), so the held-out check sees the plan
# the profile would choose and not only the instruction-slot plan's neighbourhood (about twice the time).
[ -n "${SG_PLANS_UNDER:-}" ] && t+=(--plans-under "$SG_PLANS_UNDER")
dawnRules=(-r "$here/examples/dawn/rules.yaml" --templates "$here/templates")
std=(-r "$here/rules/standard.yaml" --templates "$here/templates")
data="$here/examples/heldout"
models="$here/examples/models"
group() {  # group NAME SECONDS ARGS...: one calibrate run, its log in OUTDIR/NAME.log
  local name=$1 limit=$2; shift 2
  case " ${SG_GROUPS:-$name} " in *" $name "*) ;; *) return 0 ;; esac  # SG_GROUPS: run only these
  limit=$(awk -v l="$limit" -v s="${SG_BUDGET:-1}" 'BEGIN { printf "%d", l * s }')
  local t0=$SECONDS
  timeout -s INT -k 60 "$limit" "$sg" calibrate "${t[@]}" "$@" -o "${SG_PROFILE_DIR:-$outdir}/$name.yaml" > "$outdir/$name.log" 2>&1
  echo "== $name: exit $?, $((SECONDS - t0)) s (limit $limit)"
}
# Each rig is timed in a fresh process (docs/device-profiles.md, "One process per rig"): on the H100
# this group took 236 s so, against 223 s in one process (about 0.4 s per (rig, mesh), 34 of them here;
# bench/data/h100-fresh26).
group train 260 --corpus "${SG_CORPUS:-16}" --seed 1 --rig "$here/examples/dawn/face.rig.yaml" \
  --rig "$here/examples/dawn/face-packed.rig.yaml" -f "$here/examples/dawn/face.frag" "${dawnRules[@]}"
# A real model's own meshes in the fit (small draws, its own vertex order); not one the check uses.
group train-models 40 --no-probes --rig "$models/RiggedFigure.glb#*" -f "$here/examples/gltf/lit.frag" "${std[@]}"
group world 110 --no-probes --rig "$data/limb16.rig.yaml" --rig "$data/limb8_palette300.rig.yaml" \
  --rig "$data/face52.rig.yaml" --rig "$data/octahedral.rig.yaml" --rig "$data/qtangent.rig.yaml" -f "$data/world.frag" "${std[@]}"
# Random rigs and requests of another seed: the check's random held-out set.
group corpus-heldout 130 --no-probes --corpus "${SG_HELDOUT_CORPUS:-6}" --seed "${SG_HELDOUT_SEED:-2}" -f "$here/examples/dawn/face.frag" "${dawnRules[@]}"
group body-depth 30 --no-probes --rig "$here/examples/dawn/body.rig.yaml" -f "$here/examples/dawn/depth.frag" "${dawnRules[@]}"
group pbr 70 --no-probes --rig "$data/pbr_character.rig.yaml" --rig "$data/limb8_palette300.rig.yaml" \
  -f "$data/standard_normalmap.frag" "${std[@]}"
# The Fox has no normals (and bench draws no textures of its own): an unlit request.
group models-fox 30 --no-probes --rig "$models/Fox.glb#*" -f "$here/examples/gltf/solid.frag" "${std[@]}"
group models 90 --no-probes --rig "$models/CesiumMan.glb#*" --rig "$models/RobotExpressive.glb#*" \
  -f "$here/examples/gltf/lit.frag" "${std[@]}"
# First timed after every shipped profile was fitted: the suite's other rigs (encodings offered in
# pairs, bit-packed or separate, sparse targets), the three.js mesh, and models no run has drawn.
unseen=() unseenM=()
for r in "${unseenRigs[@]}"; do unseen+=(--rig "$data/$r.rig.yaml"); done
for m in "${unseenModels[@]}"; do unseenM+=(--rig "$models/$m#*"); done
group unseen 240 --no-probes "${unseen[@]}" -f "$data/world.frag" "${std[@]}"
group unseen-formats 40 --no-probes --rig "$data/formats_a.rig.yaml" --rig "$data/formats_b.rig.yaml" -f "$data/formats.frag" "${std[@]}"
group unseen-models 60 --no-probes "${unseenM[@]}" -f "$here/examples/gltf/lit.frag" "${std[@]}"
