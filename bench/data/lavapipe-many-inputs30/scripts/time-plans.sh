#!/usr/bin/env bash
# time-plans.sh RIG FRAG RULES ROUNDS OUT [NAME=BENCH-ARGS ...] (session 30): each named plan of one rig timed
# alone (`bench --no-alternatives`, the plan its arguments give: a profile, bans) on lavapipe with the device's
# own limits, raster off, 4 draws, 3 frames, ROUNDS rounds, on both meshes, every program validated first; then
# again in the reverse order, so that a drift of the machine does not favour one plan. One bench report per
# (pass, mesh, plan) in OUT; `best.sh OUT` prints each plan's best time per mesh over the passes.
# A corpus rig: `shadergen calibrate --corpus 80 --seed SEED --write-corpus DIR -r examples/dawn/rules.yaml` first.
set -euo pipefail
cd "$(git -C "$(dirname "$0")" rev-parse --show-toplevel)"
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp/xdg}
rig=$1 frag=$2 rules=$3 rounds=$4 out=$5; shift 5; mkdir -p "$out"
sg=build/generator/cli/shadergen
plans=("$@"); reversed=(); for ((i = ${#plans[@]} - 1; i >= 0; i--)); do reversed+=("${plans[$i]}"); done
for pass in 1 2; do
  [ $pass = 1 ] && order=("${plans[@]}") || order=("${reversed[@]}")
  for mesh in dawn head; do
    for p in "${order[@]}"; do
      name=${p%%=*}; args=${p#*=}
      # shellcheck disable=SC2086
      $sg bench --rig "$rig" -f "$frag" -r "$rules" --templates templates --device llvmpipe --no-validation-layers \
        --no-alternatives --no-floor --raster off --mesh $mesh --draws 4 --frames 3 --rounds "$rounds" $args \
        > "$out/pass$pass-$mesh-$name.txt" 2>&1
    done
  done
done
