#!/usr/bin/env bash
# Session 25, device call 1 (bundle of session 24 or later in .bundle/sg.tar.gz, public models in .bundle/unseen/):
#   order/      h200-fresh23/scripts/order-next.sh: BrainStem and RobotExpressive timed whole (mapped, staged,
#               mapped without the shader cache) and one process per part (mapped)
#   s2/         gpu_collect.sh's world, pbr, body-depth, models, models-fox groups with the default (staged,
#               device-local) inputs: the same programs as session 23's mapped logs
#   public/     models23.sh's public models, staged
# Every log comes back in logs.tar.gz (a call returns at most 8 files), refreshed after each step.
set -u
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
mkdir -p /tmp/b /tmp/c /tmp/o/order /tmp/o/s2 /tmp/o/public && tar -xzf .bundle/sg.tar.gz -C /tmp/b
here=/tmp/b/sg
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv > $OUT/gpu.txt 2>&1
pack() { tar -czf $OUT/logs.tar.gz -C /tmp/o .; }
t0=$SECONDS
OUT=/tmp/o/order timeout -s INT -k 20 ${SG_ORDER_LIMIT:-300} bash bench/data/h200-fresh23/scripts/order-next.sh 2>&1 | tee -a $OUT/collect.txt
echo "== order: $((SECONDS - t0)) s" | tee -a $OUT/collect.txt; pack
SG_GROUPS="${SG_GROUPS:-body-depth models-fox models pbr world}" SG_PROFILE_DIR=/tmp/c bash $here/gpu_collect.sh NVIDIA /tmp/o/s2 2>&1 | tee -a $OUT/collect.txt; pack
source $here/gpu_env.sh > /dev/null 2>&1
t=(--no-validation-layers --draws 32 --min-frame-vertices 64000 --frames 7 --rounds 2 --refits 0 --no-check --device NVIDIA)
for m in ${SG_PUBLIC:-Base_Man Ely Saxon Soldier Flamingo Mannequin Xbot BrainStem}; do
  [ $SECONDS -lt ${SG_STOP:-520} ] || break; t0=$SECONDS
  timeout -s INT -k 20 60 "$sg" calibrate "${t[@]}" --no-probes --rig ".bundle/unseen/$m.glb#*" -f "$here/examples/gltf/lit.frag" \
    -r "$here/rules/standard.yaml" --templates "$here/templates" -o /tmp/c/$m.yaml > /tmp/o/public/$m.log 2>&1
  echo "== $m: exit $?, $((SECONDS - t0)) s" | tee -a $OUT/collect.txt; pack
done
