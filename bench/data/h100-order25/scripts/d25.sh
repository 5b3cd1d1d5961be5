#!/usr/bin/env bash
# Session 25, device call 3 (c25.sh's questions, fewer of them, and one process per rig for two held-out
# groups), BrainStem's with mapped inputs as order-next.sh's parts, the held-out rigs' with the default
# (device-local) as their one-process logs of call 1-2; every step inside SG_STOP seconds (a device budget):
#   rep-45.log, rep-33.log   BrainStem#45/0 (#33/0) timed 6 times in one process
#   filler-K.log             BrainStem#0/0 timed K times, then #45/0
#   reversed.log             BrainStem's parts in reverse order, one process
#   world-iso/R.log          gpu_collect.sh's world group, one calibrate process per rig (Dawn scale and head)
#   s7-iso/R.log             the random held-out rigs of seed 7 (16), one process per rig
set -u
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
mkdir -p /tmp/b /tmp/o4/world-iso /tmp/o4/s7-iso && tar -xzf .bundle/sg.tar.gz -C /tmp/b
here=/tmp/b/sg; source $here/gpu_env.sh > $OUT/gpu.txt 2>&1
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv >> $OUT/gpu.txt 2>&1
std=(-r $here/rules/standard.yaml --templates $here/templates)
t=(--no-validation-layers --draws 32 --min-frame-vertices 64000 --frames 7 --rounds 2 --refits 0 --no-check --no-probes --device NVIDIA)
m=.bundle/unseen/BrainStem.glb
cal() {  # NAME ARGS...: one calibrate process, unless SG_STOP seconds have passed
  local name=$1; shift
  [ $SECONDS -lt ${SG_STOP:-300} ] || { echo "== $name: skipped (time)"; return; }
  timeout -s INT -k 10 120 $sg calibrate "${t[@]}" "$@" -o /tmp/p.yaml > /tmp/o4/$name.log 2>&1
  echo "== $name: exit $?, $SECONDS s"; tar -czf $OUT/logs.tar.gz -C /tmp/o4 .
}
lit=(--input-memory mapped -f $here/examples/gltf/lit.frag "${std[@]}")
for p in 45 33; do r=(); for i in 1 2 3 4 5 6; do r+=(--rig "$m#$p/0"); done; cal rep-$p "${r[@]}" "${lit[@]}"; done
r=(); for p in $(seq 58 -1 0); do r+=(--rig "$m#$p/0"); done; cal reversed "${r[@]}" "${lit[@]}"
data=$here/examples/heldout
for r in limb16 limb8_palette300 face52 octahedral qtangent; do
  cal world-iso/$r --meshes dawn,head --rig $data/$r.rig.yaml -f $data/world.frag "${std[@]}"
done
$sg calibrate --corpus 16 --seed 7 --write-corpus /tmp/s7 -r $here/examples/dawn/rules.yaml > /tmp/s7.txt
while read -r rig frag; do
  cal s7-iso/$(basename $rig .rig.yaml) --meshes dawn,head --rig $rig -f $frag -r $here/examples/dawn/rules.yaml --templates $here/templates
done < /tmp/s7.txt
for k in 0 1 2 3; do r=(); for i in $(seq 1 $k); do r+=(--rig "$m#0/0"); done; cal filler-$k "${r[@]}" --rig "$m#45/0" "${lit[@]}"; done
