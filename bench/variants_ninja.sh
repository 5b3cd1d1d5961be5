#!/usr/bin/env bash
# One build edge per variant against one command per manifest (docs/variants.md, "One
# build edge per variant"): the Dawn face and body (YAML rigs) x six passes x levels of
# detail (morph targets, influences, skeleton size) x the three device profiles of
# devices/ -- one manifest per profile, 1,080 variants in all -- built
#   - by CMake + Ninja through shadergen_add_shader_variants() (an edge per variant), and
#   - by `shadergen build MANIFEST`, one command per manifest, as today,
# each cold (empty cache), warm (nothing changed), after touching one rig (its mtime) and
# after editing it (its bytes: its variants are regenerated). Both start from their own
# copy of the rigs, so each does the same work; their outputs are compared byte for byte
# at the end. Prints a Markdown table. No validation (2 cores).
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

now() { date +%s%N; }
secs() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", (b - a) / 1e9 }'; }

# Two identical source trees: one for Ninja, one for the single commands.
profiles=(example llvmpipe-2core nvidia-h200)
for side in ninja single; do
  src="$work/$side-src"
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
done
src="$work/ninja-src"
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
t0=$(now); cmake -S "$src" -B "$b" -G Ninja -DCMAKE_MAKE_PROGRAM="$ninja" >"$work/cfg.log" 2>&1 || { cat "$work/cfg.log"; exit 1; }; t1=$(now)
configure=$(secs "$t0" "$t1")
indexes=()
for p in "${profiles[@]}"; do indexes+=("$b/shadergen/app/$p/index.json"); done
nin() {  # nin <name>: build the indexes, print the seconds; the commands run go to <name>.log
  local a z
  a=$(now); "$ninja" -C "$b" -j "$jobs" -v "${indexes[@]}" >"$work/$1.log" 2>&1 || { tail -n 30 "$work/$1.log"; exit 1; }; z=$(now)
  secs "$a" "$z"
}
ran() { grep -c -- '--variant ' "$work/$1.log" || true; }
one() {  # one: every manifest by one `shadergen build` each, print the seconds
  local a z
  a=$(now)
  for p in "${profiles[@]}"; do "$sg" build "$work/single-src/$p.variants.yaml" -j "$jobs" -q; done
  z=$(now)
  secs "$a" "$z"
}
edges=$("$ninja" -C "$b" -t commands "${indexes[@]}" | grep -c -- '--variant ')

n_cold=$(nin cold); c_cold=$(ran cold)
s_cold=$(one)
n_warm=$(nin warm); c_warm=$(ran warm)
s_warm=$(one)
sleep 1.1
touch "$src/body.rig.yaml" "$work/single-src/body.rig.yaml"
n_touch=$(nin touch); c_touch=$(ran touch)
s_touch=$(one)
sleep 1.1
for s in "$src" "$work/single-src"; do echo "# edited" >>"$s/body.rig.yaml"; done
n_edit=$(nin edit); c_edit=$(ran edit)
s_edit=$(one)

for p in "${profiles[@]}"; do
  diff -r -x .shadergen-cache -x .shadergen-variants "$b/shadergen/app/$p" "$work/single-src/out/$p" >/dev/null ||
    { echo "DIFFERENT outputs for $p" >&2; exit 1; }
done
files=$(find "$b/shadergen/app" -type f -not -path '*/.shadergen-*' | wc -l)
echo "byte-identical: $files files (${#profiles[@]} manifests, $total variants); $edges variant edges in build.ninja"
echo
echo "| $total variants, $jobs cores | CMake + Ninja, an edge per variant: s | commands run | one \`shadergen build\` per manifest: s |"
echo "|---|---:|---:|---:|"
echo "| configure (expands the ${#profiles[@]} manifests) | $configure | | - |"
echo "| cold (empty cache) | $n_cold | $c_cold | $s_cold |"
echo "| warm, nothing changed | $n_warm | $c_warm | $s_warm |"
echo "| body.rig.yaml touched ($body variants) | $n_touch | $c_touch | $s_touch |"
echo "| body.rig.yaml edited ($body variants regenerated) | $n_edit | $c_edit | $s_edit |"
