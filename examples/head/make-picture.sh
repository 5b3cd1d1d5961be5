#!/usr/bin/env bash
# Regenerates docs/images/head.png, the README picture: a scanned human head (three.js's
# LeePerrySmith, CC BY 3.0, examples/head/README.md) with its occlusion baked by
# `shadergen bake occlusion`, tangent frames from `shadergen bake tangents`, drawn with
# Dawn's face shader (listing 3-4, examples/dawn/face.frag) fed by the generated vertex
# program, on lavapipe.
#
#   bash examples/head/make-picture.sh [shadergen] [output.png]
#
# shadergen defaults to build/generator/cli/shadergen, the output to docs/images/head.png.
# The model is read from ../shared/models/LeePerrySmith/ (or $SHADERGEN_SHARED_DIR/models/...)
# and checked against its SHA-256 first. Every step is deterministic: the same shadergen and
# device give the same PNG bytes.
set -euo pipefail
here="$(cd "$(dirname "$0")/../.." && pwd)"
sg="${1:-$here/build/generator/cli/shadergen}"
out="${2:-$here/docs/images/head.png}"
model="${SHADERGEN_SHARED_DIR:-$here/../shared}/models/LeePerrySmith/LeePerrySmith.glb"
# three.js r186's examples/models/gltf/LeePerrySmith/LeePerrySmith.glb (a copy re-encoded
# as text circulates: it fails here).
sha=402b8a8ac9f03232e6d64b5962929703a069daf99d3c49ac8eb0e48bedc9c576
echo "$sha  $model" | sha256sum --check --quiet || { echo "$model: not the expected model (SHA-256 $sha)" >&2; exit 1; }

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp/shadergen-xdg}"
mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"

# Occlusion: Dawn's definition (blocked share of the hemisphere, uniform rays), 1024 rays a vertex.
"$sg" bake occlusion "$model" -o "$work/occluded.glb" --rays 1024 -q
# The scan has normals and UVs but no TANGENT, which listing 3-4's tangent frame needs.
"$sg" bake tangents "$work/occluded.glb" -o "$work/head.glb" -q
# SkinSilhouetteVec.x multiplies the diffuse light, so it gets the open share (1 - occlusion);
# the scan has no dapple map (w: 1 - N.V) and one UV set (SkinUVST.zw unused by the shader).
cd "$here"
"$sg" render --rig "$work/head.glb#0/0" -f examples/dawn/face.frag -r examples/dawn/rules.yaml \
  --map SkinSilhouetteVec=object.visibility,view.one_minus_ndotv_sq,view.one_minus_ndotv,view.one_minus_ndotv \
  --map SkinUVST=vertex.texcoord0,vertex.texcoord0 \
  --size 512x512 --yaw 30 --pitch 5 --zoom 1.3 -o "$out"
