#!/usr/bin/env bash
# Session 25, device call 3, with a bundle of commit 744e58b (calibrate times each rig in a fresh
# process unless --one-process): what carries over inside one process, and the new default on the GPU.
# BrainStem's runs with mapped inputs as order-next.sh's; the held-out groups with the default
# (device-local) as their logs of calls 1-2. Each step inside SG_STOP seconds (a device budget):
#   fresh-BrainStem.log      the whole model, each part in a fresh process (the new default)
#   world.log                gpu_collect.sh's world group, each rig in a fresh process
#   rep-45.log, rep-33.log   --one-process: BrainStem#45/0 (#33/0) timed 6 times in one process
#   reversed.log             --one-process: BrainStem's parts in reverse order
#   s7.log                   the random held-out rigs of seed 7 (16), each in a fresh process
#   filler-K.log             --one-process: BrainStem#0/0 timed K times, then #45/0
set -u
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
mkdir -p /tmp/b /tmp/o4 && tar -xzf .bundle/sg.tar.gz -C /tmp/b
here=/tmp/b/sg; source $here/gpu_env.sh > $OUT/gpu.txt 2>&1
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv >> $OUT/gpu.txt 2>&1
std=(-r $here/rules/standard.yaml --templates $here/templates)
t=(--no-validation-layers --draws 32 --min-frame-vertices 64000 --frames 7 --rounds 2 --refits 0 --no-check --no-probes --device NVIDIA)
m=.bundle/unseen/BrainStem.glb
cal() {  # NAME LIMIT ARGS...: one calibrate run, unless SG_STOP seconds have passed
  local name=$1 limit=$2; shift 2
  [ $SECONDS -lt ${SG_STOP:-300} ] || { echo "== $name: skipped (time)"; return; }
  timeout -s INT -k 10 $limit $sg calibrate "${t[@]}" "$@" -o /tmp/p.yaml > /tmp/o4/$name.log 2>&1
  echo "== $name: exit $?, $SECONDS s"; tar -czf $OUT/logs.tar.gz -C /tmp/o4 .
}
lit=(--input-memory mapped -f $here/examples/gltf/lit.frag "${std[@]}")
cal fresh-BrainStem ${SG_FRESH_LIMIT:-120} --rig "$m#*" "${lit[@]}"
data=$here/examples/heldout
cal world 130 --meshes dawn,head --rig $data/limb16.rig.yaml --rig $data/limb8_palette300.rig.yaml --rig $data/face52.rig.yaml \
  --rig $data/octahedral.rig.yaml --rig $data/qtangent.rig.yaml -f $data/world.frag "${std[@]}"
for p in 45 33; do r=(); for i in 1 2 3 4 5 6; do r+=(--rig "$m#$p/0"); done; cal rep-$p 60 --one-process "${r[@]}" "${lit[@]}"; done
r=(); for p in $(seq 58 -1 0); do r+=(--rig "$m#$p/0"); done; cal reversed 60 --one-process "${r[@]}" "${lit[@]}"
cal s7 $(( ${SG_STOP:-300} + 20 - SECONDS )) --meshes dawn,head --corpus 16 --seed 7 -f $here/examples/dawn/face.frag \
  -r $here/examples/dawn/rules.yaml --templates $here/templates
for k in 0 1 2 3; do r=(); for i in $(seq 1 $k); do r+=(--rig "$m#0/0"); done; cal filler-$k 30 --one-process "${r[@]}" --rig "$m#45/0" "${lit[@]}"; done
