#!/usr/bin/env bash
# shadergen_add_shader_variants() with one build edge per variant (docs/cmake.md,
# docs/variants.md), through CMake + Ninja with this build's generator as an imported
# executable: a 36-variant manifest of the Dawn face and body (copied, so they can be
# touched) and a whole glTF model (MODEL.gltf#*), also built by ONE_COMMAND.
#   - every variant is its own edge in build.ninja, with its own depfile;
#   - the first build runs each variant's command once and one --join;
#   - the outputs equal a single-process `shadergen build` of the manifest byte for byte;
#   - a rebuild runs nothing; touching / editing one rig reruns exactly its variants;
#   - editing the manifest (or touching the whole model) re-expands it at the next build.
#
#   variants_test.sh <shadergen> <source dir> <ninja>
set -uo pipefail
SG=$1 SRC=$2 NINJA=$3
T=$(mktemp -d "${TMPDIR:-/tmp}/sg-cmake-variants-XXXXXX")
trap 'rm -rf "$T"' EXIT
fails=0
fail() { echo "FAIL: $*" >&2; fails=$((fails + 1)); }
ok() { echo "ok: $*"; }
P=$T/proj B=$T/build
mkdir -p "$P"
cp "$SRC/examples/dawn/face.rig.yaml" "$SRC/examples/dawn/body.rig.yaml" "$SRC/examples/dawn/face.frag" \
  "$SRC/examples/dawn/depth.frag" "$SRC/bench/variants/shadow.frag" "$P/"
MODEL=${SHADERGEN_SHARED_DIR:-$SRC/../shared}/models/SimpleMorph  # the shared models sit next to the checkout
cp "$MODEL/SimpleMorph.gltf" "$MODEL"/*.bin "$P/" || fail "no $MODEL"
chmod u+w "$P"/*
cat >"$P/chars.variants.yaml" <<YAML
output: unused  # the function gives -o
rules: $SRC/examples/dawn/rules.yaml
rigs: { face: face.rig.yaml, body: body.rig.yaml }
passes: { color: face.frag, depth: depth.frag, shadow: shadow.frag }
axes:
  morph_targets: [5, 3, 0]
  influences: [4, 2, 1]
exclude: [{ rig: body, morph_targets: 5 }, { rig: body, morph_targets: 3 }]
name: "{rig}-{pass}-m{morph_targets}-i{influences}"
YAML
cat >"$P/model.variants.yaml" <<YAML
rules: $SRC/examples/dawn/rules.yaml
rigs: { morph: SimpleMorph.gltf#* }
passes: { depth: depth.frag }
YAML
cat >"$P/CMakeLists.txt" <<CMAKE
cmake_minimum_required(VERSION 3.22)
project(variants CXX)
add_executable(shadergen::shadergen IMPORTED)
set_target_properties(shadergen::shadergen PROPERTIES IMPORTED_LOCATION "$SG")
include("$SRC/cmake/ShadergenFunctions.cmake")
file(WRITE "\${CMAKE_BINARY_DIR}/main.cpp" "#include <cstdio>\nint main() { std::puts(SHADERGEN_CHARS_INDEX); }\n")
add_executable(app "\${CMAKE_BINARY_DIR}/main.cpp")
shadergen_add_shader_variants(app MANIFEST chars.variants.yaml)
shadergen_add_shader_variants(app MANIFEST model.variants.yaml)
file(WRITE "\${CMAKE_BINARY_DIR}/one.cpp" "int main() {}\n")
add_executable(one "\${CMAKE_BINARY_DIR}/one.cpp")
shadergen_add_shader_variants(one MANIFEST model.variants.yaml ONE_COMMAND)
CMAKE
OUT=$B/shadergen/app/chars
tick() { sleep 1.1; }  # mtime granularity on some file systems
build() {              # build <log>: every command Ninja ran, one a line
  "$NINJA" -C "$B" -v >"$T/$1.log" 2>&1 || { cat "$T/$1.log"; fail "build $1"; }
}
ran() { grep -o -- "chars.variants.yaml .*--variant [^ ]*" "$T/$1.log" | sed 's/.*--variant //' | sort; }  # variants run by build <log>
joins() { grep -c -- "chars.variants.yaml .* --join" "$T/$1.log"; }
noop() { "$NINJA" -C "$B" | grep -qx 'ninja: no work to do.' && ok "no-op rebuild $1" || fail "a rebuild $1 ran something"; }
same_as_single() {  # the CMake outputs equal one `shadergen build` of the manifest, byte for byte
  # Into the same folder (depfiles name their outputs): the CMake outputs are moved aside.
  rm -rf "$T/cmake-out" && mv "$OUT" "$T/cmake-out"
  "$SG" build "$P/chars.variants.yaml" -o "$OUT" --cache-dir "$T/single-cache" -q || fail "single-process build"
  if diff -r -x .shadergen-cache -x .shadergen-variants "$OUT" "$T/cmake-out" >"$T/diff.log"; then
    ok "$(find "$OUT" -type f | wc -l) files byte-identical to one shadergen build ($1)"
  else
    fail "outputs differ from one shadergen build ($1): $(head -n 5 "$T/diff.log")"
  fi
  rm -rf "$OUT" && mv "$T/cmake-out" "$OUT"
}

cmake -S "$P" -B "$B" -G Ninja -DCMAKE_MAKE_PROGRAM="$NINJA" >"$T/cfg.log" 2>&1 || { cat "$T/cfg.log"; fail "configure"; }
"$SG" build "$P/chars.variants.yaml" --list | sort >"$T/all"
"$SG" build "$P/chars.variants.yaml" --list | grep '^body-' | sort >"$T/body"
n=$(wc -l <"$T/all")
[ "$n" = 36 ] && [ "$(wc -l <"$T/body")" = 9 ] || fail "the manifest has $n variants, $(wc -l <"$T/body") of the body"

# One edge per variant, each with its own depfile.
"$NINJA" -C "$B" -t commands >"$T/commands"
grep -o -- "chars.variants.yaml .*--variant [^ ]*" "$T/commands" | sed 's/.*--variant //' | sort >"$T/edges"
cmp -s "$T/edges" "$T/all" && ok "build.ninja: one command per variant ($n)" || fail "variant commands: $(diff "$T/all" "$T/edges" | head)"
edges_with_depfile=$(awk '/^build [^ ]*\.entry .*: CUSTOM_COMMAND/{e=1; next} e && /^  depfile = /{c++} /^$/{e=0} END{print c+0}' "$B/build.ninja")
[ "$edges_with_depfile" = $((n + 1)) ] && ok "every variant edge has a depfile" ||
  fail "$edges_with_depfile variant edges with a depfile, expected $((n + 1)) (36 + the model's)"

grep -q -- "model.variants.yaml -o $B/shadergen/one/model -q && " "$T/commands" &&
  ok "ONE_COMMAND: one shadergen build for the manifest" || fail "ONE_COMMAND: $(grep -- /one/model "$T/commands")"

build cold
[ -s "$B/shadergen/one/model/index.json" ] && ok "ONE_COMMAND builds the index" || fail "ONE_COMMAND: no index"
ran cold >"$T/cold.ran"
cmp -s "$T/cold.ran" "$T/all" && [ "$(joins cold)" = 1 ] && ok "first build: each variant's command once, one --join" ||
  fail "first build ran $(wc -l <"$T/cold.ran") variant commands, $(joins cold) joins"
[ "$("$B/app")" = "$OUT/index.json" ] && ok "SHADERGEN_CHARS_INDEX reaches the target" || fail "index define: $("$B/app")"
same_as_single "cold"
# The depfile Ninja reads for one face variant (as CMake rewrote it): its rig and the
# rules reached through include:, not the body.
depfile=$(awk '/^build [^ ]*face-color-m5-i4\.entry /{e=1; next} e && /^  depfile = /{print $3; exit}' "$B/build.ninja")
grep -q 'face\.rig\.yaml' "$depfile" && ! grep -q 'body\.rig\.yaml' "$depfile" && grep -q 'skinning\.yaml' "$depfile" &&
  ok "a face variant's depfile: its rig and the included rules, not the body" || fail "depfile $depfile: $(cat "$depfile")"
noop "after the first build"

tick; touch "$P/body.rig.yaml"
build touch-body
ran touch-body | diff - "$T/body" >/dev/null && [ "$(joins touch-body)" = 1 ] &&
  ok "touching body.rig.yaml reruns exactly its 9 variants and the join" || fail "ran: $(ran touch-body | tr '\n' ' ')"
noop "after touching body.rig.yaml"

tick; entries=$(find "$OUT/.shadergen-cache" -type f | wc -l)
sed -i 's/^rig: .*/&  # edited/' "$P/body.rig.yaml"
build edit-body
ran edit-body | diff - "$T/body" >/dev/null && ok "editing body.rig.yaml reruns exactly its 9 variants" ||
  fail "ran: $(ran edit-body | tr '\n' ' ')"
[ $(($(find "$OUT/.shadergen-cache" -type f | wc -l) - entries)) = 9 ] && ok "9 new cache entries" || fail "cache entries"
same_as_single "after editing body.rig.yaml"
noop "after editing body.rig.yaml"

# A new axis value: CMake re-expands the manifest; the 12 new variants get edges and are
# the only ones built (the others' stamps did not change).
tick; sed -i 's/influences: \[4, 2, 1\]/influences: [4, 3, 2, 1]/' "$P/chars.variants.yaml"
build edit-manifest
grep -q 'regenerate-during-build' "$T/edit-manifest.log" && ok "editing the manifest re-runs CMake" || fail "no re-configure"
[ "$(ran edit-manifest | grep -c -- '-i3$')" = 12 ] && [ "$(ran edit-manifest | wc -l)" = 12 ] &&
  [ "$(joins edit-manifest)" = 1 ] && ok "only the 12 new variants built, one join" || fail "ran: $(ran edit-manifest | tr '\n' ' ')"
[ "$(grep -c '"name"' "$OUT/index.json")" = 48 ] && ok "index lists 48 variants" || fail "index: $(grep -c '"name"' "$OUT/index.json")"
same_as_single "after adding an axis value"
noop "after editing the manifest"

# A whole model: its file is a configure dependency (its primitives are the rigs).
tick; touch "$P/SimpleMorph.gltf"
build touch-model
grep -q 'regenerate-during-build' "$T/touch-model.log" && grep -q -- "model.variants.yaml .*--variant" "$T/touch-model.log" &&
  ok "touching the whole model re-expands its manifest and rebuilds its variant" || fail "$(cat "$T/touch-model.log")"
noop "after touching the whole model"

# `pins: DIR` (docs/variants.md): a pin written for one variant (bench --manifest --pin-out on
# lavapipe) re-runs CMake at the next build (the directory is a configure dependency) and
# rebuilds exactly that variant, pinned.
mkdir -p "$P/pins"
tick; echo "pins: pins" >>"$P/chars.variants.yaml"
build add-pins
noop "after adding pins: DIR"
tick
"$SG" bench --manifest "$P/chars.variants.yaml" --variant face-depth-m3-i2 --mesh head --raster off --draws 1 --min-frame-vertices 0 \
  --frames 1 --rounds 1 --no-floor --no-validation-layers --candidates 2 --pin-out "$P/pins" >"$T/tune.log" 2>&1 ||
  fail "bench --manifest: $(cat "$T/tune.log")"
build pin-one
grep -q 'regenerate-during-build' "$T/pin-one.log" && [ "$(ran pin-one)" = face-depth-m3-i2 ] &&
  grep -q '"pin": {"file": "[^"]*pins/face-depth-m3-i2.pin.yaml"' "$OUT/index.json" &&
  ok "a new pin in pins: DIR re-runs CMake and rebuilds exactly its variant, pinned" ||
  fail "after a new pin, ran: $(ran pin-one | tr '\n' ' '); $(grep -c '"pin"' "$OUT/index.json") pinned"
same_as_single "after a pin"
noop "after a pin"

# A broken manifest fails the next build with its file:line:col error.
tick; echo "unknown_key: 1" >>"$P/chars.variants.yaml"
if "$NINJA" -C "$B" >"$T/bad.log" 2>&1; then
  fail "a broken manifest built"
else
  grep -q "chars.variants.yaml:11:1: error: unknown" "$T/bad.log" && ok "a broken manifest: its error at configure" ||
    fail "$(cat "$T/bad.log")"
fi
[ "$fails" -eq 0 ] && echo "PASS" || { echo "$fails failure(s)"; exit 1; }
