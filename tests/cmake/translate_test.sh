#!/usr/bin/env bash
# shadergen_add_vertex_shader(... HLSL MSL ...) (docs/cmake.md, docs/hlsl-msl.md) with the
# generator of this build as an imported executable: the .hlsl and .metal are outputs of the
# custom command (in its depfile), their paths reach the target, a no-op rebuild runs
# nothing, and a translation option without its language is a configure error.
#
#   translate_test.sh <shadergen> <source dir> <ninja>
set -uo pipefail
SG=$1 SRC=$2 NINJA=$3
T=$(mktemp -d "${TMPDIR:-/tmp}/sg-cmake-translate-XXXXXX")
trap 'rm -rf "$T"' EXIT
fails=0
fail() { echo "FAIL: $*" >&2; fails=$((fails + 1)); }
ok() { echo "ok: $*"; }

project() {  # project <dir> <extra shadergen_add_vertex_shader arguments>
  mkdir -p "$1"
  cat >"$1/CMakeLists.txt" <<CMAKE
cmake_minimum_required(VERSION 3.22)
project(translate CXX)
add_executable(shadergen::shadergen IMPORTED)
set_target_properties(shadergen::shadergen PROPERTIES IMPORTED_LOCATION "$SG")
include("$SRC/cmake/ShadergenFunctions.cmake")
file(WRITE "\${CMAKE_BINARY_DIR}/main.cpp"
     "#include <cstdio>\nint main() { std::puts(SHADERGEN_DEPTH_HLSL); std::puts(SHADERGEN_DEPTH_MSL); }\n")
add_executable(app "\${CMAKE_BINARY_DIR}/main.cpp")
shadergen_add_vertex_shader(app RIG "$SRC/examples/dawn/face.rig.yaml" FRAGMENT "$SRC/examples/dawn/depth.frag"
  RULES "$SRC/examples/dawn/rules.yaml" OUTPUT_NAME depth OPTIMIZE $2)
CMAKE
}

project "$T/ok" "HLSL HLSL_SHADER_MODEL 6.0 MSL MSL_PLATFORM ios"
cmake -S "$T/ok" -B "$T/ok/b" -G Ninja -DCMAKE_MAKE_PROGRAM="$NINJA" >"$T/cfg.log" 2>&1 || { cat "$T/cfg.log"; fail "configure"; }
"$NINJA" -C "$T/ok/b" >"$T/build.log" 2>&1 || { cat "$T/build.log"; fail "build"; }
G="$T/ok/b/shadergen/app"
grep -q '^cbuffer ShadergenUniforms : register(b0, space0)' "$G/depth.hlsl" && ok "depth.hlsl at shader model 6.0" ||
  fail "depth.hlsl missing or not model 6.0"
grep -q '"platform": "ios"' "$G/depth.json" && [ -s "$G/depth.metal" ] && ok "depth.metal for iOS, recorded in depth.json" ||
  fail "depth.metal / reflection"
head -n 1 "$G/depth.d" | grep -q "depth.hlsl $G/depth.metal $G/depth.json:" && ok "the depfile names the .hlsl and .metal" ||
  fail "depfile targets: $(head -n 1 "$G/depth.d")"
[ "$("$T/ok/b/app")" = "$(printf '%s\n%s' "$G/depth.hlsl" "$G/depth.metal")" ] && ok "SHADERGEN_DEPTH_HLSL/_MSL reach the target" ||
  fail "compile definitions: $("$T/ok/b/app")"
"$NINJA" -C "$T/ok/b" | grep -qx 'ninja: no work to do.' && ok "no-op rebuild" || fail "a rebuild ran something"

project "$T/bad" "MSL_VERSION 2.1"
if cmake -S "$T/bad" -B "$T/bad/b" -G Ninja -DCMAKE_MAKE_PROGRAM="$NINJA" >"$T/bad.log" 2>&1; then
  fail "MSL_VERSION without MSL configured"
else
  grep -q 'MSL_VERSION needs MSL' "$T/bad.log" && ok "MSL_VERSION without MSL: configure error" || fail "$(cat "$T/bad.log")"
fi
[ "$fails" -eq 0 ] && echo "PASS" || { echo "$fails failure(s)"; exit 1; }
