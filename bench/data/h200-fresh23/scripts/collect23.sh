#!/usr/bin/env bash
# Session 23: several gpu_collect.sh steps in one call. SG_STEPS="SEED:group,group SEED:group ...",
# each step's logs in s<SEED>/ of logs.tar.gz (a held-out seed per step).
set -u
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
mkdir -p /tmp/b /tmp/c /tmp/o && tar -xzf .bundle/sg.tar.gz -C /tmp/b
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv > $OUT/gpu.txt 2>&1
for step in $SG_STEPS; do
  seed=${step%%:*} groups=${step#*:}
  mkdir -p /tmp/o/s$seed
  echo "== step seed $seed: ${groups//,/ }" | tee -a $OUT/collect.txt
  SG_HELDOUT_SEED=$seed SG_GROUPS="${groups//,/ }" SG_PROFILE_DIR=/tmp/c bash /tmp/b/sg/gpu_collect.sh NVIDIA /tmp/o/s$seed 2>&1 | tee -a $OUT/collect.txt
  tar -czf $OUT/logs.tar.gz -C /tmp/o .
done
