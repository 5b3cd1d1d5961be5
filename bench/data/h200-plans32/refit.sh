#!/usr/bin/env bash
# refit.sh TAG [calibrate fit flags...] (session 31-32, offline): fits the raster form on the H200 session 23 training log (with the footprints, table-reads27/augment.py) and checks it on the H200 held-out logs of sessions 23 and 18-19 and the H100 own-plan logs of sessions 28-30 (outputs under $SG_REFIT_DIR, default /tmp/sg-refit32). base: the flags as shipped; cc32: --constant-cache.
set -euo pipefail
root=$(cd "$(dirname "$0")/../../.." && pwd); sg=$root/build/generator/cli/shadergen
tag=$1; shift
A=${SG_REFIT_DIR:-/tmp/sg-refit32}/aug
if [ ! -d $A ]; then
  mkdir -p $A/h23 $A/h18
  aug=$root/bench/data/table-reads27/augment.py
  python3 $aug $root/bench/data/h200-fresh23/train.log $A/h23/train.log
  for g in world body-depth pbr models models-fox unseen unseen-formats unseen-models corpus-heldout-seed3 corpus-heldout-seed4 corpus-heldout-seed5; do python3 $aug $root/bench/data/h200-fresh23/$g.log $A/h23/$g.log; done
  for g in draw-counts18/world draw-counts18/body-depth draw-counts18/pbr draw-counts18/models draw-counts18/models-fox draw-counts18/corpus-heldout unseen19/unseen unseen19/unseen-formats unseen19/unseen-models; do python3 $aug $root/bench/data/h200-$g.log $A/h18/${g//\//-}.log; done
fi 2>/dev/null
out=${SG_REFIT_DIR:-/tmp/sg-refit32}/$tag; mkdir -p $out
$sg calibrate --from-log $A/h23/train.log --form raster --near-best-weight 0 "$@" -o $out/p.yaml > $out/fit.txt
checks() { case $1 in
  h23) for f in $A/h23/*.log; do [ "$(basename $f)" = train.log ] || echo "--check-log $f"; done ;;
  h18) for f in $A/h18/*.log; do echo "--check-log $f"; done ;;
  h28) for f in $root/bench/data/h200-plans28/s*/*.log; do [ "$(basename $f)" = train.log ] || echo "--check-log $f"; done ;;
  h29) for f in $root/bench/data/h200-plans29/s*/*.log; do echo "--check-log $f"; done ;;
  h30) for f in $root/bench/data/h200-plans30/s*/*.log; do echo "--check-log $f"; done ;;
esac; }
over() { awk -F'|' '/^held-out check/{h=1} h && /^\| / && $6 ~ /[0-9]/ {split($6,a," "); if (a[1]+0 > 1.05) {n++; s=s sprintf("%s%s %s; ", $2, $3, a[1])}} END{printf "%d over: %s\n", n+0, s}' "$1" | tr -s ' '; }
for c in h23 h18 h28 h29 h30; do
  $sg calibrate --evaluate $out/p.yaml $(checks $c) > $out/check-$c.txt
  echo "$tag $c: $(grep -E '^held-out check over' $out/check-$c.txt | sed -E 's/.*over ([0-9]+) .*median Spearman ([0-9.]+), worst chosen \/ fastest ([0-9.]+).*, RMS relative error median ([0-9.]+) %.*/\1 pairs Sp \2 worst \3 RMS \4/') | $(over $out/check-$c.txt)"
done
