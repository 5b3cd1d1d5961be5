#!/usr/bin/env bash
# The workload `explain` measures for each held-out or training rig whose plans read the
# palette from the uniform block at a per-vertex index, on the cached head and at Dawn scale:
# joints per warp (per influence slot) and palette entries per warp (over all slots).
#   palette.sh <shadergen> <corpus dir of seed 1> <corpus dir of seed 2>   (calibrate --write-corpus)
set -euo pipefail
SG=$1 C1=$2 C2=$3
cd "$(dirname "$0")/../../.."
for r in "$C1"/corpus-{1298508491,4282876139,1666063943,1013994432}.rig.yaml \
         "$C2"/corpus-{111352301,2360782358,4070471979,794921487}.rig.yaml \
         tests/validate/data/limb8_palette300.rig.yaml examples/dawn/face.rig.yaml; do
  f=${r%.rig.yaml}.frag; [ -f "$f" ] || f=examples/dawn/face.frag
  case $r in */limb*) f=tests/validate/data/world.frag ;; esac
  for m in head dawn; do
    w=$("$SG" explain --rig "$r" -f "$f" -r examples/dawn/rules.yaml --device-profile devices/nvidia-h200-raster.yaml --mesh $m |
        awk '/workload:/ && !n { print; n = 1 }' | sed 's/.*vertices per draw, //; s/ distinct joints per warp (/ /; s/ over all its influences).*//')
    echo "$(basename "$r" .rig.yaml) $m $w"
  done
done
