#!/usr/bin/env bash
# Packs `shadergen bench` for a machine without a package registry (docs/performance.md):
# the stripped shadergen, the shared libraries it needs beyond glibc/libstdc++ and the
# Vulkan loader (the target brings those; its GPU driver brings the ICD), the rules,
# templates, device profiles and the Dawn example, bench/gpu_run.sh, gpu_calibrate.sh and
# gpu_layouts.sh (and gpu_env.sh, which they source).
# Usage: bash bench/gpu_bundle.sh [BUILD_DIR=build] [OUT=build/shadergen-gpu.tar.gz]; an OUT ending in .tar.xz is
# xz-compressed: 25 MB where gzip gives 40 (Embree's library is most of it), for a carry limit the checkout shares.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
out=${2:-$build/shadergen-gpu.tar.gz}
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage/sg/bin" "$stage/sg/lib" "$stage/sg/examples"
strip -o "$stage/sg/bin/shadergen" "$build/generator/cli/shadergen"
# Libraries the target may lack; the C/C++ runtime and the Vulkan loader are the target's.
ldd "$build/generator/cli/shadergen" | awk '$3 ~ /^\// {print $3}' | while read -r lib; do
  case "$(basename "$lib")" in
    libc.so.*|libm.so.*|libgcc_s.so.*|libstdc++.so.*|ld-linux*|libvulkan.so.*|libpthread.so.*|libdl.so.*|librt.so.*) ;;
    *) cp -L "$lib" "$stage/sg/lib/" ;;
  esac
done
cp -r "$root/rules" "$root/templates" "$root/devices" "$stage/sg/"
cp -r "$root/examples/dawn" "$stage/sg/examples/"
# Rigs and requests the calibration never saw, for the held-out check (gpu_collect.sh).
mkdir -p "$stage/sg/examples/heldout"
cp "$root"/tests/validate/data/*.rig.yaml "$root"/tests/validate/data/*.frag "$root"/examples/threejs/*.frag \
  "$stage/sg/examples/heldout/"
cp "$root/examples/threejs/mesh.rig.yaml" "$stage/sg/examples/heldout/threejs-mesh.rig.yaml"
# Real models (../shared, when beside the checkout) and the requests the tests make of them.
mkdir -p "$stage/sg/examples/models" "$stage/sg/examples/gltf"
cp "$root"/tests/gltf/data/*.frag "$stage/sg/examples/gltf/"
for m in CesiumMan/CesiumMan.glb RobotExpressive/RobotExpressive.glb Fox/Fox.glb RiggedFigure/RiggedFigure.glb; do
  [ -f "$root/../shared/models/$m" ] && cp "$root/../shared/models/$m" "$stage/sg/examples/models/"
done
# Models no profile was fitted or checked on before session 12 (the "unseen" groups), one as gltfpack writes it.
for m in LeePerrySmith/LeePerrySmith.glb MorphStressTest/MorphStressTest.gltf; do
  [ -f "$root/../shared/models/$m" ] && cp "$root/../shared/models/$m" "$stage/sg/examples/models/"
done
cp "$root/tests/gltf/data/gltfpack/AnimatedMorphSphere.meshopt-cc-kv.glb" "$stage/sg/examples/models/"
cp "$root/bench/gpu_env.sh" "$root/bench/gpu_run.sh" "$root/bench/gpu_calibrate.sh" "$root/bench/gpu_layouts.sh" \
  "$root/bench/gpu_collect.sh" "$root/bench/gpu_verify.sh" "$root/bench/gpu_pin.sh" "$stage/sg/"
case "$out" in
  *.xz) tar -C "$stage" -cf - sg | xz -T0 -9 > "$out" ;;
  *) tar -C "$stage" -czf "$out" sg ;;
esac
echo "$out: $(du -h "$out" | cut -f1)"
