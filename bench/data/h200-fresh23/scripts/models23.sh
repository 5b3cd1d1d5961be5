#!/usr/bin/env bash
# Session 23: public models no run had timed (not committed: licences unknown), each on its own meshes,
# every primitive's plan and alternatives validated then timed, as gpu_collect.sh's models group.
set -u
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
mkdir -p /tmp/b /tmp/c /tmp/o && tar -xzf .bundle/sg.tar.gz -C /tmp/b
here=/tmp/b/sg; source $here/gpu_env.sh > $OUT/gpu.txt 2>&1
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv >> $OUT/gpu.txt 2>&1
t=(--no-validation-layers --draws 32 --min-frame-vertices 64000 --frames 7 --rounds 2 --refits 0 --no-check --device NVIDIA)
for m in $SG_MODELS; do
  t0=$SECONDS
  timeout -s INT -k 30 ${SG_LIMIT:-120} "$sg" calibrate "${t[@]}" --no-probes --rig ".bundle/unseen/$m.glb#*" -f "$here/examples/gltf/lit.frag" \
    -r "$here/rules/standard.yaml" --templates "$here/templates" -o /tmp/c/$m.yaml > /tmp/o/$m.log 2>&1
  echo "== $m: exit $?, $((SECONDS - t0)) s" | tee -a $OUT/collect.txt
  tar -czf $OUT/logs.tar.gz -C /tmp/o .
done
