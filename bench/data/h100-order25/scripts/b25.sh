#!/usr/bin/env bash
# Session 25, device call 2: gpu_collect.sh's training group and the unseen groups with the default
# (staged, device-local) inputs, beside session 23's mapped logs of the same programs, and a random
# held-out set no run has timed (seed 7, 16 rigs). Logs in logs.tar.gz (s2/, s7/).
set -u
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
mkdir -p /tmp/b /tmp/c /tmp/o/s2 /tmp/o/s7 && tar -xzf .bundle/sg.tar.gz -C /tmp/b
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv > $OUT/gpu.txt 2>&1
for step in ${SG_STEPS:-2:train,unseen,unseen-formats,unseen-models 7:corpus-heldout}; do
  seed=${step%%:*} groups=${step#*:}
  echo "== step seed $seed: ${groups//,/ }" | tee -a $OUT/collect.txt
  SG_HELDOUT_SEED=$seed SG_HELDOUT_CORPUS=${SG_HELDOUT_CORPUS:-16} SG_GROUPS="${groups//,/ }" SG_PROFILE_DIR=/tmp/c \
    bash /tmp/b/sg/gpu_collect.sh NVIDIA /tmp/o/s$seed 2>&1 | tee -a $OUT/collect.txt
  tar -czf $OUT/logs.tar.gz -C /tmp/o .
done
