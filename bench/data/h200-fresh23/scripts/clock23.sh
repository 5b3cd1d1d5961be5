#!/usr/bin/env bash
# Session 23: the SM clock while calibrate and bench time one small part (BrainStem#33/0).
set -u
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
mkdir -p /tmp/b && tar -xzf .bundle/sg.tar.gz -C /tmp/b
here=/tmp/b/sg; source $here/gpu_env.sh > $OUT/gpu.txt 2>&1
nvidia-smi --query-gpu=timestamp,clocks.sm,utilization.gpu,power.draw --format=csv -lms 20 > $OUT/clocks.txt 2>&1 &
smi=$!
m=".bundle/unseen/BrainStem.glb#33/0"; std=(-f $here/examples/gltf/lit.frag -r $here/rules/standard.yaml --templates $here/templates)
t=(--no-validation-layers --draws 32 --min-frame-vertices 64000 --frames 7 --device NVIDIA)
for i in 1 2; do
  echo "calibrate start $(date +%H:%M:%S.%N)" >> $OUT/marks.txt
  $sg calibrate "${t[@]}" --rounds 2 --refits 0 --no-check --no-probes --rig "$m" "${std[@]}" -o /tmp/p.yaml > $OUT/calibrate$i.log 2>&1
  echo "bench start $(date +%H:%M:%S.%N)" >> $OUT/marks.txt
  $sg bench --rig "$m" "${std[@]}" "${t[@]}" --rounds 2 --raster on --device-profile $here/devices/nvidia-h200-raster.yaml > $OUT/bench$i.txt 2>&1
done
echo "end $(date +%H:%M:%S.%N)" >> $OUT/marks.txt
kill $smi
