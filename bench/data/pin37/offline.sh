#!/usr/bin/env bash
# The measured choice offline (docs/performance.md, "A measured choice"): from the held-out logs of
# sessions 35 and 36 (NVIDIA H100 80GB HBM3, driver 580.159.04), the K plans each pair's profile
# (devices/nvidia-h200-raster.yaml) predicts cheapest among the plans the log holds, the fastest of them
# by one run's timing, judged by the same run and by the other run of the same rigs (seeds 57-59, timed
# in both sessions on different leases). Writes offline.txt. About 20 s.
set -euo pipefail
cd "$(dirname "$0")/../../.."
sg=${SG:-build/generator/cli/shadergen}
d=bench/data
t=$(mktemp -d); trap 'rm -rf "$t"' EXIT
{
  for s in 35 36; do
    echo "## session $s's 132 pairs (seeds $([ $s = 35 ] && echo 57-67 || echo 68-78)), picked and judged by the same run"
    python3 $d/pin37/offline.py $d/h100-plans$s/per-plan.txt $d/h100-plans$s/per-plan.txt
    echo
  done
  for s in 57 58 59; do
    for run in 35 36; do
      "$sg" calibrate --evaluate devices/nvidia-h200-raster.yaml --check-log $d/h100-plans$run/s$s/corpus-heldout.log --per-plan > $t/$run-$s.txt
    done
  done
  cat $t/35-5?.txt > $t/a.txt
  cat $t/36-5?.txt > $t/b.txt
  echo "## seeds 57-59 (36 pairs): picked by session 35's run, judged by session 36's"
  python3 $d/pin37/offline.py $t/a.txt $t/b.txt
  echo
  echo "## seeds 57-59: picked by session 36's run, judged by session 35's"
  python3 $d/pin37/offline.py $t/b.txt $t/a.txt
} > $d/pin37/offline.txt
cat $d/pin37/offline.txt
