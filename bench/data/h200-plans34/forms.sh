#!/usr/bin/env bash
# Session 34 (offline, a minute a form): the raster form fitted on the H200 session-23 training log (table-reads27/augment.py),
# with other calibrate fit flags, checked on the H200 held-out logs of sessions 23 and 18-19.
#   Usage: bash forms.sh NAME [calibrate fit flags...]   (forms.txt: the runs below)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd); root=$(cd "$here/../../.." && pwd); d=$root/bench/data; sg=$root/build/generator/cli/shadergen
aug=${SG_FORMS_DIR:-/tmp/sg-forms34}/aug; mkdir -p $aug
if [ ! -f $aug/done ]; then
python3 $d/table-reads27/augment.py $d/h200-fresh23/train.log $aug/train23.log >/dev/null 2>&1
for g in world body-depth pbr models models-fox unseen unseen-formats unseen-models corpus-heldout-seed3 corpus-heldout-seed4 corpus-heldout-seed5; do
  python3 $d/table-reads27/augment.py $d/h200-fresh23/$g.log $aug/h23-$g.log > /dev/null 2>&1; done
for g in draw-counts18/world draw-counts18/body-depth draw-counts18/pbr draw-counts18/models draw-counts18/models-fox draw-counts18/corpus-heldout unseen19/unseen unseen19/unseen-formats unseen19/unseen-models; do
  python3 $d/table-reads27/augment.py $d/h200-$g.log $aug/h18-${g//\//-}.log > /dev/null 2>&1; done
touch $aug/done
fi
name=$1; shift
$sg calibrate --from-log $aug/train23.log --form raster --near-best-weight 0 "$@" -o ${SG_FORMS_DIR:-/tmp/sg-forms34}/$name.yaml > ${SG_FORMS_DIR:-/tmp/sg-forms34}/$name.fit.txt
mkdir -p ${SG_FORMS_DIR:-/tmp/sg-forms34}/p; cp ${SG_FORMS_DIR:-/tmp/sg-forms34}/$name.yaml ${SG_FORMS_DIR:-/tmp/sg-forms34}/p/p.yaml
h23=$(ls $aug/h23-*.log | sed 's/^/--check-log /'); h18=$(ls $aug/h18-*.log | sed 's/^/--check-log /')
$sg calibrate --evaluate ${SG_FORMS_DIR:-/tmp/sg-forms34}/p/p.yaml $h23 > ${SG_FORMS_DIR:-/tmp/sg-forms34}/$name.h23.txt
$sg calibrate --evaluate ${SG_FORMS_DIR:-/tmp/sg-forms34}/p/p.yaml $h18 > ${SG_FORMS_DIR:-/tmp/sg-forms34}/$name.h18.txt
for s in h23 h18; do echo "$name $s: $(grep -E '^held-out check over' ${SG_FORMS_DIR:-/tmp/sg-forms34}/$name.$s.txt | cut -d';' -f1)"; done
