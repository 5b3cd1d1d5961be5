#!/usr/bin/env bash
# Session 33 (offline, seconds): the shipped H200 raster profile's held-out check with every plan listed
# (calibrate --evaluate --per-plan) on the H200's held-out logs (sessions 23 and 18-19) and on the H100's logs of
# the profile's own plans (sessions 29-32); summary.txt has each set's summary line.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd); root=$(cd "$here/../../.." && pwd); sg=${SG:-$root/build/generator/cli/shadergen}
profile=$root/devices/nvidia-h200-raster.yaml
d=$root/bench/data
# The H200's logs predate the table-load terms: table-reads27/augment.py adds them (as refit.sh of h200-plans32 does).
aug=$(mktemp -d); trap 'rm -rf "$aug"' EXIT
h23= h18=
for g in world body-depth pbr models models-fox unseen unseen-formats unseen-models corpus-heldout-seed3 corpus-heldout-seed4 corpus-heldout-seed5; do
  python3 $d/table-reads27/augment.py $d/h200-fresh23/$g.log $aug/h23-$g.log > /dev/null 2>&1; h23+=" --check-log $aug/h23-$g.log"
done
for g in draw-counts18/world draw-counts18/body-depth draw-counts18/pbr draw-counts18/models draw-counts18/models-fox draw-counts18/corpus-heldout unseen19/unseen unseen19/unseen-formats unseen19/unseen-models; do
  python3 $d/table-reads27/augment.py $d/h200-$g.log $aug/h18-${g//\//-}.log > /dev/null 2>&1; h18+=" --check-log $aug/h18-${g//\//-}.log"
done
h100=$(ls $d/h200-plans{29,30,31,32}/s*/*.log | sed 's/^/--check-log /')
$sg calibrate --evaluate $profile $h23 --per-plan > $here/per-plan-h200-23.txt
$sg calibrate --evaluate $profile $h18 --per-plan > $here/per-plan-h200-18.txt
$sg calibrate --evaluate $profile $h100 --per-plan > $here/per-plan-h100-own-29-32.txt
for f in per-plan-h200-23 per-plan-h200-18 per-plan-h100-own-29-32; do
  echo "$f: $(grep -E '^held-out check over' $here/$f.txt | cut -d';' -f1)"
done > $here/summary.txt
cat $here/summary.txt
