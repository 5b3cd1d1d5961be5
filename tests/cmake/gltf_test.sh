#!/usr/bin/env bash
# shadergen_add_vertex_shader(... RIG "MODEL.gltf#M/P" ...) (docs/cmake.md): a glTF primitive as
# the rig, by a path relative to the project. The build depends on the model file (not on a
# file named "MODEL.gltf#0/0", which Ninja would call missing), the shader is byte-identical
# to `shadergen generate` with that rig, a rebuild runs nothing, and touching the model or
# its buffer file (named by the depfile) regenerates it.
#
#   gltf_test.sh <shadergen> <source dir> <ninja>
set -uo pipefail
SG=$1 SRC=$2 NINJA=$3
T=$(mktemp -d "${TMPDIR:-/tmp}/sg-cmake-gltf-XXXXXX")
trap 'rm -rf "$T"' EXIT
fails=0
fail() { echo "FAIL: $*" >&2; fails=$((fails + 1)); }
ok() { echo "ok: $*"; }
P=$T/proj B=$T/build
mkdir -p "$P/models"
MODEL=${SHADERGEN_SHARED_DIR:-$SRC/../shared}/models/SimpleMorph  # the shared models sit next to the checkout
cp "$MODEL/SimpleMorph.gltf" "$MODEL"/*.bin "$P/models/" || fail "no $MODEL"
cp "$SRC/tests/gltf/data/minimal.frag" "$P/"
chmod u+w "$P"/models/*
cat >"$P/CMakeLists.txt" <<CMAKE
cmake_minimum_required(VERSION 3.22)
project(gltf CXX)
add_executable(shadergen::shadergen IMPORTED)
set_target_properties(shadergen::shadergen PROPERTIES IMPORTED_LOCATION "$SG")
include("$SRC/cmake/ShadergenFunctions.cmake")
file(WRITE "\${CMAKE_BINARY_DIR}/main.cpp" "int main() {}\n")
add_executable(app "\${CMAKE_BINARY_DIR}/main.cpp")
shadergen_add_vertex_shader(app RIG "models/SimpleMorph.gltf#0/0" FRAGMENT minimal.frag RULES "$SRC/rules/standard.yaml")
CMAKE
cmake -S "$P" -B "$B" -G Ninja -DCMAKE_MAKE_PROGRAM="$NINJA" >"$T/cfg.log" 2>&1 || { cat "$T/cfg.log"; fail "configure"; }
"$NINJA" -C "$B" >"$T/build.log" 2>&1 && ok "builds with RIG models/SimpleMorph.gltf#0/0" || { cat "$T/build.log"; fail "build"; }
G="$B/shadergen/app"
"$SG" generate --rig "$P/models/SimpleMorph.gltf#0/0" -f "$P/minimal.frag" -r "$SRC/rules/standard.yaml" \
  -o "$T/cli" --emit glsl,spv,reflection -q || fail "generate"
for ext in vert spv json; do
  cmp -s "$G/minimal.$ext" "$T/cli.$ext" || fail "minimal.$ext differs from generate"
done
ok "byte-identical to generate --rig MODEL.gltf#0/0"
"$NINJA" -C "$B" | grep -qx 'ninja: no work to do.' && ok "no-op rebuild" || fail "a rebuild ran something"
for f in SimpleMorph.gltf simpleMorphGeometry.bin; do
  sleep 1.1  # mtime granularity on some file systems
  touch "$P/models/$f"
  "$NINJA" -C "$B" | grep -q 'generating vertex shader minimal' && ok "touching $f regenerates" || fail "touching $f did not regenerate"
done
[ "$fails" -eq 0 ] || { echo "$fails failure(s)"; exit 1; }
