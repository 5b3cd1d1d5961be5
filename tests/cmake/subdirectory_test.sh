#!/usr/bin/env bash
# add_subdirectory() of the source tree: the consumer configured with
# -DSHADERGEN_SOURCE_DIR=<source> must get shadergen_add_vertex_shader() and run the
# in-tree generator (built first); bad calls of the function fail at configure time.
# Configure-only plus a dry run (a full build of the generator takes minutes); set
# SHADERGEN_FULL_SUBDIRECTORY_TEST=1 to also build and run it.
#
#   subdirectory_test.sh <shadergen source dir> [ninja]
set -uo pipefail
SRC=$1 NINJA=${2:-$(command -v ninja || command -v ninja-build)}
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp}
T=$(mktemp -d "${TMPDIR:-/tmp}/sg-subdir-XXXXXX")
trap 'rm -rf "$T"' EXIT
fails=0
fail() { echo "FAIL: $*" >&2; fails=$((fails + 1)); }
ok() { echo "ok: $*"; }

OUT=$T/build
if cmake -S "$SRC/examples/cmake-consumer" -B "$OUT" -G Ninja -DCMAKE_MAKE_PROGRAM="$NINJA" \
  -DSHADERGEN_SOURCE_DIR="$SRC" >"$T/configure.log" 2>&1; then
  ok "consumer configures with add_subdirectory(<shadergen source>)"
  cmds=$("$NINJA" -C "$OUT" -t commands shadergen_consumer)
  grep -q "$OUT/shadergen/generator/cli/shadergen generate --rig $SRC/examples/cmake-consumer/face.rig.yaml" <<<"$cmds" &&
    ok "custom command runs the in-tree generator" || fail "custom command: $(grep generate <<<"$cmds")"
  grep -q -- "-r $SRC/rules/standard.yaml" <<<"$cmds" && ok "SHADERGEN_RULES_DIR is the source tree's rules/" ||
    fail "rules dir: $(grep -o -- '-r [^ ]*standard.yaml' <<<"$cmds")"
  "$NINJA" -C "$OUT" -n shadergen_consumer >"$T/dry.log" 2>&1
  gen_line=$(grep -n 'generating vertex shader face' "$T/dry.log" | cut -d: -f1)
  exe_line=$(grep -n 'Linking CXX executable shadergen/generator/cli/shadergen$' "$T/dry.log" | cut -d: -f1)
  [ -n "$gen_line" ] && [ -n "$exe_line" ] && [ "$exe_line" -lt "$gen_line" ] &&
    ok "the generator is built before it runs" || fail "build order: $(cat "$T/dry.log")"
  grep -q 'gtest\|tests/' "$T/dry.log" && fail "the consumer build would build shadergen's tests" || ok "shadergen's tests are not built"
  if [ "${SHADERGEN_FULL_SUBDIRECTORY_TEST:-0}" = 1 ]; then
    "$NINJA" -C "$OUT" >"$T/build.log" 2>&1 && "$OUT/shadergen_consumer" | tail -n 1 | grep -qx OK &&
      ok "built and ran: OK" || fail "full build/run: $(tail -n 20 "$T/build.log")"
  fi
else
  fail "configure: $(cat "$T/configure.log")"
fi

# Misuse is a configure error with a message that says what is wrong.
mkdir -p "$T/bad"
cat >"$T/bad/CMakeLists.txt" <<EOF2
cmake_minimum_required(VERSION 3.20)
project(bad LANGUAGES CXX)
add_subdirectory("$SRC" shadergen EXCLUDE_FROM_ALL)
file(WRITE \${CMAKE_CURRENT_BINARY_DIR}/m.cpp "int main() { return 0; }\n")
add_executable(app \${CMAKE_CURRENT_BINARY_DIR}/m.cpp)
shadergen_add_vertex_shader(app RIG face.rig.yaml RULES r.yaml)
EOF2
if cmake -S "$T/bad" -B "$T/bad/build" -G Ninja -DCMAKE_MAKE_PROGRAM="$NINJA" >"$T/bad.log" 2>&1; then
  fail "a call without FRAGMENT configured"
else
  grep -q 'FRAGMENT is required' "$T/bad.log" && ok "missing FRAGMENT is a configure error" || fail "message: $(tail -n 20 "$T/bad.log")"
fi

if [ "$fails" -ne 0 ]; then
  echo "$fails check(s) failed" >&2
  exit 1
fi
echo "all checks passed"
