#!/usr/bin/env bash
# Runs on the GPU machine, from the unpacked bundle of bench/gpu_bundle.sh: prints the
# device, validates the Dawn face plan there, times every program (each validated on the
# device first; docs/performance.md), the buffer-fed plans too, and renders the Dawn face. Needs a Vulkan loader (libvulkan.so.1) and the GPU's ICD.
# Usage: bash gpu_run.sh [DEVICE=NVIDIA] [OUTDIR=.]   (SG_MESH, SG_DRAWS, SG_FRAMES: a quick local try)
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
device=${1:-NVIDIA}
outdir=${2:-.}
mesh=${SG_MESH:-dawn}
draws=${SG_DRAWS:-64}
frames=${SG_FRAMES:-21}
source "$here/gpu_env.sh"
"$sg" --version
echo "== validate (Dawn face, Dawn-scale mesh, cross-check)"
"$sg" validate "${dawn[@]}" --mesh "$mesh" --cross-check --poses 1 --device "$device" --no-validation-layers | grep -v '^  '
echo "== bench, rasterization on and off"
"$sg" bench "${dawn[@]}" --hand-port "$here/examples/dawn/listing-3-3.vert" --device "$device" --no-validation-layers \
  --mesh "$mesh" --draws "$draws" --frames "$frames" --rounds 1
echo "== bench again (run-to-run spread)"
"$sg" bench "${dawn[@]}" --hand-port "$here/examples/dawn/listing-3-3.vert" --device "$device" --no-validation-layers \
  --mesh "$mesh" --draws "$draws" --frames "$frames" --rounds 1 | tail -n +4
echo "== bench, buffer-fed plans (--max-attributes 8: every row validated on the device, then timed)"
"$sg" bench "${dawn[@]}" --max-attributes 8 --device "$device" --no-validation-layers \
  --mesh "$mesh" --draws "$draws" --frames "$frames" --rounds 1
echo "== render"
"$sg" render "${dawn[@]}" --mesh "$mesh" --size 480x480 --yaw 20 --pitch 5 --device "$device" --no-validation-layers \
  -o "$outdir/dawn-face-gpu.png"
