#!/usr/bin/env bash
# Session 28, offline (no device; about a minute): the raster form with input locations and storage-buffer
# loads priced outside the pipes as well as in them (the default since session 28) against the form before
# (`--outside-pipes none`), each fitted on four training logs of two GPUs and checked on held-out logs its fit
# never saw; and the profile shipped before this session on this collection's own plans.
#   Usage: bash evaluate.sh [shadergen]   (from anywhere; writes fit-*.yaml, *.txt and summary.txt here)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$here/../../..
sg=${1:-$root/build/generator/cli/shadergen}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
aug=$root/bench/data/table-reads27/augment.py
# Logs written before session 27 count table reads (the palette in a buffer) in the buffer loads:
# augment.py counts them apart (table-reads27/README.md). This collection's logs have the columns.
h23=(world body-depth pbr models models-fox unseen unseen-formats unseen-models corpus-heldout-seed3 corpus-heldout-seed4 corpus-heldout-seed5)
h18=(draw-counts18/world draw-counts18/body-depth draw-counts18/pbr draw-counts18/models draw-counts18/models-fox draw-counts18/corpus-heldout
     unseen19/unseen unseen19/unseen-formats unseen19/unseen-models)
h27=(s2/world s2/body-depth s2/pbr s2/models s2/models-fox s2/unseen s2/unseen-formats s2/unseen-models s3/corpus-heldout s4/corpus-heldout s5/corpus-heldout s7/corpus-heldout)
mkdir -p "$tmp/h23" "$tmp/h18" "$tmp/h27"
{
  python3 "$aug" "$root/bench/data/h200-fresh23/train.log" "$tmp/h23/train.log"
  for g in "${h23[@]}"; do python3 "$aug" "$root/bench/data/h200-fresh23/$g.log" "$tmp/h23/$g.log"; done
  python3 "$aug" "$root/bench/data/h200-draw-counts18/train.log" "$tmp/h18/train.log"
  for g in "${h18[@]}"; do python3 "$aug" "$root/bench/data/h200-$g.log" "$tmp/h18/${g//\//-}.log"; done
  python3 "$aug" "$root/bench/data/h100-fresh26/call2/s2/train.log" "$tmp/h27/train.log"
  for g in "${h27[@]}"; do python3 "$aug" "$root/bench/data/h100-plans27/$g.log" "$tmp/h27/${g//\//-}.log"; done
} 2> "$here/augment.txt"
checks() {  # SET: --check-log arguments
  case $1 in
    h23) for g in "${h23[@]}"; do echo "--check-log $tmp/h23/$g.log"; done ;;
    h18) for g in "${h18[@]}"; do echo "--check-log $tmp/h18/${g//\//-}.log"; done ;;
    h27) for g in "${h27[@]}"; do echo "--check-log $tmp/h27/${g//\//-}.log"; done ;;
    h28) for g in s2/world s2/body-depth s2/pbr s2/models s2/models-fox s2/unseen s2/unseen-formats s2/unseen-models \
                  s3/corpus-heldout s4/corpus-heldout s5/corpus-heldout; do echo "--check-log $here/$g.log"; done ;;
  esac
}
train() { case $1 in h200-23) echo "$tmp/h23/train.log" ;; h200-18) echo "$tmp/h18/train.log" ;;
                     h100-26) echo "$tmp/h27/train.log" ;; h100-28) echo "$here/s2/train.log" ;; esac; }
headline() { grep -E "^held-out check over" "$1" | sed -E 's/^held-out check over ([0-9]+) .*median Spearman ([0-9.]+), worst chosen \/ fastest ([0-9.]+).*, RMS relative error median ([0-9.]+) %.*/\1 pairs: Spearman \2, worst \3, RMS \4 %/'; }
over() { awk -F'|' '/^held-out check/{h=1} h && /^\| / && $6 ~ /[0-9]/ {split($6,a," "); if (a[1]+0 > 1.05) {n++; s=s sprintf("%s%s %s; ", $2, $3, a[1])}} END{printf "%d over 5 %%: %s\n", n+0, s}' "$1" | tr -s ' '; }
: > "$here/summary.txt"
for form in default none; do
  opt=(); [ "$form" = none ] && opt=(--outside-pipes none)
  for t in h200-23 h200-18 h100-26 h100-28; do
    "$sg" calibrate --from-log "$(train $t)" --form raster --near-best-weight 0 "${opt[@]}" -o "$here/fit-$t-$form.yaml" > /dev/null
    # Training and held-out logs of one collection are disjoint groups (gpu_collect.sh).
    case $t in h200-*) sets="h23 h18" ;; *) sets="h27 h28" ;; esac
    # The H200 fits on the H100's logs too: a second card of the same die.
    [ "$t" = h200-23 ] && sets="$sets h27 h28"
    for c in $sets; do
      cp "$here/fit-$t-$form.yaml" "$tmp/p.yaml"  # under another name than the logs' own plans: the tie rule
      "$sg" calibrate --evaluate "$tmp/p.yaml" $(checks $c) > "$here/check-$t-$form-on-$c.txt"
      echo "$form, fitted on $t, checked on $c: $(headline "$here/check-$t-$form-on-$c.txt"); $(over "$here/check-$t-$form-on-$c.txt")" >> "$here/summary.txt"
    done
  done
done
# The profile shipped before session 28 on this collection, which timed its own plans (plan under nvidia-h200-raster).
mkdir -p "$tmp/before"
cp "$here/nvidia-h200-raster-before.yaml" "$tmp/before/nvidia-h200-raster.yaml"
"$sg" calibrate --evaluate "$tmp/before/nvidia-h200-raster.yaml" $(checks h28) > "$here/own-plans-before.txt"
echo "shipped before, its own plans timed, on h28: $(headline "$here/own-plans-before.txt"); $(over "$here/own-plans-before.txt")" >> "$here/summary.txt"
cat "$here/summary.txt"
