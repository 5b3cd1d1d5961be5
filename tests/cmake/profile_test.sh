#!/usr/bin/env bash
# shadergen_add_vertex_shader(... DEVICE_PROFILE <a> <b> MESH ... BAN ... SET ... PIN ...) (docs/cmake.md):
# each shader is byte-identical to `shadergen generate` with the same flags; the mesh, a ban and
# a --set each change the plan as they do on the command line; both profiles are dependencies
# (editing the second regenerates the shaders, nothing else does); MESH without a profile, or
# a mesh that does not exist, is a configure error. shadergen_add_shader_variants(... DEVICE_PROFILE
# <a> <b>): each variant is generate's portable plan, and index.json lists both profiles.
#
#   profile_test.sh <shadergen> <source dir> <ninja>
set -uo pipefail
SG=$1 SRC=$2 NINJA=$3
T=$(mktemp -d "${TMPDIR:-/tmp}/sg-cmake-profile-XXXXXX")
trap 'rm -rf "$T"' EXIT
fails=0
fail() { echo "FAIL: $*" >&2; fails=$((fails + 1)); }
ok() { echo "ok: $*"; }

D="$SRC/examples/dawn"
P1="$T/h200.yaml" P2="$T/llvmpipe.yaml"
cp "$SRC/devices/nvidia-h200-raster.yaml" "$P1"
cp "$SRC/devices/llvmpipe-2core.yaml" "$P2"
project() {  # project <dir> <calls>: a project whose target `app` gets <calls> (CMake lines)
  mkdir -p "$1"
  cat >"$1/CMakeLists.txt" <<CMAKE
cmake_minimum_required(VERSION 3.22)
project(profiles CXX)
add_executable(shadergen::shadergen IMPORTED)
set_target_properties(shadergen::shadergen PROPERTIES IMPORTED_LOCATION "$SG")
include("$SRC/cmake/ShadergenFunctions.cmake")
file(WRITE "\${CMAKE_BINARY_DIR}/main.cpp" "int main() {}\n")
add_executable(app "\${CMAKE_BINARY_DIR}/main.cpp")
$2
CMAKE
}
shaders() {  # shaders <dir> <shadergen_add_vertex_shader arguments after the face's inputs, one call per line>
  local calls=""
  while IFS= read -r args; do
    calls+="shadergen_add_vertex_shader(app RIG \"$D/face.rig.yaml\" FRAGMENT \"$D/face.frag\" RULES \"$D/rules.yaml\" $args)"$'\n'
  done <<<"$2"
  project "$1" "$calls"
}

# A pin (bench --pin-out on lavapipe, the 3 plans cheapest under the second profile): PIN is --pin.
XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp/shadergen-xdg} "$SG" bench --rig "$D/face.rig.yaml" -f "$D/face.frag" -r "$D/rules.yaml" \
  --device-profile "$P2" --mesh head --raster off --draws 1 --min-frame-vertices 0 --frames 2 --rounds 1 --no-floor \
  --no-validation-layers --candidates 3 --pin-out "$T/face.pin.yaml" >"$T/bench.log" 2>&1 || { cat "$T/bench.log"; fail "bench --pin-out"; }
# name | the function's arguments | the same as generate flags
cases=(
  "pinned|PIN $T/face.pin.yaml|--pin $T/face.pin.yaml"
  "dawn|DEVICE_PROFILE $P1 $P2 MESH dawn|--device-profile $P1 --device-profile $P2 --mesh dawn"
  "head|DEVICE_PROFILE $P1 $P2 MESH head|--device-profile $P1 --device-profile $P2 --mesh head"
  "banned|DEVICE_PROFILE $P1 $P2 MESH dawn BAN skin_matrix_blend|--device-profile $P1 --device-profile $P2 --mesh dawn --ban skin_matrix_blend"
  "rigid|DEVICE_PROFILE $P1 $P2 MESH dawn SET influences=1|--device-profile $P1 --device-profile $P2 --mesh dawn --set influences=1"
)
calls=""
for c in "${cases[@]}"; do
  IFS='|' read -r name args _ <<<"$c"
  calls+="OUTPUT_NAME $name $args"$'\n'
done
shaders "$T/ok" "${calls%$'\n'}"
cmake -S "$T/ok" -B "$T/ok/b" -G Ninja -DCMAKE_MAKE_PROGRAM="$NINJA" >"$T/cfg.log" 2>&1 || { cat "$T/cfg.log"; fail "configure"; }
"$NINJA" -C "$T/ok/b" >"$T/build.log" 2>&1 || { cat "$T/build.log"; fail "build"; }
G="$T/ok/b/shadergen/app"

for c in "${cases[@]}"; do
  IFS='|' read -r name _ flags <<<"$c"
  # shellcheck disable=SC2086
  "$SG" generate --rig "$D/face.rig.yaml" -f "$D/face.frag" -r "$D/rules.yaml" $flags \
    -o "$T/cli-$name" --emit glsl,spv,reflection -q || fail "generate $flags"
  for ext in vert spv json; do
    cmp -s "$G/$name.$ext" "$T/cli-$name.$ext" || fail "$name.$ext differs from generate $flags"
  done
  ok "$name: byte-identical to generate $flags"
done

blend() { grep -o '// [a-z_]* -> skin.matrix' "$G/$1.vert" | cut -d' ' -f2; }
[ -n "$(blend dawn)" ] && [ -n "$(blend head)" ] && [ "$(blend dawn)" != "$(blend head)" ] &&
  ok "MESH prices the workload: the portable plan blends with $(blend dawn) at Dawn scale, $(blend head) on the head" ||
  fail "skin blends: dawn '$(blend dawn)', head '$(blend head)'"
[ -n "$(blend banned)" ] && [ "$(blend banned)" != skin_matrix_blend ] && ok "BAN: $(blend banned) in place of skin_matrix_blend" ||
  fail "banned plan blends with '$(blend banned)'"
case "$(blend rigid)" in skin_matrix_rigid*) ok "SET influences=1: a rigid skin ($(blend rigid))" ;; *) fail "SET: '$(blend rigid)'" ;; esac

grep -q "$P2" "$G/dawn.d" && grep -q "$P1" "$G/dawn.d" && ok "the depfile names both profiles" || fail "depfile: $(cat "$G/dawn.d")"
grep -q "$T/face.pin.yaml" "$G/pinned.d" && ok "the depfile names the pin" || fail "pinned depfile: $(cat "$G/pinned.d")"
"$NINJA" -C "$T/ok/b" | grep -qx 'ninja: no work to do.' && ok "no-op rebuild" || fail "a rebuild ran something"
touch "$P2"
n=$("$NINJA" -C "$T/ok/b" | grep -c 'shadergen: generating vertex shader')
[ "$n" = 4 ] && ok "editing the second profile regenerates the 4 shaders" || fail "after touching $P2: $n regenerated"

# The same two profiles for a manifest's variants, one build edge each.
cat >"$T/m.variants.yaml" <<YAML
rules: $D/rules.yaml
mesh: head
rigs: { face: $D/face.rig.yaml }
passes: { color: $D/face.frag }
YAML
project "$T/var" "shadergen_add_shader_variants(app MANIFEST \"$T/m.variants.yaml\" DEVICE_PROFILE \"$P1\" \"$P2\")"
cmake -S "$T/var" -B "$T/var/b" -G Ninja -DCMAKE_MAKE_PROGRAM="$NINJA" >"$T/vcfg.log" 2>&1 || { cat "$T/vcfg.log"; fail "configure variants"; }
"$NINJA" -C "$T/var/b" >"$T/vbuild.log" 2>&1 || { cat "$T/vbuild.log"; fail "build variants"; }
V="$T/var/b/shadergen/app/m"
cmp -s "$V/face-color.vert" "$T/cli-head.vert" && ok "the manifest's variant is generate's portable plan on the head" ||
  fail "face-color.vert differs from generate --device-profile $P1 --device-profile $P2 --mesh head"
grep -q "\"device_profiles\": \[\"$P1\", \"$P2\"\]" "$V/index.json" && ok "index.json lists both profiles" ||
  fail "index.json: $(head -8 "$V/index.json")"

shaders "$T/noprofile" "MESH head"
if cmake -S "$T/noprofile" -B "$T/noprofile/b" -G Ninja -DCMAKE_MAKE_PROGRAM="$NINJA" >"$T/bad1.log" 2>&1; then
  fail "MESH without DEVICE_PROFILE configured"
else
  grep -q 'MESH needs DEVICE_PROFILE' "$T/bad1.log" && ok "MESH without DEVICE_PROFILE: configure error" || fail "$(cat "$T/bad1.log")"
fi
shaders "$T/nomesh" "DEVICE_PROFILE $P1 MESH torso"
if cmake -S "$T/nomesh" -B "$T/nomesh/b" -G Ninja -DCMAKE_MAKE_PROGRAM="$NINJA" >"$T/bad2.log" 2>&1; then
  fail "MESH torso configured"
else
  grep -q 'MESH must be head, limb or dawn, not' "$T/bad2.log" && grep -q "'torso'" "$T/bad2.log" && ok "an unknown MESH: configure error" || fail "$(cat "$T/bad2.log")"
fi
[ "$fails" -eq 0 ] && echo "PASS" || { echo "$fails failure(s)"; exit 1; }
