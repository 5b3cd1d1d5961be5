#!/usr/bin/env bash
# Session 31, offline (seconds): the shipped H200 raster profile on the H100's own-plan logs of the random
# corpus rigs (sessions 29 and 30, seeds 3, 4, 5, 7, 43, 44, 45), each pair's level and the error left
# without it (`calibrate --evaluate`), and what the level follows (levels.py). Writes evaluate.txt,
# fragment-sizes.txt, rig-deformers.txt and summary.txt here.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd); root=$here/../../..
sg=${1:-$root/build/generator/cli/shadergen}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
logs=("$root"/bench/data/h200-plans29/s[3457]/corpus-heldout.log "$root"/bench/data/h200-plans30/s4[345]/corpus-heldout.log)
checks=(); for f in "${logs[@]}"; do checks+=(--check-log "$f"); done
"$sg" calibrate --evaluate "$root/devices/nvidia-h200-raster.yaml" "${checks[@]}" > "$here/evaluate.txt"
# The requests' fragment shaders, as the corpus writes them (16 rigs a seed covers the 6 timed).
for s in 3 4 5 7 43 44 45; do
  mkdir -p "$tmp/s$s"; "$sg" calibrate --corpus 16 --seed $s --write-corpus "$tmp/s$s" -r "$root/examples/dawn/rules.yaml" > /dev/null
done
for f in "$tmp"/s*/*.frag; do
  glslangValidator -V -S frag "$f" -o "$tmp/f.spv" > /dev/null && spirv-opt -O "$tmp/f.spv" -o "$tmp/o.spv"
  echo "$(basename "$f" .frag) $(spirv-dis "$tmp/o.spv" | grep -cE '^ *(%[^ ]+ = )?Op(F|I|S|U|Ext|Dot|Vector|Matrix|Image|Select|Load|Store|Composite)')"
done | sort -u > "$here/fragment-sizes.txt"
# The rigs' deformers (bones, influences, morph targets), as their files state them.
for f in "$tmp"/s*/*.rig.yaml; do
  printf '%s' "$(basename "$f" .rig.yaml)"
  for k in bones influences morph_targets; do printf ' %s' "$( (grep -oE "\b$k: [0-9]+" "$f" || echo "x: 0") | head -1 | grep -oE '[0-9]+$')"; done
  echo
done | sort -u > "$here/rig-deformers.txt"
{ grep "^held-out check over" "$here/evaluate.txt" | cut -d';' -f1; python3 "$here/levels.py" "$here/evaluate.txt" "$here/fragment-sizes.txt" "$here/rig-deformers.txt" "${logs[@]}"; } > "$here/summary.txt"
cat "$here/summary.txt"
