#!/usr/bin/env bash
# Session 36, offline (no device; about 25 minutes on 2 cores): raster fits on H100 logs, checked on
# this collection's seeds 68-78 (66 corpus rigs no fit saw). Writes /tmp/fit36; fits/ keeps the results.
#   fit-h100-raster:    every earlier H100 log (sessions 26-35, 84 logs; logs before session 27
#                       through table-reads27/augment.py)
#   fit-h100-raster-sb: the same, buffer_bytes counting per-vertex streams only (stream_bytes.py)
#   fit-cb / fit-cc:    session 35's 11 logs alone, their rows with driver statistics; cc with the
#                       driver's Input Count (components read) in place of attribute_bytes (components.py)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd); root=$here/../../..; sg=${1:-$root/build/generator/cli/shadergen}
t=/tmp/fit36; mkdir -p $t/aug $t/sb $t/sbc $t/cb/train $t/cb/check $t/cc/train $t/cc/check
cd "$root/bench/data"
for f in $(grep -l "H100" $(find h100-fresh26 h100-plans27 h200-plans2* h200-plans3* h200-portable30 h100-plans35 -name '*.log') | sort); do
  o=$t/aug/$(echo "$f" | tr '/' '_')
  if grep -q buffer_table_loads "$f"; then cp "$f" "$o"; else python3 table-reads27/augment.py "$f" "$o" 2>/dev/null; fi
  python3 "$here/stream_bytes.py" "$o" "$t/sb/$(basename "$o")"
done
seeds="68 69 70 71 72 73 74 75 76 77 78"
for s in $seeds; do python3 "$here/stream_bytes.py" "$here/s$s/corpus-heldout.log" "$t/sbc/s$s.log"; done
for s in 57 58 59 60 61 62 63 64 65 66 67; do
  python3 "$here/components.py" base "$t/aug/h100-plans35_s${s}_corpus-heldout.log" "$t/cb/train/s$s.log"
  python3 "$here/components.py" components "$t/aug/h100-plans35_s${s}_corpus-heldout.log" "$t/cc/train/s$s.log"
done
for s in $seeds; do
  python3 "$here/components.py" base "$here/s$s/corpus-heldout.log" "$t/cb/check/s$s.log"
  python3 "$here/components.py" components "$here/s$s/corpus-heldout.log" "$t/cc/check/s$s.log"
done
args() { for f in $2; do echo "$1 $f"; done; }
fit() {  # NAME TRAIN-GLOB CHECK-GLOB
  "$sg" calibrate $(args --from-log "$2") $(args --check-log "$3") --form raster --near-best-weight 0 -o "$t/$1.yaml" > "$t/$1.txt"
  { grep -E "^(held-out check over|leave-one-rig-out over|fit on)" "$t/$1.txt"
    awk '/^held-out check:/{h=1} h && /^\| /' "$t/$1.txt" | awk -F'|' '$6+0 > 1.05'; } > "$here/fits/$1.txt"
  cp "$t/$1.yaml" "$here/fits/"
}
fit fit-h100-raster "$t/aug/*.log" "$(ls $here/s{68,69,7?}/corpus-heldout.log)"
fit fit-h100-raster-sb "$t/sb/*.log" "$t/sbc/*.log"
fit fit-cb "$t/cb/train/*.log" "$t/cb/check/*.log"
fit fit-cc "$t/cc/train/*.log" "$t/cc/check/*.log"
