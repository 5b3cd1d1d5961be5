#!/usr/bin/env bash
# Session 23: does a part's time depend on the parts timed before it in one calibrate run?
set -u
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
mkdir -p /tmp/b && tar -xzf .bundle/sg.tar.gz -C /tmp/b
here=/tmp/b/sg; source $here/gpu_env.sh > $OUT/gpu.txt 2>&1
std=(-f $here/examples/gltf/lit.frag -r $here/rules/standard.yaml --templates $here/templates)
t=(--no-validation-layers --draws 32 --min-frame-vertices 64000 --frames 7 --rounds 2 --refits 0 --no-check --no-probes --device NVIDIA)
m=.bundle/unseen/BrainStem.glb
late=(); early=(--rig "$m#33/0")
for i in $(seq 0 32); do late+=(--rig "$m#$i/0"); early+=(--rig "$m#$i/0"); done
late+=(--rig "$m#33/0")
$sg calibrate "${t[@]}" "${late[@]}" "${std[@]}" -o /tmp/p.yaml > $OUT/late.log 2>&1; echo "late $?"
$sg calibrate "${t[@]}" "${early[@]}" "${std[@]}" -o /tmp/p.yaml > $OUT/early.log 2>&1; echo "early $?"
$sg calibrate "${t[@]}" --rig "$m#*" "${std[@]}" -o /tmp/p.yaml > $OUT/all.log 2>&1; echo "all $?"
