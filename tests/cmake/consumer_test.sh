#!/usr/bin/env bash
# The installed package from a consumer's point of view (examples/cmake-consumer):
#   1. cmake --install <build dir> --prefix <tmp>
#   2. configure + build a copy of the consumer against it (CMAKE_PREFIX_PATH), run it on
#      lavapipe, check its output (GPU gl_Position == CPU, "OK")
#   3. incremental builds: no-op does nothing; touching a shader's rig (or its own rules
#      file) regenerates exactly that shader; touching an installed rules file reached only
#      through `include:` or the installed template regenerates both; nothing else does.
#
#   consumer_test.sh <shadergen build dir> <shadergen source dir> [ninja]
set -uo pipefail
BUILD=$1 SRC=$2 NINJA=${3:-$(command -v ninja || command -v ninja-build)}
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp}
T=$(mktemp -d "${TMPDIR:-/tmp}/sg-consumer-XXXXXX")
trap 'rm -rf "$T"' EXIT
PREFIX=$T/prefix CONSUMER=$T/src OUT=$T/build

fails=0
fail() { echo "FAIL: $*" >&2; fails=$((fails + 1)); }
ok() { echo "ok: $*"; }
die() { echo "FAIL: $*" >&2; exit 1; }
[ -x "$NINJA" ] || die "ninja not found"

# 1. Install.
cmake --install "$BUILD" --prefix "$PREFIX" >"$T/install.log" 2>&1 || die "install: $(cat "$T/install.log")"
for f in bin/shadergen share/shadergen/templates/vertex.glsl share/shadergen/rules/standard.yaml \
  share/shadergen/rules/skinning.yaml include/shadergen/runtime/vk_harness.h \
  lib/cmake/shadergen/shadergenConfig.cmake lib/cmake/shadergen/ShadergenFunctions.cmake; do
  [ -e "$PREFIX/$f" ] && ok "installed $f" || fail "not installed: $f"
done
"$PREFIX/bin/shadergen" --version >/dev/null && ok "installed shadergen runs" || fail "installed shadergen --version"

# 2. Configure, build and run a copy of the consumer (a copy: the test touches its files).
cp -r "$SRC/examples/cmake-consumer" "$CONSUMER"
cmake -S "$CONSUMER" -B "$OUT" -G Ninja -DCMAKE_MAKE_PROGRAM="$NINJA" -DCMAKE_PREFIX_PATH="$PREFIX" \
  >"$T/configure.log" 2>&1 || die "configure: $(cat "$T/configure.log")"
ok "consumer configured with find_package(shadergen)"
"$NINJA" -C "$OUT" >"$T/build.log" 2>&1 || die "build: $(cat "$T/build.log")"
ok "consumer built"
grep -q "$PREFIX/bin/shadergen generate" "$OUT/build.ninja" && ok "custom command runs the installed shadergen" ||
  fail "custom command does not use $PREFIX/bin/shadergen"
"$OUT/shadergen_consumer" >"$T/run.log" 2>&1
rc=$?
cat "$T/run.log"
[ $rc -eq 0 ] && ok "consumer exits 0" || fail "consumer exit $rc"
grep -q '^face: gl_Position\[0\] gpu' "$T/run.log" && grep -q '^face: .*: match$' "$T/run.log" &&
  grep -q '^prop: .*: match$' "$T/run.log" && ok "GPU gl_Position matches the CPU for both shaders" || fail "no match lines"
[ "$(tail -n 1 "$T/run.log")" = "OK" ] && ok "consumer prints OK" || fail "consumer did not print OK"

# The engine program: shadergen::core at load time makes the build's variants byte for byte.
"$OUT/shadergen_engine" >"$T/engine.log" 2>&1
rc=$?
cat "$T/engine.log"
[ $rc -eq 0 ] && [ "$(tail -n 1 "$T/engine.log")" = "OK" ] && [ "$(grep -c 'same SPIR-V as the build' "$T/engine.log")" = 2 ] &&
  ok "shadergen::core remakes two variants byte for byte" || fail "engine program (exit $rc)"
VARIANTS=$OUT/shadergen/shadergen_engine/variants
n=$(grep -c '"name":' "$VARIANTS/index.json")
[ "$n" = 16 ] && ok "variants index lists 16 variants" || fail "variants index lists $n variants"
entries() { find "$VARIANTS/.shadergen-cache" -type f | wc -l; }

# 3. Incremental builds.
GEN=$OUT/shadergen/shadergen_consumer
mtime() { stat -c %Y.%y "$1"; }
# build <label>: runs ninja -d explain; sets $regen to the shaders it regenerated (sorted).
build() {
  "$NINJA" -C "$OUT" -d explain >"$T/$1.log" 2>&1 || fail "$1: build failed: $(cat "$T/$1.log")"
  regen=$(grep -o 'generating vertex shader [a-z]*' "$T/$1.log" | awk '{print $4}' | sort | tr '\n' ' ' | sed 's/ $//')
}
expect_regen() {  # <label> <expected shaders, space-separated, sorted> <why>
  if [ "$regen" = "$2" ]; then ok "$3: regenerated [${regen}]"; else
    fail "$3: regenerated [${regen}], expected [$2]"; sed 's/^/  | /' "$T/$1.log" >&2
  fi
}
noop() {
  "$NINJA" -C "$OUT" >"$T/noop.log" 2>&1
  grep -qx 'ninja: no work to do.' "$T/noop.log" && ok "no-op rebuild: ninja: no work to do ($1)" ||
    { fail "no-op rebuild did work ($1)"; sed 's/^/  | /' "$T/noop.log" >&2; }
}
tick() { sleep 0.05; }  # let the file system clock move past the outputs' mtimes

noop "after the first build"

tick; before_prop=$(mtime "$GEN/prop.spv") before_face=$(mtime "$GEN/face.spv")
touch "$CONSUMER/face.rig.yaml"
build touch-face-rig
expect_regen touch-face-rig "face" "touch face.rig.yaml"
grep -q 'older than most recent input .*face.rig.yaml' "$T/touch-face-rig.log" && ok "ninja explains: face.rig.yaml is newer" ||
  fail "ninja -d explain does not name face.rig.yaml"
[ "$(mtime "$GEN/prop.spv")" = "$before_prop" ] && ok "prop.spv untouched" || fail "prop.spv rewritten"
[ "$(mtime "$GEN/face.spv")" != "$before_face" ] && ok "face.spv rewritten" || fail "face.spv not rewritten"
noop "after touching face.rig.yaml"

tick; touch "$CONSUMER/prop.rules.yaml"
build touch-prop-rules
expect_regen touch-prop-rules "prop" "touch prop.rules.yaml"
noop "after touching prop.rules.yaml"

tick; touch "$CONSUMER/prop.frag"
build touch-prop-frag
expect_regen touch-prop-frag "prop" "touch prop.frag"

# skinning.yaml is only reached through standard.yaml's include: only the depfile knows it.
tick; touch "$PREFIX/share/shadergen/rules/skinning.yaml"
build touch-included-rules
expect_regen touch-included-rules "face prop" "touch included rules/skinning.yaml"
noop "after touching an included rules file"

tick; touch "$PREFIX/share/shadergen/templates/vertex.glsl"
build touch-template
expect_regen touch-template "face prop" "touch templates/vertex.glsl"
noop "after touching the template"

# A regenerated face.spv.h recompiled only face_shader.cpp, never main.cpp.
grep -q 'face_shader.cpp.o' "$T/touch-face-rig.log" && ! grep -q 'main.cpp.o$' "$T/touch-face-rig.log" &&
  ok "a new face.spv.h recompiles face_shader.cpp only" || fail "recompiled: $(grep -o 'Building CXX object [^ ]*' "$T/touch-face-rig.log")"
# Touching the consumer's C++ source recompiles it and regenerates no shader.
tick; touch "$CONSUMER/main.cpp"
build touch-main
expect_regen touch-main "" "touch main.cpp"
noop "at the end"

"$OUT/shadergen_consumer" | tail -n 1 | grep -qx OK && ok "consumer still OK after the rebuilds" || fail "consumer after rebuilds"

# Editing one rig's bytes regenerates that rig's variants only (4 body variants: 4 new
# cache entries), leaves the face's outputs untouched, and the next build is a no-op.
tick; before_entries=$(entries) before_facevar=$(mtime "$VARIANTS/face-color-m5-i4.vert")
echo "# edited" >>"$CONSUMER/body.rig.yaml"
"$NINJA" -C "$OUT" >"$T/edit-body.log" 2>&1 || fail "build after editing body.rig.yaml"
# One build edge per variant: the 4 body variants' commands ran, no face variant's.
[ "$(grep -c 'building shader variant body-' "$T/edit-body.log")" = 4 ] &&
  ! grep -q 'building shader variant face-' "$T/edit-body.log" && ok "editing body.rig.yaml reruns its 4 variants' commands" ||
  fail "variant commands after editing body.rig.yaml: $(grep -o 'building shader variant [^ ]*' "$T/edit-body.log" | tr '\n' ' ')"
[ "$(( $(entries) - before_entries ))" = 4 ] && ok "exactly the 4 body variants regenerated" ||
  fail "$(( $(entries) - before_entries )) variants regenerated, expected 4"
[ "$(mtime "$VARIANTS/face-color-m5-i4.vert")" = "$before_facevar" ] && ok "face variant outputs untouched" ||
  fail "face variant output rewritten"
noop "after editing body.rig.yaml"

if [ "$fails" -ne 0 ]; then
  echo "$fails check(s) failed" >&2
  exit 1
fi
echo "all checks passed"
