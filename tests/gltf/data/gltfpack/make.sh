#!/usr/bin/env bash
# Regenerates the gltfpack outputs the glTF tests read (tests/gltf/test_gltf_quantized.cpp)
# from the shared sample models. gltfpack 1.3 from the npm registry (its WebAssembly build):
#   npm install --prefix /tmp/gltfpack gltfpack@1.3.0 && GLTFPACK=/tmp/gltfpack/node_modules/.bin/gltfpack
# Default output: KHR_mesh_quantization (positions 14-bit, normals 8-bit, UVs 12-bit, the
# position dequantization in the mesh node's transform or, skinned, the inverse bind
# matrices). -c: the same with EXT_meshopt_compression; -cc: also with its filters.
# Only the small models are committed (a few KB each).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
shared=${SHADERGEN_SHARED_DIR:-$here/../../../../../shared}/models
gltfpack=${GLTFPACK:-gltfpack}
"$gltfpack" -v 2>&1 | grep -q "gltfpack 1.3" || { echo "needs gltfpack 1.3 (GLTFPACK=...)" >&2; exit 1; }
pack() {  # model-relative-path output-name flags...
  local in=$1 out=$2
  shift 2
  "$gltfpack" -i "$shared/$in" -o "$here/$out" "$@" > /dev/null
}
for m in SimpleSkin/SimpleSkin.gltf SimpleMorph/SimpleMorph.gltf MorphPrimitivesTest/MorphPrimitivesTest.gltf; do
  n=$(basename "${m%.*}")
  pack "$m" "$n.glb"
  pack "$m" "$n.meshopt.glb" -c
done
pack SimpleSkin/SimpleSkin.gltf SimpleSkin.meshopt-cc.glb -cc
# -kv keeps the tangents and the normal and tangent deltas (no material uses them here).
pack AnimatedMorphSphere/AnimatedMorphSphere.gltf AnimatedMorphSphere.meshopt-cc-kv.glb -cc -kv
