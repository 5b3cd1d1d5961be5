#!/usr/bin/env bash
# One build edge per variant against one command per manifest (docs/variants.md, "One
# build edge per variant"): the Dawn face and body (YAML rigs) x six passes x levels of
# detail (morph targets, influences, skeleton size) x the three device profiles of
# devices/ -- one manifest per profile, 1,080 variants in all -- built
#   - by CMake + Ninja through shadergen_add_shader_variants() (an edge per variant), and
#   - by `shadergen build MANIFEST`, one command per manifest, as today,
# each cold (empty cache), warm (nothing changed), after touching one rig (its mtime) and
# after editing it (its bytes: its variants are regenerated); their outputs are compared
# byte for byte at the end. Prints a Markdown table. No validation (2 cores).
# Ninja's side runs first (cold, warm, touched, edited), then the rig is restored and the
# single commands take the same steps.
#
#   bench/variants_ninja.sh [build-dir]
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$here/build}"
sg="$build/generator/cli/shadergen"
[[ -x "$sg" ]] || { echo "build shadergen first: $sg" >&2; exit 1; }
ninja=$(command -v ninja || command -v ninja-build)
jobs=$(nproc)
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# timed <name> <command...>: runs it, its output to <name>.log; prints "wall cpu" seconds
# (CPU: user + system of every process it ran; the machine is shared, so the wall time
# depends on its load, the CPU time much less).
timed() {
  local name=$1 t
  shift
  t=$( { TIMEFORMAT='%R %U %S'; time "$@" >"$work/$name.log" 2>&1; } 2>&1 ) || { tail -n 30 "$work/$name.log" >&2; exit 1; }
  awk '{ printf "%.2f %.2f", $1, $2 + $3 }' <<<"$t"
}

# The rigs are copied (to be touched and edited); one manifest per device profile.
profiles=(example llvmpipe-2core nvidia-h200)
src="$work/src"
mkdir -p "$src"
cp "$here/examples/dawn/face.rig.yaml" "$here/examples/dawn/body.rig.yaml" "$src/"
for p in "${profiles[@]}"; do
  cat >"$src/$p.variants.yaml" <<YAML
output: out/$p
rules: $here/examples/dawn/rules.yaml
device_profile: $here/devices/$p.yaml
rigs: { face: face.rig.yaml, body: body.rig.yaml }
passes:
  color: $here/examples/dawn/face.frag
  depth: $here/examples/dawn/depth.frag
  shadow: $here/bench/variants/shadow.frag
  gbuffer: $here/bench/variants/gbuffer.frag
  lit: $here/bench/variants/lit.frag
  eye: $here/bench/variants/eye.frag
axes:
  rig: [face, body]
  morph_targets: [5, 4, 2, 0]
  influences: [4, 3, 2, 1]
  bones: [98, 64, 32]
exclude: [{ rig: body, morph_targets: 5 }, { rig: body, morph_targets: 4 }, { rig: body, morph_targets: 2 }]
name: "{rig}-{pass}-m{morph_targets}-i{influences}-b{bones}"
YAML
done
{
  echo "cmake_minimum_required(VERSION 3.22)"
  echo "project(variants_bench CXX)"
  echo "add_executable(shadergen::shadergen IMPORTED)"
  echo "set_target_properties(shadergen::shadergen PROPERTIES IMPORTED_LOCATION \"$sg\")"
  echo "include(\"$here/cmake/ShadergenFunctions.cmake\")"
  echo "file(WRITE \"\${CMAKE_BINARY_DIR}/main.cpp\" \"int main() {}\\n\")"
  echo "add_executable(app \"\${CMAKE_BINARY_DIR}/main.cpp\")"
  for p in "${profiles[@]}"; do echo "shadergen_add_shader_variants(app MANIFEST $p.variants.yaml)"; done
} >"$src/CMakeLists.txt"
total=0
for p in "${profiles[@]}"; do total=$((total + $("$sg" build "$src/$p.variants.yaml" --list | wc -l))); done
body=$(( $("$sg" build "$src/example.variants.yaml" --list | grep -c '^body-') * ${#profiles[@]} ))

b="$work/ninja-build"
configure=$(timed configure cmake -S "$src" -B "$b" -G Ninja -DCMAKE_MAKE_PROGRAM="$ninja")
indexes=()
for p in "${profiles[@]}"; do indexes+=("$b/shadergen/app/$p/index.json"); done
nin() { timed "$1" "$ninja" -C "$b" -j "$jobs" -v "${indexes[@]}"; }  # nin <name>: Ninja builds the indexes
ran() { grep -c -- ' --variant ' "$work/$1.log" || true; }                # variant commands it ran
singles() { for p in "${profiles[@]}"; do "$sg" build "$src/$p.variants.yaml" -j "$jobs" -q; done; }
one() { timed "$1-single" singles; }                                       # one <name>: one command per manifest
edges=$("$ninja" -C "$b" -t commands "${indexes[@]}" | grep -c -- '--variant ')

# The same steps by each way, from the same rigs (restored in between).
cp "$src/body.rig.yaml" "$work/body.rig.yaml.orig"
n_cold=$(nin cold); c_cold=$(ran cold)
n_warm=$(nin warm); c_warm=$(ran warm)
sleep 1.1; touch "$src/body.rig.yaml"
n_touch=$(nin touch); c_touch=$(ran touch)
sleep 1.1; echo "# edited" >>"$src/body.rig.yaml"
n_edit=$(nin edit); c_edit=$(ran edit)

cp "$work/body.rig.yaml.orig" "$src/body.rig.yaml"
s_cold=$(one cold)
s_warm=$(one warm)
sleep 1.1; touch "$src/body.rig.yaml"
s_touch=$(one touch)
sleep 1.1; echo "# edited" >>"$src/body.rig.yaml"
s_edit=$(one edit)

row() { # row <label> <ninja "wall cpu"> <commands> <single "wall cpu">
  read -r nw nc <<<"$2"; read -r sw sc <<<"$4"
  echo "| $1 | $nw | $nc | $3 | $sw | $sc |"
}
echo "$edges variant edges in build.ninja"
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), load average $(cut -d' ' -f1-3 /proc/loadavg)"
echo
echo "| $total variants | Ninja wall s | Ninja CPU s | commands | one \`shadergen build\` per manifest: wall s | CPU s |"
echo "|---|---:|---:|---:|---:|---:|"
read -r cw cc <<<"$configure"
echo "| configure (expands the ${#profiles[@]} manifests) | $cw | $cc | | - | - |"
row "cold (empty cache)" "$n_cold" "$c_cold" "$s_cold"
row "warm, nothing changed" "$n_warm" "$c_warm" "$s_warm"
row "body.rig.yaml touched ($body variants)" "$n_touch" "$c_touch" "$s_touch"
row "body.rig.yaml edited ($body variants regenerated)" "$n_edit" "$c_edit" "$s_edit"

# Byte for byte: the depfiles name their outputs, so each manifest is built once more by
# the single command (from its cache) into Ninja's folder, Ninja's outputs moved aside.
files=0
for p in "${profiles[@]}"; do
  out="$b/shadergen/app/$p"
  mv "$out" "$work/ninja-out"
  "$sg" build "$src/$p.variants.yaml" -o "$out" --cache-dir "$src/out/$p/.shadergen-cache" -q
  diff -r -x .shadergen-cache -x .shadergen-variants "$out" "$work/ninja-out" >"$work/diff.log" ||
    { echo "DIFFERENT outputs for $p:" >&2; head -n 20 "$work/diff.log" >&2; exit 1; }
  files=$((files + $(find "$out" -type f -not -path '*/.shadergen-*' | wc -l)))
  rm -rf "$out" && mv "$work/ninja-out" "$out"
done
echo
echo "byte-identical to the single commands: $files files"
