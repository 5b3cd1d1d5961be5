#!/usr/bin/env bash
# CLI conventions of `shadergen generate` (glslc style): exit codes, -o, --emit, --target-env,
# -MD/-MF depfiles, atomic outputs, byte-identical reruns, the C++ header, --version/--help.
#
#   cli_test.sh <case> <shadergen> <source dir> <c++ compiler> <version> [ninja]
set -uo pipefail
[ -z "${LD_PRELOAD-}" ] || SG_SHADERGEN_PRELOAD=$LD_PRELOAD LD_PRELOAD= exec bash "$0" "$@"  # tests/support/preload_only_shadergen.sh
case_name=$1 SG=$2 SRC=$3 CXX=$4 VERSION=$5 NINJA=${6:-}
E=$SRC/examples/dawn
T=$(mktemp -d "${TMPDIR:-/tmp}/sg-cli-XXXXXX")
trap 'chmod -R u+w "$T" 2>/dev/null; rm -rf "$T"' EXIT
source "$SRC/tests/support/preload_only_shadergen.sh"
preload_only_shadergen SG "$T"
cd "$T"

fails=0
fail() { echo "FAIL: $*" >&2; fails=$((fails + 1)); }
ok() { echo "ok: $*"; }
# expect <code> <description> -- command...
expect() {
  local want=$1 what=$2
  shift 3
  "$@" >"$T/last.out" 2>"$T/last.err"
  local got=$?
  if [ "$got" -eq "$want" ]; then ok "$what (exit $got)"; else
    fail "$what: exit $got, expected $want"; sed 's/^/  | /' "$T/last.err" >&2
  fi
}
DAWN=(--rig "$E/face.rig.yaml" -f "$E/face.frag" -r "$E/rules.yaml")
# A calibrate run sent SIGINT, its exit status <rc> and files <name>.out, .err, .yaml: it fitted
# what it timed, or, interrupted before any timing, failed saying so; never a death by the signal
# (exit 130).
interrupted_calibration() {  # interrupted_calibration <rc> <name> <what>
  local rc=$1 name=$2 what=$3
  if [ "$rc" -eq 0 ] && grep -q "^note: interrupted: [0-9]* samples were timed" "$name.out" && [ -s "$name.yaml" ]; then
    ok "$what: fits what it timed"
  elif [ "$rc" -ne 0 ] && [ "$rc" -ne 130 ] && grep -q "interrupted before anything was timed" "$name.err"; then
    ok "$what, before any timing: says so"
  else
    fail "$what: exit $rc; $(tail -3 "$name.out") $(cat "$name.err")"
  fi
}
no_temps() {  # no *.tmp.* / *.bak.* left anywhere under $1
  local left
  left=$(find "$1" -name '*.tmp.*' -o -name '*.bak.*')
  [ -z "$left" ] && ok "no temporaries left in $(basename "$1")" || fail "temporaries left: $left"
}

case "$case_name" in

version_help)
  expect 0 "--version" -- "$SG" --version
  grep -qx "shadergen $VERSION" last.out && ok "--version prints 'shadergen $VERSION'" || fail "--version printed: $(cat last.out)"
  expect 0 "--help" -- "$SG" --help
  grep -q "generate" last.out || fail "--help does not list generate"
  expect 0 "generate --help" -- "$SG" generate --help
  for opt in "-o" "--emit" "--target-env" "-O" "-MD" "-MF" "--capture" "--rig" "--fragment" "--rules"; do
    grep -q -- "$opt" last.out && ok "generate --help mentions $opt" || fail "generate --help lacks $opt"
  done
  ;;

exit_codes)
  expect 0 "valid inputs" -- "$SG" generate "${DAWN[@]}" -o ok/face -q
  expect 2 "no subcommand" -- "$SG"
  expect 2 "unknown option" -- "$SG" generate "${DAWN[@]}" -o x -q --frobnicate
  expect 2 "unknown subcommand" -- "$SG" frobnicate
  expect 2 "missing --rig" -- "$SG" generate -f "$E/face.frag" -r "$E/rules.yaml" -o x
  expect 2 "missing --fragment" -- "$SG" generate --rig "$E/face.rig.yaml" -r "$E/rules.yaml" -o x
  expect 2 "missing --rules" -- "$SG" generate --rig "$E/face.rig.yaml" -f "$E/face.frag" -o x
  expect 2 "bad --target-env" -- "$SG" generate "${DAWN[@]}" -o x --target-env=vulkan9
  expect 2 "bad --emit" -- "$SG" generate "${DAWN[@]}" -o x --emit glsl,elf
  expect 2 "-MF without a path" -- "$SG" generate "${DAWN[@]}" -o x -MF
  expect 2 "malformed --map" -- "$SG" generate "${DAWN[@]}" -o x --map bogus -q
  grep -q '^shadergen: error: ' last.err && ok "usage errors start with 'shadergen: error:'" || fail "usage error: $(head -1 last.err)"
  printf 'rig: broken\ndeformers: [1, 2\n' >bad.rig.yaml
  expect 1 "malformed rig (YAML)" -- "$SG" generate --rig bad.rig.yaml -f "$E/face.frag" -r "$E/rules.yaml" -o x -q
  grep -Eq '^bad\.rig\.yaml:[0-9]+:[0-9]+: error: ' last.err && ok "diagnostic is file:line:col: error:" ||
    fail "diagnostic format: $(head -1 last.err)"
  sed 's/format: float32x3/format: float99/' "$E/face.rig.yaml" >badfmt.rig.yaml
  expect 1 "rig with an unknown vertex format" -- "$SG" generate --rig badfmt.rig.yaml -f "$E/face.frag" -r "$E/rules.yaml" -o x -q
  expect 1 "missing rig file" -- "$SG" generate --rig nope.rig.yaml -f "$E/face.frag" -r "$E/rules.yaml" -o x -q
  printf 'include: [does-not-exist.yaml]\n' >bad.rules.yaml
  expect 1 "rules including a missing file" -- "$SG" generate --rig "$E/face.rig.yaml" -f "$E/face.frag" -r bad.rules.yaml -o x -q
  printf '#version 450\nlayout(location = 0) in vec3 Foo\nvoid main() {}\n' >bad.frag
  expect 1 "fragment shader that does not compile" -- "$SG" generate --rig "$E/face.rig.yaml" -f bad.frag -r "$E/rules.yaml" -o x -q
  [ ! -e x ] && [ ! -e x.vert ] && [ ! -e x.spv ] && ok "failed runs wrote nothing" || fail "a failed run wrote outputs"
  no_temps "$T"
  ;;

outputs)
  # -o names the file exactly when one kind is emitted (like glslc -o).
  expect 0 "--emit spv -o dir/my.spv" -- "$SG" generate "${DAWN[@]}" --emit spv -o one/my.spv -q
  [ "$(ls one)" = "my.spv" ] && ok "exactly one/my.spv written" || fail "one/ holds: $(ls one)"
  [ "$(od -An -tx4 -N4 one/my.spv | tr -d ' ')" = "07230203" ] && ok "SPIR-V magic" || fail "one/my.spv is not SPIR-V"
  expect 0 "--emit glsl -o shader.glsl" -- "$SG" generate "${DAWN[@]}" --emit glsl -o g/shader.glsl -q
  [ "$(ls g)" = "shader.glsl" ] && grep -q '^#version 450' g/shader.glsl && ok "exactly g/shader.glsl written" || fail "g/ holds: $(ls g)"
  # Several kinds: -o is a stem (a known suffix is stripped).
  expect 0 "--emit all -o all/face" -- "$SG" generate "${DAWN[@]}" --emit glsl,spv,header,reflection -o all/face -q
  [ "$(ls all | tr '\n' ' ')" = "face.json face.spv face.spv.h face.vert " ] && ok "stem outputs" || fail "all/ holds: $(ls all)"
  expect 0 "--emit glsl,spv -o st/face.spv" -- "$SG" generate "${DAWN[@]}" --emit glsl,spv -o st/face.spv -q
  [ "$(ls st | tr '\n' ' ')" = "face.spv face.vert " ] && ok "suffix stripped from the stem" || fail "st/ holds: $(ls st)"
  python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["inputs"] and d["outputs"] and d["uniform_block"]["members"]' all/face.json &&
    ok "reflection is JSON with inputs/outputs/uniforms" || fail "all/face.json is not the expected JSON"
  # Default: the fragment shader's stem in the current directory, glsl + spv.
  mkdir def && (cd def && "$SG" generate "${DAWN[@]}" -q) && [ "$(ls def | tr '\n' ' ')" = "face.spv face.vert " ] &&
    ok "default outputs face.vert face.spv" || fail "default outputs: $(ls def)"
  # --target-env, '=' and space syntax; the SPIR-V version word follows it.
  for env in vulkan1.0:00010000 vulkan1.1:00010300 vulkan1.2:00010500 vulkan1.3:00010600; do
    name=${env%%:*} want=${env##*:}
    expect 0 "--target-env=$name" -- "$SG" generate "${DAWN[@]}" --emit spv -o "env/$name.spv" --target-env="$name" -q
    got=$(od -An -tx4 -j4 -N4 "env/$name.spv" | tr -d ' ')
    [ "$got" = "$want" ] && ok "$name -> SPIR-V version word $got" || fail "$name -> SPIR-V version word $got, expected $want"
  done
  expect 0 "--target-env vulkan1.2 (space)" -- "$SG" generate "${DAWN[@]}" --emit spv -o env/space.spv --target-env vulkan1.2 -q
  cmp -s env/space.spv env/vulkan1.2.spv && ok "'=' and space syntax agree" || fail "--target-env syntaxes differ"
  # -O: optimised SPIR-V still valid and different from the unoptimised one.
  expect 0 "-O" -- "$SG" generate "${DAWN[@]}" --emit spv -o opt/face.spv -O -q
  if command -v spirv-val >/dev/null; then
    spirv-val opt/face.spv && ok "-O output passes spirv-val" || fail "-O output fails spirv-val"
  fi
  cmp -s opt/face.spv one/my.spv && fail "-O changed nothing" || ok "-O changes the SPIR-V"
  # --capture: transform-feedback qualifiers only when asked.
  expect 0 "--capture" -- "$SG" generate "${DAWN[@]}" --emit glsl -o cap/face.vert --capture -q
  grep -q 'xfb_offset' cap/face.vert && ok "--capture adds xfb qualifiers" || fail "--capture output lacks xfb_offset"
  grep -q 'xfb_' g/shader.glsl && fail "xfb qualifiers without --capture" || ok "no xfb qualifiers without --capture"
  no_temps "$T"
  ;;

depfile)
  expect 0 "-MD" -- "$SG" generate "${DAWN[@]}" --emit glsl,spv -o d/face -MD -q
  [ -f d/face.vert.d ] && ok "-MD writes <first output>.d" || fail "no d/face.vert.d: $(ls d)"
  expect 0 "-MF" -- "$SG" generate "${DAWN[@]}" --emit spv -o f/face.spv -MF f/deps.d -q
  [ -f f/deps.d ] && [ ! -e f/face.spv.d ] && ok "-MF names the depfile" || fail "-MF: $(ls f)"
  head -1 f/deps.d | grep -q '^f/face\.spv: \\$' && ok "-MF target is the output" || fail "-MF target line: $(head -1 f/deps.d)"
  head -1 d/face.vert.d | grep -q '^d/face\.vert d/face\.spv: \\$' && ok "every output is a target, the first first" ||
    fail "target line: $(head -1 d/face.vert.d)"
  # Every input read: rig, fragment, the rules file and everything it includes, the template.
  want=("$E/face.rig.yaml" "$E/face.frag" "$E/rules.yaml" "$SRC/templates/vertex.glsl")
  for r in standard vocabulary encodings morph skinning frames view projection buffers conventions; do want+=("$SRC/rules/$r.yaml"); done
  deps=$(tail -n +2 d/face.vert.d | sed 's/^ *//; s/ *\\$//')
  for w in "${want[@]}"; do
    w=$(realpath -ms "$w")
    grep -qxF "$w" <<<"$deps" && ok "depfile lists ${w#$SRC/}" || fail "depfile lacks $w"
  done
  [ "$(wc -l <<<"$deps")" -eq "${#want[@]}" ] && ok "depfile lists nothing else" || fail "depfile: $deps"
  # Relative inputs stay relative (to the working directory, like a compiler's depfile).
  mkdir rel && cp "$E/face.rig.yaml" "$E/face.frag" rel/ && printf 'include: [%s]\nvaryings:\n' "$SRC/rules/standard.yaml" >rel/r.yaml
  sed -n '/^varyings:/,$p' "$E/rules.yaml" | tail -n +2 >>rel/r.yaml
  (cd rel && "$SG" generate --rig face.rig.yaml -f face.frag -r r.yaml --emit spv -o out.spv -MD -q) && grep -q '^  face.rig.yaml \\$' rel/out.spv.d &&
    ok "relative input paths as given" || fail "relative depfile: $(cat rel/out.spv.d)"
  # Ninja reads it (paths with spaces too): build, no-op, touch an included rules file.
  if [ -n "$NINJA" ]; then
    mkdir -p "nj/in put" && cp "$E/face.rig.yaml" "$E/face.frag" "nj/in put/"
    cp -r "$SRC/rules" "nj/in put/rules" && cp -r "$SRC/templates" "nj/in put/templates"
    printf 'include: [rules/standard.yaml]\nvaryings:\n' >"nj/in put/face rules.yaml"
    sed -n '/^varyings:/,$p' "$E/rules.yaml" | tail -n +2 >>"nj/in put/face rules.yaml"
    cat >nj/build.ninja <<EOF
rule sg
  command = "$SG" generate --rig "in put/face.rig.yaml" -f "in put/face.frag" -r "in put/face rules.yaml" --templates "in put/templates" --emit spv,reflection -o out/face -MF out/face.d -q
  depfile = out/face.d
  deps = gcc
build out/face.spv out/face.json: sg
EOF
    (cd nj && "$NINJA" >../nj1.log 2>&1) && ok "ninja builds with the depfile" || fail "ninja build: $(cat nj1.log)"
    (cd nj && "$NINJA" -t deps out/face.spv) >nj-deps.log 2>&1
    grep -q 'in put/rules/skinning.yaml' nj-deps.log && grep -q 'in put/templates/vertex.glsl' nj-deps.log &&
      ok "ninja recorded included rules and the template (paths with spaces)" || fail "ninja deps: $(cat nj-deps.log)"
    (cd nj && "$NINJA") | grep -q 'no work to do' && ok "ninja: no-op rebuild" || fail "ninja rebuilt without a change"
    sleep 0.01; touch "nj/in put/rules/skinning.yaml"
    (cd nj && "$NINJA" -d explain >../nj2.log 2>&1)
    grep -q 'older than most recent input in put/rules/skinning.yaml' nj2.log && ok "touching an included rules file rebuilds" ||
      fail "included rules file not a dependency: $(cat nj2.log)"
    sleep 0.01; touch "nj/in put/templates/vertex.glsl"
    (cd nj && "$NINJA") | grep -q 'no work to do' && fail "touching the template did not rebuild" || ok "touching the template rebuilds"
    (cd nj && "$NINJA") | grep -q 'no work to do' && ok "ninja: no-op again" || fail "ninja rebuilt without a change"
  fi
  no_temps "$T"
  ;;

atomic)
  "$SG" generate "${DAWN[@]}" --emit glsl,spv,header,reflection -o out/face -MD -q || fail "first run"
  cp -r out saved
  # A bad rig: the run fails before writing; old outputs stay byte-identical.
  printf 'rig: [oops\n' >bad.rig.yaml
  expect 1 "bad rig over existing outputs" -- "$SG" generate --rig bad.rig.yaml -f "$E/face.frag" -r "$E/rules.yaml" \
    --emit glsl,spv,header,reflection -o out/face -MD -q
  diff -r saved out >/dev/null && ok "old outputs unchanged after an input error" || fail "outputs changed: $(diff -rq saved out)"
  no_temps "$T/out"
  # A write that fails half-way (the reflection's path is a directory): outputs renamed before
  # the failure are put back, so every old output is unchanged and nothing new appears.
  rm -rf blocked && mkdir blocked && printf 'old glsl\n' >blocked/face.vert && printf 'old spv\n' >blocked/face.spv
  mkdir blocked/face.json
  cp -r blocked blocked.saved
  expect 1 "output path is a directory" -- "$SG" generate "${DAWN[@]}" --emit glsl,spv,header,reflection -o blocked/face -MD -q
  grep -q "blocked/face.json" last.err && ok "error names the file" || fail "error: $(cat last.err)"
  diff -r blocked.saved blocked >/dev/null && ok "all-or-nothing: old outputs restored, no new ones" ||
    fail "partial write: $(diff -rq blocked.saved blocked)"
  no_temps "$T/blocked"
  # A read-only output directory (meaningless as root, who may write anyway).
  if [ "$(id -u)" -ne 0 ]; then
    chmod a-w out
    expect 1 "read-only output directory" -- "$SG" generate "${DAWN[@]}" --emit glsl,spv,header,reflection -o out/face -MD -q
    chmod u+w out
    diff -r saved out >/dev/null && ok "old outputs unchanged" || fail "outputs changed"
    no_temps "$T/out"
  else
    echo "skip: read-only directory case (running as root)"
  fi
  # A successful rerun replaces them and cleans up.
  expect 0 "rerun" -- "$SG" generate "${DAWN[@]}" --emit glsl,spv,header,reflection -o out/face -MD -q
  no_temps "$T/out"
  ;;

deterministic)
  for d in a b; do  # same inputs, two output directories
    "$SG" generate "${DAWN[@]}" --emit glsl,spv,header,reflection -o "$d/out/face" -MD -q &&
      "$SG" generate "${DAWN[@]}" --emit spv -o "$d/opt/face.spv" -O -MD -q --target-env=vulkan1.2 &&
      "$SG" generate "${DAWN[@]}" --emit glsl,spv -o "$d/cap/face" --capture -MD -q || fail "run into $d"
  done
  n=0
  while IFS= read -r f; do
    n=$((n + 1))
    if [[ $f == *.d ]]; then  # the target line names the output path; the rest must match
      cmp -s <(tail -n +2 "a/$f") <(tail -n +2 "b/$f") && ok "identical (modulo target): $f" || fail "differs: $f"
    else
      cmp -s "a/$f" "b/$f" && ok "identical: $f" || fail "differs: $f"
    fi
  done < <(cd a && find . -type f | sort)
  [ "$n" -eq 10 ] && ok "compared $n files" || fail "compared $n files, expected 10"
  # Different output directories must not leak into the shader outputs either.
  "$SG" generate "${DAWN[@]}" --emit glsl,spv,header,reflection -o elsewhere/deep/face -q
  for f in face.vert face.spv face.spv.h face.json; do
    cmp -s "a/out/$f" "elsewhere/deep/$f" && ok "same $f from another output dir" || fail "$f depends on the output dir"
  done
  ;;

hlsl_msl)  # docs/hlsl-msl.md: --emit hlsl,msl, byte-identical reruns, validate --via hlsl
  for d in a b; do  # two processes, two output directories
    "$SG" generate "${DAWN[@]}" --emit spv,hlsl,msl,reflection -O -o "$d/face" -q --hlsl-shader-model 6.0 \
      --msl-version 2.1 --msl-platform ios || fail "run into $d"
  done
  for f in face.spv face.hlsl face.metal face.json; do
    cmp -s "a/$f" "b/$f" && ok "identical: $f" || fail "differs: $f"
  done
  grep -q '^cbuffer ShadergenUniforms : register(b0, space0)' a/face.hlsl && ok "HLSL cbuffer at b0, space0" ||
    fail "no cbuffer at b0 in face.hlsl"
  grep -q 'SPIRV_Cross_Output main(SPIRV_Cross_Input stage_input)' a/face.hlsl && ok "HLSL entry point main" ||
    fail "no HLSL entry point"
  grep -q 'vertex main0_out main0(main0_in in \[\[stage_in\]\], constant ShadergenUniforms& uniforms \[\[buffer(0)\]\])' \
    a/face.metal && ok "MSL entry point main0, uniforms at buffer(0)" || fail "MSL entry point"
  grep -q '"shader_model": "6.0", "profile": "vs_6_0", "entry_point": "main"' a/face.json &&
    grep -q '"version": "2.1", "platform": "ios", "entry_point": "main0"' a/face.json &&
    ok "reflection records the HLSL and MSL options" || fail "reflection lacks the options"
  # One kind: -o names the file exactly.
  expect 0 "--emit hlsl -o x.hlsl" -- "$SG" generate "${DAWN[@]}" --emit hlsl -o one/x.hlsl -q
  [ "$(ls one)" = "x.hlsl" ] && ok "wrote only one/x.hlsl" || fail "wrote: $(ls one)"
  expect 0 "validate --via hlsl (depth pass)" -- "$SG" validate --rig "$E/face.rig.yaml" -f "$E/depth.frag" \
    -r "$E/rules.yaml" --via hlsl --poses 1
  grep -q "running HLSL 5.0 (compiled back by glslang)" last.out && ok "validate says what ran" ||
    fail "validate output: $(head -3 last.out)"
  ;;

header)
  "$SG" generate "${DAWN[@]}" --emit spv,header -o gen/face -q || fail "generate"
  "$SG" generate "${DAWN[@]}" --emit header -o gen/2nd-shader.spv.h -q || fail "generate 2nd-shader"
  grep -q 'face_spv\[\]' gen/face.spv.h && ok "symbol face_spv from the stem" || fail "no face_spv in header"
  grep -q 'sg_2nd_shader_spv\[\]' gen/2nd-shader.spv.h && ok "symbol sg_2nd_shader_spv (sanitised)" || fail "2nd-shader symbol: $(grep -o '[a-z_0-9]*\[\]' gen/2nd-shader.spv.h)"
  bytes=$(stat -c %s gen/face.spv)
  cat >use.cpp <<'EOF'
#include "face.spv.h"
#include "face.spv.h"  // include guard
#include "2nd-shader.spv.h"
#include <cstdio>
#include <cstring>
#include <vector>
size_t other_tu_size();
int main() {
  static_assert(sizeof(face_spv[0]) == 4, "32-bit words");
  if (face_spv[0] != 0x07230203u || face_spv_size != sizeof(face_spv) || face_spv_size % 4) return 1;
  if (face_spv_size != other_tu_size()) return 2;
  if (std::memcmp(face_spv, sg_2nd_shader_spv, face_spv_size) != 0) return 3;
  std::vector<uint32_t> words(face_spv, face_spv + face_spv_size / 4);
  std::printf("%zu\n", words.size() * 4);
  return 0;
}
EOF
  printf '#include "face.spv.h"\nsize_t other_tu_size() { return face_spv_size; }\n' >other.cpp
  # The packed face's inputs as the header states them, against the Vulkan header's enum.
  "$SG" generate --rig "$SRC/examples/dawn/face-packed.rig.yaml" -f "$SRC/examples/dawn/face.frag" \
    -r "$SRC/examples/dawn/rules.yaml" --emit header -o gen/packed.spv.h -q || fail "generate packed"
  cat >>other.cpp <<'EOF'
#include "packed.spv.h"
#include <vulkan/vulkan_core.h>
static_assert(PACKED_INPUT_COUNT == 15u, "15 inputs");
static_assert(PACKED_A_COORD_LOCATION == 0u && PACKED_A_COORD_FORMAT == VK_FORMAT_R16G16B16A16_UNORM, "coord");
static_assert(PACKED_A_COORD_STRIDE == 8u, "coord stride");
static_assert(PACKED_A_FRAME_FORMAT == VK_FORMAT_R16G16B16A16_SNORM && PACKED_A_FRAME_STRIDE == 8u, "frame (a QTangent)");
static_assert(PACKED_A_BONE_WEIGHT_FORMAT == VK_FORMAT_R8G8B8A8_UNORM, "weights");
static_assert(PACKED_A_SKIN_UVST_FORMAT == VK_FORMAT_R16G16B16A16_SFLOAT, "uvst");
EOF
  if "$CXX" -std=c++17 -Wall -Wextra -Werror -pedantic -Igen use.cpp other.cpp -o use 2>cxx.log; then
    ok "header compiles in two C++ TUs (-Wall -Wextra -Werror -pedantic)"
    out=$(./use) && [ "$out" = "$bytes" ] && ok "face_spv_size == size of face.spv ($bytes bytes)" || fail "run: exit $? output '$out' (want $bytes)"
  else
    fail "header does not compile: $(cat cxx.log)"
  fi
  ;;

search)
  # --search picks the engine, --stats reports the effort; every engine finds cost 97 (81 before the degenerate-tangent fallback, 100 with it as a branch; docs/design.md).
  expect 0 "--stats (default engine)" -- "$SG" generate "${DAWN[@]}" -o s/face --stats
  grep -q '^search (regression A\*, lmcut): [0-9]* expanded, [0-9]* generated' last.out && ok "--stats names engine and counts" ||
    fail "--stats printed: $(head -2 last.out)"
  grep -q 'initial h 97 vs cost 97; heuristic [0-9.]* ms of [0-9.]* ms' last.out && ok "--stats: initial h vs cost, heuristic time" ||
    fail "--stats printed: $(head -2 last.out)"
  for engine in forward ip regression; do
    expect 0 "--search $engine" -- "$SG" generate "${DAWN[@]}" -o "s/$engine" --search "$engine" --stats
    grep -q "^search ($engine" last.out && grep -q 'total cost 97$' last.out && ok "--search $engine: cost 97" ||
      fail "--search $engine printed: $(head -3 last.out)"
    # The shader's header and the plan line name the search that found it: no A* for the IP.
    case $engine in ip) what='integer program' ;; *) what='lmcut A\*' ;; esac
    grep -q "Plan cost 97 ($what)\.$" s/$engine*.vert && ok "--search $engine: the header names it" ||
      fail "--search $engine header: $(grep -h 'Plan cost' s/$engine*)"
    case $engine in ip) grep -q "^plan for rig .*(21 rules, integer program):" last.out ;;
                    *) grep -q "^plan for rig .*(21 rules, lmcut A\*, [0-9]* expanded):" last.out ;; esac &&
      ok "--search $engine: the plan line names it" || fail "--search $engine plan line: $(grep '^plan for' last.out)"
  done
  expect 2 "unknown --search" -- "$SG" generate "${DAWN[@]}" -o x --search sideways
  expect 2 "negative --search-time-limit" -- "$SG" generate "${DAWN[@]}" -o x --search-time-limit -1
  expect 2 "--max-expansions 0" -- "$SG" generate "${DAWN[@]}" -o x --max-expansions 0
  expect 1 "--max-expansions below the need" -- "$SG" generate "${DAWN[@]}" -o x --max-expansions 3
  grep -q '^shadergen: error: search gave up: expansion limit of 3 reached' last.err && ok "names the expansion limit" ||
    fail "expansion limit error: $(head -1 last.err)"
  expect 1 "--search-time-limit too short" -- "$SG" generate "${DAWN[@]}" -o x --search forward --search-time-limit 0.000001
  grep -q 'time limit of 1e-06 s reached' last.err && ok "names the time limit" || fail "time limit error: $(head -1 last.err)"
  [ ! -e x.vert ] && [ ! -e x.spv ] && ok "a search that gave up wrote nothing" || fail "a search that gave up wrote outputs"
  expect 0 "generous limits" -- "$SG" generate "${DAWN[@]}" -o s/limited -q --search-time-limit 60 --max-expansions 1000
  cmp -s s/limited.spv s/face.spv && ok "limits do not change the output" || fail "limits changed the output"
  ;;


check_rig)
  # `check --rig`: every rule run alone on lavapipe against its definition (docs/rules-authoring.md).
  expect 0 "check --rig (rules run alone)" -- "$SG" check --rig "$E/face.rig.yaml" "$SRC/rules/standard.yaml"
  grep -q '^rules run alone on .* against their definitions (.* vertices, 5 poses): [0-9]* agree, 0 disagree; [0-9]* skipped: in no plan for the rig$' last.err &&
    ok "summary: agree, 0 disagree" || fail "check --rig printed: $(head -3 last.err)"
  grep -q '^  object_position_unmorphed: when .!has(morph.position) && !has(morph.position_scaled). is false' last.err && ok "lists rules not applicable" ||
    fail "no not-applicable list: $(cat last.err)"
  expect 0 "check --rig --no-run" -- "$SG" check --rig "$E/face.rig.yaml" "$SRC/rules/standard.yaml" --no-run
  grep -q 'rules run alone' last.err && fail "--no-run still ran the rules" || ok "--no-run skips the device"
  # A drifted copy: the buffer-fed tangent rule without the fallback is located at the rule.
  mkdir -p drift && cp "$SRC"/rules/*.yaml drift/
  sed -i 's/^      @use tangent_orthonormal(\${out}, \${object.normal})$/      ${out} = normalize(${out} - dot(${out}, ${object.normal}) * ${object.normal});/' drift/buffers.yaml
  expect 1 "check --rig with a drifted rule" -- "$SG" check --rig "$E/face.rig.yaml" drift/standard.yaml
  grep -q "^drift/buffers.yaml:[0-9]*:[0-9]*: error: rule 'object_tangent_morphed_buffer_gram_schmidt' disagrees with the definition of 'object.tangent' .* at input " last.err &&
    ok "the disagreement is located at the rule, with its input" || fail "check printed: $(head -5 last.err)"
  grep -q "^drift/buffers.yaml:[0-9]*:[0-9]*: error: rule 'object_tangent_morphed_sparse_gram_schmidt' disagrees" last.err &&
    ok "and the sparse form too" || fail "check printed: $(head -5 last.err)"
  # A rig without an occlusion (issue 34): the rules reading one are in no plan for it, so
  # they are skipped and listed with why, not fed an occlusion the rig does not have.
  PBR=$SRC/tests/validate/data/pbr_character.rig.yaml
  expect 0 "check --rig, a rig without occlusion" -- "$SG" check --rig "$PBR" "$SRC/rules/standard.yaml"
  grep -q '^rules run alone on .*: [0-9]* agree, 0 disagree; 6 skipped: in no plan for the rig$' last.err &&
    grep -q "^  object_occlusion_from_normal_occlusion: needs 'morph.normal_occlusion', which the rig neither provides nor derives$" last.err &&
    ok "the occlusion rules are skipped, with why" || fail "check printed: $(cat last.err)"
  # A wrong rule the rig can use still fails; the wrong rule it cannot use is skipped.
  expect 1 "check --rig, planted wrong rules" -- "$SG" check --rig "$PBR" "$SRC/tests/validate/data/planted_wrong.rules.yaml"
  grep -q "planted_wrong.rules.yaml:8:11: error: rule 'object_normal_morphed' disagrees" last.err &&
    ! grep -q "error: rule 'object_occlusion_from_normal_occlusion'" last.err &&
    ok "the usable wrong rule fails, the unusable one is skipped" || fail "check printed: $(cat last.err)"
  # A glTF primitive as the rig: MorphStressTest's targets move position and normal, no occlusion.
  MST=$SRC/../shared/models/MorphStressTest/MorphStressTest.gltf
  if [ -f "$MST" ]; then
    expect 0 "check --rig MODEL.gltf#0/1" -- "$SG" check --rig "$MST#0/1" "$SRC/rules/standard.yaml"
    grep -q "^  object_occlusion_from_normal_occlusion: needs 'morph.normal_occlusion'" last.err &&
      ok "a glTF rig: the occlusion rules are skipped" || fail "check printed: $(cat last.err)"
  fi
  ;;

device_limits)
  # validate / render / bench --device: the named device's own limits (docs/limits.md). The
  # 300-bone palette (19,200 bytes) is over the guaranteed 16,384-byte uniform block but
  # within lavapipe's: without --device the palette comes from a buffer, with it from the block.
  L=(--rig "$SRC/tests/validate/data/limb8_palette300.rig.yaml" -f "$SRC/tests/validate/data/world.frag"
    -r "$SRC/rules/standard.yaml" --mesh limb)
  expect 0 "validate (guaranteed limits)" -- "$SG" validate "${L[@]}" --poses 1
  grep -q 'limits of' last.out && fail "limits read without --device" || ok "no device limits without --device"
  grep -q '^chosen plan: plan cost 109,' last.out && ok "buffer palette (cost 109)" || fail "validate printed: $(head -4 last.out)"
  expect 0 "validate --device llvmpipe" -- "$SG" validate "${L[@]}" --poses 1 --device llvmpipe
  grep -q '^limits of llvmpipe.*: [0-9]* vertex attributes, [0-9]* uniform bytes, [0-9]* storage buffers' last.out &&
    ok "prints the device's limits" || fail "validate --device printed: $(head -4 last.out)"
  grep -q '^chosen plan: plan cost 101,' last.out && ok "palette in the uniform block (cost 101)" ||
    fail "validate --device printed: $(head -5 last.out)"
  expect 0 "validate --device with a flag above the device's" -- "$SG" validate "${L[@]}" --poses 1 --device llvmpipe --max-attributes 4096
  grep -q -- "--max-attributes 4096 clamped to the device's maxVertexInputAttributes" last.out && ok "clamped, and says so" ||
    fail "validate printed: $(head -4 last.out)"
  expect 0 "render --device llvmpipe" -- "$SG" render "${L[@]}" --device llvmpipe --size 16x16 -o limb.png
  grep -q '^limits of llvmpipe' last.out && grep -q 'plan cost 101,' last.out && ok "render searches under them too" ||
    fail "render printed: $(cat last.out)"
  expect 0 "bench --device llvmpipe" -- "$SG" bench "${L[@]}" --device llvmpipe --frames 1 --rounds 1 --draws 1 \
    --no-alternatives --no-floor --size 16x16
  grep -q '^limits of llvmpipe' last.out && grep -q '^| generated | pass | 101 |' last.out && ok "bench searches under them too" ||
    fail "bench printed: $(head -12 last.out)"
  ;;

build)
  # `shadergen build`: one process, cache across runs (and between two concurrent builds),
  # unchanged outputs untouched, byte-identical to `generate --set`, located errors.
  cp "$E/face.rig.yaml" face.rig.yaml
  cat >m.yaml <<EOF
output: out
rules: $E/rules.yaml
rigs:
  face: face.rig.yaml
passes:
  color: $E/face.frag
  depth: $E/depth.frag
  shadow: shadow.frag
axes:
  influences: [4, 1]
EOF
  printf '#version 450\nlayout(location = 0) out float D;\nvoid main() { D = gl_FragCoord.z; }\n' >shadow.frag
  expect 0 "build" -- "$SG" build m.yaml
  grep -q "6 variants: 6 generated, 0 from the cache, 0 failed" last.out && ok "cold: 6 generated" || fail "cold summary: $(cat last.out)"
  [ -f out/index.json ] && [ -f out/face-color-influences4.vert ] && [ -f out/face-depth-influences1.json ] &&
    [ -f out/face-color-influences1.d ] && ok "index, GLSL, reflection and depfiles written" || fail "outputs missing: $(ls out)"
  spv=$(ls out/spirv/*.spv | wc -l)
  [ "$spv" -eq 4 ] && ok "4 SPIR-V modules for 6 variants (shadow = depth, kept once)" || fail "$spv SPIR-V files"
  no_temps out
  before=$(stat -c %Y.%y out/face-color-influences4.vert)
  sleep 1
  expect 0 "warm build" -- "$SG" build m.yaml
  grep -q "6 variants: 0 generated, 6 from the cache" last.out && ok "warm: all from the cache" || fail "warm summary: $(cat last.out)"
  [ "$(stat -c %Y.%y out/face-color-influences4.vert)" = "$before" ] && ok "unchanged output not rewritten" ||
    fail "unchanged output rewritten"
  expect 0 "generate --set influences=1" -- "$SG" generate --rig face.rig.yaml -f "$E/face.frag" -r "$E/rules.yaml" \
    --set influences=1 -o sep/face-color-influences1 --emit glsl,spv,reflection -q
  spvpath=$(grep -A20 '"name": "face-color-influences1"' out/index.json | grep -o 'spirv/[0-9a-f]*\.spv' | head -1)
  cmp -s sep/face-color-influences1.spv "out/$spvpath" && cmp -s sep/face-color-influences1.json out/face-color-influences1.json &&
    cmp -s sep/face-color-influences1.vert out/face-color-influences1.vert &&
    ok "build output == generate --set output (GLSL, SPIR-V, reflection)" || fail "build and generate differ ($spvpath)"
  # A level-of-detail variant is validated as its own rig: the sparse 52-target face with 2 targets
  # poses at most 2 active ones (before: "the pose has 6 targets with a non-zero weight").
  SP=(--rig "$SRC/tests/validate/data/face52_sparse.rig.yaml" -f "$SRC/tests/validate/data/world.frag" -r "$SRC/rules/standard.yaml")
  expect 0 "validate --set morph_targets=2 (sparse face)" -- "$SG" validate "${SP[@]}" --set morph_targets=2 --poses 2 --no-validation-layers
  grep -q '^PASS' last.out && ok "the 2-target level of detail validates" || fail "validate printed: $(tail -3 last.out)"
  cat >lod.yaml <<EOF
output: lod
rules: $SRC/rules/standard.yaml
rigs:
  sparse: $SRC/tests/validate/data/face52_sparse.rig.yaml
passes:
  world: $SRC/tests/validate/data/world.frag
axes:
  morph_targets: [52, 2]
validate: { poses: 2, validation_layers: false }
EOF
  expect 0 "build --validate, level-of-detail variants of a sparse rig" -- "$SG" build lod.yaml
  grep -q "validated on llvmpipe.*: 2 run" last.out && ok "both levels validated" || fail "build printed: $(tail -3 last.out)"
  # Two builds at once sharing one cache directory: both succeed, same bytes.
  "$SG" build m.yaml -o c1 --cache-dir shared -q & p1=$!
  "$SG" build m.yaml -o c2 --cache-dir shared -q & p2=$!
  wait $p1 && wait $p2 && ok "two concurrent builds sharing a cache succeed" || fail "concurrent builds failed"
  diff -r -x .shadergen-cache -x "*.d" c1 c2 >/dev/null && ok "concurrent builds wrote the same bytes" ||
    fail "concurrent outputs differ"
  no_temps shared
  # Progress only on request when stderr is not a terminal.
  CI=1 "$SG" build m.yaml -o c3 2>err.txt >/dev/null
  [ ! -s err.txt ] && ok "quiet stderr in CI" || fail "stderr in CI: $(cat err.txt)"
  "$SG" build m.yaml -o c3 --progress 2>err.txt >/dev/null
  grep -q "\[6/6\]" err.txt && ok "--progress shows [6/6]" || fail "no progress: $(cat err.txt)"
  # Errors: located, exit 1, no index.
  printf 'rules: r.yaml\nrigs:\n  face: face.rig.yaml\npasses:\n  color: c.frag\naxes:\n  rig: [face, bdy]\n' >bad.yaml
  expect 1 "unknown rig in an axis" -- "$SG" build bad.yaml
  grep -q "bad.yaml:7:3: error: axis 'rig': no rig named 'bdy'" last.err && ok "located manifest error" ||
    fail "manifest error: $(cat last.err)"
  sed 's/influences: \[4, 1\]/influences: [4, 9]/' m.yaml >nine.yaml
  expect 1 "a variant that cannot be made" -- "$SG" build nine.yaml -o bad-out
  grep -q "error: variant 'face-color-influences9' failed" last.err && ok "failed variant named" || fail "$(cat last.err)"
  [ ! -e bad-out/index.json ] && ok "no index after a failure" || fail "index written despite a failure"
  # One build edge per variant: --variant each, then --join, gives the whole build's index;
  # a failing variant names itself and leaves no entry; --join names what is missing or damaged.
  for v in $("$SG" build m.yaml --list); do "$SG" build m.yaml -o edges --variant "$v" -q || fail "--variant $v"; done
  expect 0 "--join" -- "$SG" build m.yaml -o edges --join
  cmp -s edges/index.json out/index.json && ok "--variant x6 + --join: the whole build's index" || fail "index differs"
  head -c 40 edges/.shadergen-variants/face-depth-influences1.entry >cut && mv cut edges/.shadergen-variants/face-depth-influences1.entry
  expect 1 "--join over a truncated entry" -- "$SG" build m.yaml -o edges --join
  grep -q "face-depth-influences1.entry: error: not an entry of variant 'face-depth-influences1'" last.err &&
    ok "truncated entry named" || fail "$(cat last.err)"
  echo stale >edges/.shadergen-variants/face-color-influences9.entry
  expect 1 "--variant of a variant that cannot be made" -- "$SG" build nine.yaml -o edges --variant face-color-influences9
  grep -q "error: variant 'face-color-influences9' failed" last.err && [ ! -e edges/.shadergen-variants/face-color-influences9.entry ] &&
    ok "failed variant named, no entry left" || fail "$(cat last.err)"
  expect 1 "--join without that entry" -- "$SG" build nine.yaml -o edges --join
  grep -q "variant 'face-color-influences9' has not been built" last.err && ok "missing entry named" || fail "$(cat last.err)"
  expect 1 "--variant with an unknown name" -- "$SG" build m.yaml --variant nope
  grep -q "m.yaml: error: no variant named 'nope'" last.err && ok "unknown variant named" || fail "$(cat last.err)"
  ;;

device_profile)
  # Without a profile: what generate always printed; with one: a dearer-per-location plan,
  # its prediction per term, the profile in the depfile, the prediction in the reflection.
  expect 0 "no profile" -- "$SG" generate "${DAWN[@]}" --emit glsl,reflection -o plain/face
  grep -q "total cost 97$" last.out && ok "slot model total cost 97" || fail "no-profile plan: $(cat last.out)"
  grep -q "predicted" last.out && fail "prediction printed without a profile" || ok "no prediction without a profile"
  grep -q predicted_cost plain/face.json && fail "predicted_cost without a profile" || ok "reflection unchanged"
  P=$SRC/devices/example.yaml
  expect 0 "--device-profile" -- "$SG" generate "${DAWN[@]}" --emit glsl,reflection -o prof/face -MD --device-profile "$P"
  grep -q "fs per vertex, device profile" last.out && ok "cost in femtoseconds" || fail "$(cat last.out)"
  grep -qE "^    locations +[0-9]+ +0\.570000 " last.out && ok "locations priced at 0.57 ns" || fail "$(cat last.out)"
  grep -qE "^    total +[0-9.]+$" last.out && ok "predicted total printed" || fail "$(cat last.out)"
  grep -qF "$(realpath -ms "$P")" prof/face.vert.d && ok "depfile lists the profile" || fail "$(cat prof/face.vert.d)"
  grep -q '"predicted_cost": {"device": ' prof/face.json && ok "reflection has the prediction" || fail "$(cat prof/face.json)"
  cmp -s plain/face.vert prof/face.vert && fail "the profile did not change the plan" || ok "the profile changes the plan"
  expect 0 "explain --device-profile" -- "$SG" explain "${DAWN[@]}" --device-profile "$P" --no-alternatives
  grep -q "predicted per vertex on 'example" last.out && ok "explain shows the terms" || fail "$(cat last.out)"
  grep -qE "^    buffer_loads +[1-9]" last.out && ok "explain: buffer loads counted" || fail "$(cat last.out)"
  # explain shows the plan generate writes: under the device limits given (a 300-bone palette fits
  # a 64 KiB uniform block, not the default 16 KiB one) and under several profiles (the least
  # worst-case regret, not the first profile's own plan).
  rulesOf() { grep -oE "$1" last.out | awk '{print $NF}' | sort -u; }
  V=$SRC/tests/validate/data
  for case in "limits" "portable"; do
    if [ $case = limits ]; then args=(--rig "$V/limb8_palette300.rig.yaml" -f "$V/world.frag" -r "$SRC/rules/standard.yaml" --max-uniform-bytes 65536)
    else args=("${DAWN[@]}" --device-profile "$SRC/devices/nvidia-h200-raster.yaml" --device-profile "$SRC/devices/llvmpipe-2core.yaml"); fi
    expect 0 "generate ($case)" -- "$SG" generate "${args[@]}" -o explained/$case
    rulesOf '^ +[0-9]+\. [a-z_0-9]+' > explained-$case-generate.txt
    expect 0 "explain ($case)" -- "$SG" explain "${args[@]}" --no-alternatives
    rulesOf '<- [a-z_0-9]+' > explained-$case-explain.txt
    [ -s explained-$case-generate.txt ] && cmp -s explained-$case-generate.txt explained-$case-explain.txt &&
      ok "explain shows generate's plan ($case)" || fail "explain ($case): $(diff explained-$case-generate.txt explained-$case-explain.txt)"
  done
  grep -qx skin_matrix_blend explained-limits-generate.txt && ok "the 64 KiB block holds the palette" || fail "$(cat explained-limits-generate.txt)"
  # A profile with per-draw weights prices its own workload, or the vertices a draw is said to have.
  H=$SRC/devices/nvidia-h200.yaml
  expect 0 "explain, H200 profile" -- "$SG" explain "${DAWN[@]}" --device-profile "$H" --no-alternatives
  grep -q "at 180000 vertices per draw:" last.out && ok "the profile's workload" || fail "$(cat last.out)"
  dawn_total=$(awk '$1 == "total" && NF == 2 {print $2}' last.out)
  expect 0 "explain --vertices 2010" -- "$SG" explain "${DAWN[@]}" --device-profile "$H" --no-alternatives --vertices 2010
  grep -q "at 2010 vertices per draw:" last.out && ok "--vertices sets the workload" || fail "$(cat last.out)"
  head_total=$(awk '$1 == "total" && NF == 2 {print $2}' last.out)
  awk -v a="$dawn_total" -v b="$head_total" 'BEGIN {exit !(b > a + 0.1)}' && ok "a small draw pays more per vertex ($dawn_total -> $head_total ns)" ||
    fail "per-vertex prediction $dawn_total at 180000, $head_total at 2010"
  # SIGINT stops calibrate's timing and keeps what was timed (a fitted profile and a note), or,
  # before anything was timed, fails saying so: never a death by the signal (exit 130). Dawn scale
  # after the head, 10 rounds, keeps it timing well past the signal on any machine (one round of
  # the head alone took 4.2 s here, and the signal at 4 s sometimes came after the end); the
  # signal ends the rounds, so they cost nothing.
  "$SG" calibrate "${DAWN[@]}" --meshes head,dawn --draws 2 --frames 2 --rounds 10 --no-validation-layers -o int.yaml \
    >int.out 2>int.err &
  pid=$!
  sleep 4
  kill -INT "$pid"
  wait "$pid"
  rc=$?
  interrupted_calibration "$rc" int "calibrate, interrupted"
  # `timeout -s INT` (the bench scripts' time limits) signals the command and then its process
  # group: two SIGINTs a moment apart are one interrupt, not the second that ends the process
  # (ending on timeout's copy lost every timed sample, bench/data/h200-linear-blend13).
  "$SG" calibrate "${DAWN[@]}" --meshes head,dawn --draws 2 --frames 2 --rounds 10 --no-validation-layers -o int2.yaml \
    >int2.out 2>int2.err &
  pid=$!
  sleep 4
  kill -INT "$pid"
  sleep 0.2
  kill -INT "$pid" 2>/dev/null
  wait "$pid"
  rc=$?
  interrupted_calibration "$rc" int2 "calibrate, SIGINT twice within a second (one interrupt)"
  # Offline refit from a recorded log: the device (a driver name holding parentheses of its own)
  # and the fit are read back, the profile loads, and --evaluate checks held-out logs by name.
  LP=$SRC/bench/data/lavapipe-heldout
  expect 0 "calibrate --from-log (no device)" -- "$SG" calibrate --from-log "$LP/train.log" --check-log "$LP/pbr.log" \
    --form additive --near-best-weight 0 -o refit.yaml
  grep -qx 'device: "llvmpipe (LLVM 15.0.6, 256 bits) (llvmpipe Mesa 22.3.6 (LLVM 15.0.6))"' refit.yaml &&
    ok "the log's device and driver, whole" || fail "device line: $(grep '^device' refit.yaml)"
  grep -q "^held-out check over 4 (rig, mesh) pairs" last.out && ok "the held-out check of the pbr log's four pairs" ||
    fail "$(grep held-out last.out)"
  expect 0 "generate under the refitted profile" -- "$SG" generate "${DAWN[@]}" --device-profile refit.yaml -o refit --emit glsl
  expect 0 "calibrate --evaluate" -- "$SG" calibrate --evaluate refit.yaml --check-log "$LP/world.log"
  grep -q "^| limb8_palette300.rig.yaml | head | 6 |" last.out && ok "--evaluate lists each held-out pair" || fail "$(tail -5 last.out)"
  # --write-corpus: the random rigs and requests of a seed as files, without a device; the same
  # seed writes the same bytes, and each case generates with the vocabulary's rules.
  expect 0 "calibrate --write-corpus" -- "$SG" calibrate --corpus 3 --seed 5 --write-corpus corpus5
  [ "$(wc -l < last.out)" -eq 3 ] && [ "$(ls corpus5 | wc -l)" -eq 6 ] && ok "three cases, a rig and a request each" ||
    fail "--write-corpus wrote: $(ls corpus5 | tr '\n' ' ')"
  "$SG" calibrate --corpus 3 --seed 5 --write-corpus corpus5b >/dev/null && diff -r corpus5 corpus5b >/dev/null &&
    ok "the same seed, the same files" || fail "--write-corpus is not deterministic"
  read -r crig cfrag < <(head -1 last.out)
  expect 0 "a written case generates" -- "$SG" generate --rig "$crig" -f "$cfrag" -r "$SRC/examples/dawn/rules.yaml" \
    --templates "$SRC/templates" -o corpus-case --emit glsl
  expect 2 "--write-corpus without --corpus (a usage error)" -- "$SG" calibrate --write-corpus corpus6
  # --plans-under: each rig's plan under that profile is timed too, with its forced alternatives, so
  # a held-out log holds the plan the profile would choose. Of seed 4242's first two rigs, the H200
  # profile moves at least one plan away from the instruction-slot plan (it reads the skin from buffers).
  PU=(--no-probes --corpus 2 --seed 4242 --meshes head -r "$SRC/examples/dawn/rules.yaml" --templates "$SRC/templates"
      --no-check --refits 0 --frames 1 --rounds 1 --draws 1 --min-frame-vertices 0)
  expect 0 "calibrate --plans-under --processes 2" -- "$SG" calibrate "${PU[@]}" --plans-under "$SRC/devices/nvidia-h200-raster.yaml" \
    --processes 2 -o pu.yaml
  grep -q "^device: .*best of 1 rounds in each of 2 processes" last.out && ok "calibrate --processes 2: each rig's rounds from 2 processes" ||
    fail "calibrate --processes: $(head -1 last.out)"
  generated() { grep -E "^\| head \| $1 \| $2 \|" last.out | cut -d'|' -f5-13; }
  # The label names the profile by its file's stem and the first 12 hex digits of its SHA-256.
  fp=$(sha256sum "$SRC/devices/nvidia-h200-raster.yaml" | cut -c1-12)
  rigs=$(grep -oE '^\| head \| corpus-[0-9]+\.rig\.yaml \| plan: generated' last.out | cut -d'|' -f3 | tr -d ' ')
  both=0 moved=0
  for r in $rigs; do
    a=$(generated "$r" "plan: generated") b=$(generated "$r" "plan under nvidia-h200-raster@$fp: generated")
    [ -n "$a" ] && [ -n "$b" ] && both=$((both + 1))
    [ -n "$b" ] && [ "$a" != "$b" ] && moved=$((moved + 1))
  done
  [ "$both" -eq 2 ] && [ "$moved" -ge 1 ] && ok "each rig's plan timed under both ($moved moved by the profile)" ||
    fail "rigs with both plans: $both, moved: $moved; $(grep -c 'plan under' last.out) rows under the profile"
  cp last.out pu.log
  expect 0 "the log reads back, its plans under the profile among them" -- "$SG" calibrate --from-log pu.log
  n=$(grep -c "| plan under nvidia-h200-raster@$fp: " pu.log)
  grep -q "^fit on 'head': $(grep -cE '^\| head \| corpus-.* \| [0-9]+\.[0-9]+ \|' pu.log) samples" last.out && [ "$n" -ge 3 ] &&
    ok "every timed row fitted, the $n under the profile too" || fail "$(grep "^fit on" last.out); $n rows under the profile"
  # --evaluate counts each rig's own plan where the log timed it under this very profile; the
  # profile changed by one comment line, under the same name, is another profile: none is its own.
  expect 0 "--evaluate the profile on its own plans" -- "$SG" calibrate --evaluate "$SRC/devices/nvidia-h200-raster.yaml" --check-log pu.log
  own=$(grep -c '(its plan)' last.out)
  mkdir -p edited && { cat "$SRC/devices/nvidia-h200-raster.yaml"; echo "# edited"; } > edited/nvidia-h200-raster.yaml
  expect 0 "--evaluate an edited profile of the same name" -- "$SG" calibrate --evaluate edited/nvidia-h200-raster.yaml --check-log pu.log
  [ "$own" -eq 2 ] && ! grep -q '(its plan)' last.out && ok "its own plan counted in 2 pairs, an edited profile's in none" ||
    fail "own plans: $own under the profile, $(grep -c '(its plan)' last.out) under the edited one"
  # --per-plan lists each pair's plans: as many rows as the pairs' plan counts add up to, one chosen per pair.
  expect 0 "--evaluate --per-plan" -- "$SG" calibrate --evaluate "$SRC/devices/nvidia-h200-raster.yaml" --check-log pu.log --per-plan
  pairs=$(sed -n '/^held-out check:/,/^held-out check over/p' last.out | grep -E '^\| corpus-' | wc -l)
  plans=$(sed -n '/^held-out check:/,/^held-out check over/p' last.out | grep -E '^\| corpus-' | awk -F'|' '{ n += $4 } END { print n }')
  rows=$(sed -n '/^held-out check, every plan/,$p' last.out | grep -cE '^\| corpus-')
  chosen=$(sed -n '/^held-out check, every plan/,$p' last.out | grep -c '| chosen (its plan)')
  [ "$pairs" -eq 2 ] && [ "$rows" -eq "$plans" ] && [ "$chosen" -eq 2 ] && ok "every plan listed ($rows), each pair's own plan marked" ||
    fail "pairs $pairs, plans $plans, rows $rows, chosen $chosen"
  # A refit's leave-one-rig-out lists its plans too, one chosen per pair; without the flag, no plan table.
  expect 0 "--from-log --per-plan" -- "$SG" calibrate --from-log pu.log --per-plan
  pairs=$(sed -n '/^leave-one-rig-out:/,/^leave-one-rig-out over/p' last.out | grep -E '^\| corpus-' | wc -l)
  chosen=$(sed -n '/^leave-one-rig-out, every plan/,$p' last.out | grep -cE '\| chosen( \(its plan\))?( \||, )')
  [ "$pairs" -eq 2 ] && [ "$chosen" -eq 2 ] && ok "the leave-one-rig-out's plans listed, one chosen a pair" ||
    fail "pairs $pairs, chosen $chosen"
  "$SG" calibrate --from-log pu.log | grep -q "every plan" && fail "a plan table without --per-plan" || ok "no plan table without --per-plan"
  # --outside-pipes: the raster form prices locations and buffer loads outside the pipes too by
  # default; "none" is the form before (every term inside its pipe); names are checked.
  expect 0 "--outside-pipes none" -- "$SG" calibrate --from-log pu.log --form raster --outside-pipes none -o inside.yaml
  expect 0 "the raster form's default" -- "$SG" calibrate --from-log pu.log --form raster -o outside.yaml
  grep -qx '# form: raster (outside the pipes too: locations, buffer_loads, buffer_vec4_loads)' outside.yaml &&
    grep -qx '# form: raster' inside.yaml && ok "each profile's header says what it priced outside the pipes" ||
    fail "$(grep '^# form' outside.yaml inside.yaml)"
  awk '/^weights:/{w=1} /^pipes:/{w=0} w && /^  locations:/{print $2}' inside.yaml | grep -qx 0 &&
    ok "none: locations priced in the fetch pipe only" || fail "$(grep -A3 '^weights' inside.yaml)"
  expect 2 "--outside-pipes an unknown term" -- "$SG" calibrate --from-log pu.log --form raster --outside-pipes locations,bogus
  grep -q "'bogus' is not a term any pipe of the raster form prices" last.err && ok "names the term" || fail "$(cat last.err)"
  expect 2 "--outside-pipes with the additive form" -- "$SG" calibrate --from-log pu.log --outside-pipes locations
  # --threshold TERM: a price per unit past a threshold the fit chooses; --no-floors fits the probes and
  # plans only. On lavapipe's training log of session 17 (its probes and four of its rigs, for time: the
  # fit runs once per rig left out) the inputs past 15 cost more, and under that profile the Dawn face
  # reads its skin from a storage buffer: the plan lavapipe runs fastest (docs/device-profiles.md, "A
  # price past a threshold").
  LP=$SRC/bench/data/lavapipe-rounds17/train.log
  awk '!/^\|/ || /^\| mesh \|/ { print; t = /^\| mesh \|/; next } t && /^\|---/ { print; t = 0 }
       /^\| (dawn|head) \| (—|face.rig.yaml|face-packed.rig.yaml|corpus-4282876139.rig.yaml|corpus-550290313.rig.yaml) \|/' "$LP" > lp.log
  expect 0 "--threshold locations --no-floors" -- "$SG" calibrate --from-log lp.log --threshold locations --no-floors --near-best-weight 0 -o past.yaml
  grep -q "^  locations: { at: [0-9]*, ns: [0-9.]* }$" past.yaml && grep -q "(not the floors': --no-floors)" past.yaml &&
    ok "the profile states the threshold and that the floors were left out" || fail "$(grep -A2 '^thresholds' past.yaml)"
  expect 0 "explain the Dawn face under it" -- "$SG" explain --rig "$SRC/examples/dawn/face.rig.yaml" -f "$SRC/examples/dawn/face.frag" -r "$SRC/examples/dawn/rules.yaml" --device-profile past.yaml --mesh dawn
  grep -q "skin.matrix <- skin_matrix_blend_buffered_influences" last.out && grep -q "locations past " last.out &&
    ok "the skin from a storage buffer, the threshold's line shown" || fail "$(grep -E 'skin.matrix <-|past' last.out)"
  expect 2 "--threshold an unknown term" -- "$SG" calibrate --from-log "$LP" --threshold bogus
  grep -q "'bogus' is not a term a threshold may price" last.err && ok "names the term" || fail "$(cat last.err)"
  expect 2 "--threshold vertices" -- "$SG" calibrate --from-log "$LP" --threshold vertices
  printf 'device: "x"\nweights: [1\n' > bad-profile.yaml
  expect 1 "--plans-under a malformed profile" -- "$SG" calibrate "${PU[@]}" --plans-under bad-profile.yaml
  grep -q '^bad-profile.yaml:[0-9]*:[0-9]*: error' last.err && ! grep -q 'corpus-' last.out &&
    ok "its located error, before any rig is timed" || fail "printed: $(head -3 last.err) / $(head -3 last.out)"
  expect 2 "--plans-under without rigs (a usage error)" -- "$SG" calibrate --plans-under "$SRC/devices/nvidia-h200-raster.yaml"
  # render MODEL.glb#* under a profile prices each primitive for its own mesh, as MODEL.glb#m/p
  # does (CesiumMan has one primitive; its palette loads are priced per joint a warp reads).
  CESIUM=$SRC/../shared/models/CesiumMan/CesiumMan.glb
  if [ -f "$CESIUM" ]; then
    RC=(-f "$SRC/tests/gltf/data/lit.frag" -r "$SRC/rules/standard.yaml" --device-profile "$SRC/devices/nvidia-h200-roofline.yaml"
        --no-validation-layers --size 16x16)
    expect 0 "render MODEL.glb#0/0 under a profile" -- "$SG" render --rig "$CESIUM#0/0" "${RC[@]}" -o cesium1.png
    one=$(grep -o "plan cost [0-9]*" last.out)
    expect 0 "render MODEL.glb#* under a profile" -- "$SG" render --rig "$CESIUM#*" "${RC[@]}" -o cesium2.png
    all=$(grep -o "plan cost [0-9]*" last.out)
    [ -n "$one" ] && [ "$one" = "$all" ] && ok "render #* prices the part as #0/0 does ($one)" || fail "#0/0: '$one', #*: '$all'"
  fi
  # A rig storing its frame both ways: every command that generates says which form it reads.
  V=$SRC/tests/validate/data
  FORMS=(--rig "$V/octahedral_or_float.rig.yaml" -f "$V/world.frag" -r "$SRC/rules/standard.yaml" --mesh limb
         --device-profile "$SRC/devices/nvidia-h200.yaml" --no-validation-layers)
  expect 0 "render, both forms stored" -- "$SG" render "${FORMS[@]}" -o forms.png
  grep -q "note: vertex.normal: the plan reads vertex.normal_octahedral" last.err && ok "render names the form read" ||
    fail "render notes: $(cat last.err)"
  expect 0 "bench, both forms stored" -- "$SG" bench "${FORMS[@]}" --no-alternatives --draws 1 --frames 1 --raster on
  grep -q "note: vertex.tangent: the plan reads vertex.tangent_octahedral" last.err && ok "bench names the form read" ||
    fail "bench notes: $(cat last.err)"
  ;;

pack)  # docs/rig-format.md "Packing": the streams and their layout, byte-identical reruns
  OCT=(--rig "$SRC/tests/validate/data/octahedral.rig.yaml" -f "$SRC/tests/validate/data/world.frag"
       -r "$SRC/rules/standard.yaml")
  for d in a b; do
    expect 0 "pack into $d" -- "$SG" pack "${OCT[@]}" --mesh limb -o "$d/limb" -q
  done
  cmp -s a/limb.bin b/limb.bin && ok "identical streams" || fail "limb.bin differs between runs"
  cmp -s a/limb.json b/limb.json && ok "identical layout" || fail "limb.json differs between runs"
  # The layout accounts for every byte: the last stream ends where the file does.
  size=$(stat -c %s a/limb.bin)
  grep -q "\"bytes\": $size," a/limb.json && ok "layout states the file's $size bytes" || fail "bytes != $size"
  grep -q '"encoding": "octahedral"' a/limb.json && ok "layout names the encoding" || fail "no encoding in the layout"
  # A model without the data a stream needs: an error, and nothing written.
  expect 1 "pack a model lacking normals" -- "$SG" pack "${OCT[@]}" --model "$SRC/tests/gltf/data/gltfpack/SimpleSkin.glb#0/0" -o c/x -q
  grep -q "octahedral.rig.yaml:12:3: error: mesh 'SimpleSkin/0/0' has no data for 'vertex.normal_octahedral'" last.err &&
    ok "the error names the stream" || fail "$(cat last.err)"
  [ ! -e c ] && ok "nothing written on failure" || fail "pack left $(ls c)"
  expect 2 "--mesh and --model together" -- "$SG" pack "${OCT[@]}" --mesh limb --model x.glb#0/0 -o d/x -q
  # validate checks the stored streams twice (docs/validation.md, "Against the float data").
  expect 0 "validate the packed rig" -- "$SG" validate "${OCT[@]}" --mesh limb --poses 1 --no-validation-layers
  grep -qE "^  ok +vs float data: max dev .* tolerance/observed" last.out && ok "validate checks against the float data" ||
    fail "validate printed: $(head -6 last.out)"
  expect 0 "validate --no-float-check" -- "$SG" validate "${OCT[@]}" --mesh limb --poses 1 --no-validation-layers --no-float-check
  grep -q "vs float data" last.out && fail "--no-float-check still checked" || ok "--no-float-check skips the second check"
  ;;

fresh_process)
  # calibrate and bench MODEL.glb#* time each rig in a fresh shadergen process unless --one-process
  # (docs/device-profiles.md, "One process per rig"): the same programs, validated alike, either way,
  # and a rig's input error comes back from its process as the error one process gives.
  CESIUM=$SRC/../shared/models/CesiumMan/CesiumMan.glb
  FIGURE=$SRC/../shared/models/RiggedFigure/RiggedFigure.glb
  [ -f "$CESIUM" ] && [ -f "$FIGURE" ] || { echo "skipped: ../shared/models lacks CesiumMan or RiggedFigure"; exit 0; }
  TIMING=(--no-validation-layers --draws 1 --frames 1 --rounds 1 --refits 0 --no-check --no-probes)
  RIGS=(--rig "$CESIUM#0/0" --rig "$FIGURE#*" -f "$SRC/tests/gltf/data/lit.frag" -r "$SRC/rules/standard.yaml")
  mkdir -p reports  # where the processes' reports pass: none may be left there
  expect 0 "calibrate, a fresh process per rig" -- env TMPDIR="$T/reports" "$SG" calibrate "${TIMING[@]}" "${RIGS[@]}" -o fresh.yaml
  mv last.out fresh.out
  expect 0 "calibrate --one-process" -- "$SG" calibrate "${TIMING[@]}" "${RIGS[@]}" --one-process -o one.yaml
  # Mesh, rig, program and every term's amount (the columns before the times) agree row by row.
  programs() { grep -E '^\| own \|' "$1" | cut -d'|' -f2-14; }
  n=$(programs fresh.out | wc -l)
  [ "$n" -ge 10 ] && cmp -s <(programs fresh.out) <(programs last.out) && ok "the same $n programs timed either way" ||
    fail "fresh: $n rows; diff: $(diff <(programs fresh.out) <(programs last.out) | head -5)"
  [ -z "$(ls reports)" ] && ok "no report file left behind" || fail "left behind: $(ls reports)"
  # A given rig whose request cannot be met: the located error, and exit 1, as in one process.
  BAD=(--rig "$SRC/tests/bad-input/base/tiny.rig.yaml" -f "$SRC/tests/bad-input/fragment/not_a_semantic/x.frag"
       -r "$SRC/tests/bad-input/base/tiny.rules.yaml" --meshes head)
  expect 1 "calibrate, a rig that cannot be generated, in its process" -- "$SG" calibrate "${TIMING[@]}" "${BAD[@]}"
  mv last.err fresh.err
  expect 1 "the same with --one-process" -- "$SG" calibrate "${TIMING[@]}" "${BAD[@]}" --one-process
  grep -q ': error: ' fresh.err && cmp -s fresh.err last.err && ok "the same error either way: $(head -1 fresh.err)" ||
    fail "fresh: $(head -3 fresh.err); one process: $(head -3 last.err)"
  # An interrupt sent to the whole process group (`timeout -s INT`, Ctrl-C) reaches the rig's
  # process too: it finishes its rig, and the calibration fits what was timed, as in one process.
  # The head alone, 5 rounds: the process timing at the signal finishes all its rounds (at Dawn
  # scale that took 35 s here, 46 s under the sanitizers). Uninterrupted, this run (a process
  # timing the rig, then one checking the fit) takes 9 s on 2 cores, so the signal comes mid-run.
  setsid "$SG" calibrate "${DAWN[@]}" --meshes head --draws 2 --frames 2 --rounds 5 --no-probes \
    --no-validation-layers -o group.yaml >group.out 2>group.err &
  pid=$!
  sleep 4
  kill -INT -- "-$pid"
  wait "$pid"
  rc=$?
  interrupted_calibration "$rc" group "calibrate, the process group interrupted (the rig's process finishes its rig)"
  # bench MODEL.glb#*: each part's table, the same programs and verdicts.
  BENCH=(--rig "$FIGURE#*" -f "$SRC/tests/gltf/data/lit.frag" -r "$SRC/rules/standard.yaml" --no-validation-layers
     --draws 1 --frames 1 --rounds 1 --raster on)
  expect 0 "bench MODEL.glb#*, a fresh process per part" -- "$SG" bench "${BENCH[@]}"
  mv last.out bench-fresh.out
  expect 0 "bench MODEL.glb#* --one-process" -- "$SG" bench "${BENCH[@]}" --one-process
  verdicts() { grep -E '^(## |\| (generated|forced|floor))' "$1" | cut -d'|' -f1-3; }
  n=$(verdicts bench-fresh.out | grep -c '| pass')
  [ "$n" -ge 2 ] && cmp -s <(verdicts bench-fresh.out) <(verdicts last.out) && ok "bench: the same parts and $n passing programs either way" ||
    fail "bench: $(diff <(verdicts bench-fresh.out) <(verdicts last.out) | head -5)"
  ;;

pin)
  # A measured choice (docs/performance.md, "A measured choice"): bench --candidates K times the K plans
  # cheapest under a profile on lavapipe and pins the fastest; generate --pin writes that plan without
  # the device, under any profile or none; a pin the inputs no longer give is a located error.
  BENCH=("${DAWN[@]}" --device-profile "$SRC/devices/llvmpipe-2core.yaml" --mesh head --raster off --draws 1
         --min-frame-vertices 0 --frames 2 --rounds 1 --no-floor --no-validation-layers)
  expect 0 "bench --candidates 3 --pin-out" -- "$SG" bench "${BENCH[@]}" --candidates 3 --max-candidates 3 --pin-out face.pin.yaml
  mv last.out bench.out
  rows=$(grep -cE '^\| (generated|cheapest plan #[0-9]+) \| pass' bench.out)
  [ "$rows" -eq 3 ] && ok "bench: 3 candidates timed, each validated" || fail "bench: $rows candidates passed, expected 3: $(cat bench.out)"
  label=$(sed -n 's/^plan: "\(.*\)"$/\1/p' face.pin.yaml)
  grep -q "^fastest validated plan (.*): \(the generated one\|$label\)" bench.out && [ -n "$label" ] &&
    ok "one round: the pin is bench's fastest ($label)" || fail "pin plan '$label' is not bench's fastest: $(grep fastest bench.out)"
  # The rules the generated GLSL names (one comment per rule) are the pin's, with or without a profile.
  glsl_rules() { sed -n 's|^  // \([a-z0-9_]*\) -> .*|\1|p' "$1" | sort -u | tr '\n' ' '; }
  pin_rules=$(sed -n 's/^rules: \[\(.*\)\]$/\1/p' face.pin.yaml | tr -d ',"' | tr ' ' '\n' | sort -u | tr '\n' ' ')
  for profile in "" "$SRC/devices/nvidia-h200-raster.yaml"; do
    args=(); [ -n "$profile" ] && args=(--device-profile "$profile" --mesh dawn)
    expect 0 "generate --pin ${profile:+under another profile}" -- "$SG" generate "${DAWN[@]}" --pin face.pin.yaml "${args[@]}" --emit glsl -o pinned.vert -q
    [ -s last.err ] && fail "generate --pin printed: $(cat last.err)"
    [ "$(glsl_rules pinned.vert)" = "$pin_rules" ] && ok "generate --pin ${profile:+(another profile) }writes the pinned plan" ||
      fail "generate --pin: rules $(glsl_rules pinned.vert), pinned $pin_rules"
    [ -z "$profile" ] && cp pinned.vert pinned-slots.vert
  done
  expect 0 "generate --pin again" -- "$SG" generate "${DAWN[@]}" --pin face.pin.yaml --emit glsl -o again.vert -q
  cmp -s pinned-slots.vert again.vert && ok "generate --pin: two runs, the same bytes" || fail "generate --pin: two runs differ"
  # Several devices (docs/performance.md, "Several devices"): each device's pin lists every plan it timed;
  # pin merge keeps the plan whose worst time over a device's fastest is least. Two benches here stand for
  # two devices; the choice is checked against the regrets worked out from the two files' timed plans.
  timed_plans() { sed -n 's/^  - {plan: "\([^"]*\)", program: "\([0-9a-f]*\)", ns_per_vertex: \([0-9.e+-]*\),.*/\1|\2|\3/p' "$1"; }
  [ "$(timed_plans face.pin.yaml | wc -l)" -eq 3 ] && grep -q "^$label|" <(timed_plans face.pin.yaml) &&
    ok "the pin lists the 3 plans bench timed, the pinned one among them" || fail "timed plans: $(timed_plans face.pin.yaml)"
  expect 0 "bench --candidates 3 --pin-out, a second 'device'" -- "$SG" bench "${BENCH[@]}" --candidates 3 --max-candidates 3 --pin-out second.pin.yaml
  expect 0 "pin merge" -- "$SG" pin merge face.pin.yaml second.pin.yaml -o both.pin.yaml
  want=$(awk -F'|' 'FNR == 1 { f++ } { t[f, $2] = $3; if (!(f in best) || $3 < best[f]) best[f] = $3; if (f == 1) order[++n] = $1 "|" $2 }
    END { w = 1e300; for (i = 1; i <= n; i++) { split(order[i], o, "|"); r = 0; ok = 1
            for (d = 1; d <= f; d++) { if (!((d, o[2]) in t)) ok = 0; else if (t[d, o[2]] / best[d] > r) r = t[d, o[2]] / best[d] }
            if (ok && r < w) { w = r; pick = o[1] } } print pick }' <(timed_plans face.pin.yaml) <(timed_plans second.pin.yaml))
  [ -n "$want" ] && grep -q "^plan: \"$want\"$" both.pin.yaml && [ "$(grep -c '^  - device: "llvmpipe' both.pin.yaml)" -eq 2 ] &&
    grep -q '^candidates: 3$' both.pin.yaml && [ "$(grep -c '^| llvmpipe .* | [0-9.]* | [0-9.]* | [0-9.]* |$' last.out)" -eq 2 ] &&
    ok "pin merge: the least worst regret over both ($want), each device's row printed" ||
    fail "pin merge: want '$want': $(cat both.pin.yaml last.out | head -20)"
  merged_rules=$(sed -n 's/^rules: \[\(.*\)\]$/\1/p' both.pin.yaml | tr -d ',"' | tr ' ' '\n' | sort -u | tr '\n' ' ')
  expect 0 "generate --pin, a merged pin" -- "$SG" generate "${DAWN[@]}" --pin both.pin.yaml --emit glsl -o both.vert -q
  [ -n "$merged_rules" ] && [ "$(glsl_rules both.vert)" = "$merged_rules" ] && ok "generate --pin writes the merged pin's plan" ||
    fail "merged pin: rules $(glsl_rules both.vert), pinned $merged_rules"
  expect 1 "pin merge, a merged pin again" -- "$SG" pin merge both.pin.yaml face.pin.yaml -o again.pin.yaml
  grep -q "^both.pin.yaml:3:1: error: pin merge: a merged pin is not merged again" last.err && [ ! -e again.pin.yaml ] &&
    ok "pin merge: a merged pin is a located error, nothing written" || fail "merge of a merged pin: $(cat last.err)"
  # Under a portable objective (two profiles) the candidates hold each device's own cheapest plan too,
  # as generate under that profile alone writes it, so a merge can weigh it.
  PORTABLE=(--rig "$SRC/tests/validate/data/limb8_palette300.rig.yaml" -f "$SRC/tests/validate/data/world.frag" -r "$SRC/rules/standard.yaml"
            --device-profile "$SRC/devices/nvidia-h200-raster.yaml" --device-profile "$SRC/devices/llvmpipe-2core.yaml" --mesh head)
  expect 0 "bench --candidates 2, a portable objective" -- "$SG" bench "${PORTABLE[@]}" --raster off --draws 1 --min-frame-vertices 0 \
    --frames 2 --rounds 1 --no-floor --no-validation-layers --candidates 2 --max-candidates 2 --pin-out portable.pin.yaml
  timed_rules() { sed -n 's/^  - {plan: .*, rules: \[\([^]]*\)\], ban: .*/\1/p' "$1" | while read -r r; do echo "$r" | tr -d ',"' | tr ' ' '\n' | sort -u | tr '\n' ' '; echo; done; }
  for profile in llvmpipe-2core nvidia-h200-raster; do
    expect 0 "generate under $profile alone" -- "$SG" generate --rig "$SRC/tests/validate/data/limb8_palette300.rig.yaml" \
      -f "$SRC/tests/validate/data/world.frag" -r "$SRC/rules/standard.yaml" --device-profile "$SRC/devices/$profile.yaml" --mesh head --emit glsl -o alone.vert -q
    timed_rules portable.pin.yaml > timed.txt  # a file: grep -q closing a pipe early fails it under pipefail
    grep -qxF "$(glsl_rules alone.vert)" timed.txt && ok "portable candidates: $profile's own cheapest was timed" ||
      fail "portable candidates lack $profile's cheapest: $(glsl_rules alone.vert) not in $(cat timed.txt)"
  done
  # The H200's own cheapest is the portable plan here, found by another search: timed once.
  [ "$(wc -l < timed.txt)" -ge 2 ] && [ -z "$(sort timed.txt | uniq -d)" ] && ok "portable candidates: no plan timed twice" ||
    fail "portable candidates: a plan timed twice: $(sort timed.txt | uniq -d)"
  # A manifest's variant pinned the same way (pins: { variant: file }): generate --pin's program.
  cat > pins.variants.yaml <<YAML
rules: $E/rules.yaml
output: built
rigs: { face: $E/face.rig.yaml }
passes: { color: $E/face.frag }
pins: { face-color: face.pin.yaml }
YAML
  expect 0 "build, a pinned variant" -- "$SG" build pins.variants.yaml -q --no-cache
  cmp -s built/face-color.vert pinned-slots.vert && grep -q '"pin": {"file": "face.pin.yaml"' built/index.json &&
    ok "a manifest's pin: the variant is generate --pin's program, index.json names the pin" ||
    fail "pinned variant: $(diff built/face-color.vert pinned-slots.vert | head -5) $(grep pin built/index.json)"
  # A byte the pin was not measured with: the same plan, written, with a warning at its inputs line.
  cp "$E/face.frag" edited.frag && echo "// edited" >> edited.frag
  expect 0 "generate --pin, the request edited" -- "$SG" generate --rig "$E/face.rig.yaml" -f edited.frag -r "$E/rules.yaml" --pin face.pin.yaml --emit glsl -o edited.vert -q
  grep -q "^face.pin.yaml:[0-9]*:[0-9]*: warning: the inputs' bytes differ" last.err && ok "an edited input is reported at the pin" ||
    fail "no warning for an edited input: $(cat last.err)"
  # Every command that reads the pin says so, the same way: explain, validate, and a manifest's build.
  EDITED=(--rig "$E/face.rig.yaml" -f edited.frag -r "$E/rules.yaml" --pin face.pin.yaml)
  expect 0 "explain --pin, the request edited" -- "$SG" explain "${EDITED[@]}" --no-alternatives
  grep -q "^face.pin.yaml:[0-9]*:[0-9]*: warning: the inputs' bytes differ" last.err && ok "explain: the edited input reported at the pin" ||
    fail "explain: no warning for an edited input: $(cat last.err)"
  expect 0 "validate --pin, the request edited" -- "$SG" validate "${EDITED[@]}" --mesh head --no-validation-layers
  grep -q "face.pin.yaml:[0-9]*:[0-9]*: warning: the inputs' bytes differ" last.out last.err && ok "validate: the edited input reported at the pin" ||
    fail "validate: no warning for an edited input: $(cat last.out last.err)"
  sed "s|passes: { color: $E/face.frag }|passes: { color: edited.frag }|" pins.variants.yaml > edited.variants.yaml
  expect 0 "build, a pinned variant's request edited" -- "$SG" build edited.variants.yaml -q --no-cache
  grep -q "face.pin.yaml:[0-9]*:[0-9]*: warning: variant 'face-color': the inputs' bytes differ" last.out last.err &&
    ok "build: the edited input reported at the pin" || fail "build: no warning for an edited input: $(cat last.out last.err)"
  # The pin no longer what the inputs give (a rule taken from its plan): a located error, nothing written.
  first=$(echo $pin_rules | cut -d' ' -f1)
  sed "s/^rules: \[\"$first\", /rules: [/" face.pin.yaml > stale.pin.yaml
  expect 1 "generate --pin, a stale pin" -- "$SG" generate "${DAWN[@]}" --pin stale.pin.yaml --emit glsl -o stale.vert -q
  grep -q "^stale.pin.yaml:[0-9]*:[0-9]*: error: the pinned plan is not what these inputs give under its bans (without: -; instead: $first)" last.err &&
    [ ! -e stale.vert ] && ok "a stale pin: located error, nothing written" || fail "stale pin: $(cat last.err)"
  expect 1 "explain --pin, a stale pin" -- "$SG" explain "${DAWN[@]}" --pin stale.pin.yaml --no-alternatives
  grep -q "^stale.pin.yaml:[0-9]*:[0-9]*: error: the pinned plan is not what these inputs give" last.err &&
    ok "explain: a stale pin is the same located error" || fail "explain, stale pin: $(cat last.err)"
  # A short list the objective cannot rank is widened: a profile that prices only a vertex location past
  # the 4th (1,000 ns each) puts limb8_palette300's two 4-location plans at 0.01 ns and its two 8-location
  # plans at 4,000 ns; lavapipe shows them within a few percent. --candidates 2 (the two 4-location
  # plans, predicted equal) times 2; --candidates 3 (an 8-location plan too: 4e7 % predicted, nothing
  # like it measured) times all 4 (--max-candidates 4), and the pin says so.
  cat > locations.device.yaml <<YAML
device: "llvmpipe"
unit: ns
weights: { vertices: 0.01 }
vertices_per_draw: 2009
thresholds:
  locations: { at: 4, ns: 1000 }
YAML
  V="$SRC/tests/validate/data"
  LIMB=(--rig "$V/limb8_palette300.rig.yaml" -f "$V/world.frag" -r "$SRC/rules/standard.yaml" --device-profile locations.device.yaml
        --mesh head --raster off --draws 1 --min-frame-vertices 0 --frames 2 --rounds 1 --no-floor --no-validation-layers)
  timed() { grep -cE '^\| (generated|cheapest plan #[0-9]+) \| pass' "$1"; }
  expect 0 "bench --candidates 2, predicted equal" -- "$SG" bench "${LIMB[@]}" --candidates 2 --max-candidates 4 --pin-out equal.pin.yaml
  [ "$(timed last.out)" -eq 2 ] && grep -q '^candidates: 2$' equal.pin.yaml && ! grep -q 'cannot rank' last.err &&
    ok "bench: candidates the objective prices alike are not widened" || fail "bench --candidates 2: $(cat last.err; cat equal.pin.yaml)"
  expect 0 "bench --candidates 3, an order the device does not show" -- "$SG" bench "${LIMB[@]}" --candidates 3 --max-candidates 4 --processes 2 --pin-out widened.pin.yaml
  [ "$(timed last.out)" -eq 4 ] && grep -q '^candidates: 4$' widened.pin.yaml &&
    grep -q "limb8_palette300.rig.yaml: note: the search's objective puts the 3 cheapest plans 4e+07 % apart and the device measured [0-9.e+-]* %: it cannot rank them here, so the 4 cheapest were timed" last.err &&
    grep -q 'best of 2 rounds in 2 processes' last.out &&
    ok "bench: an unranked short list widened to --max-candidates, in fresh processes, and pinned from all 4" ||
    fail "bench --candidates 3: $(timed last.out) timed; $(cat last.err; cat widened.pin.yaml)"
  expect 0 "bench --candidates 3 --max-candidates 3" -- "$SG" bench "${LIMB[@]}" --candidates 3 --max-candidates 3
  [ "$(timed last.out)" -eq 3 ] && ! grep -q 'cannot rank' last.err && ok "bench: --max-candidates K never widens" ||
    fail "--max-candidates 3: $(timed last.out) timed"
  # A whole manifest tuned at once: bench --manifest --pin-out DIR times each variant's candidates and
  # pins each; the manifest's `pins: DIR` then builds every variant as generate --pin writes it.
  cat > tune.variants.yaml <<YAML
rules: $E/rules.yaml
output: tuned
device_profile: $SRC/devices/llvmpipe-2core.yaml
mesh: head
rigs: { face: $E/face.rig.yaml }
passes: { color: $E/face.frag, depth: $E/depth.frag }
pins: tuned-pins
YAML
  expect 0 "build, pins: DIR not made yet" -- "$SG" build tune.variants.yaml -q --no-cache
  grep -q '"pin"' tuned/index.json && fail "a variant pinned before any pin was made" || ok "pins: DIR not there yet: no variant pinned"
  expect 0 "bench --manifest --candidates 3 --processes 2 --pin-out DIR" -- "$SG" bench --manifest tune.variants.yaml --raster off \
    --draws 1 --min-frame-vertices 0 --frames 2 --rounds 1 --no-floor --no-validation-layers --candidates 3 --max-candidates 3 \
    --processes 2 --pin-out tuned-pins
  [ "$(grep -c '^## face-' last.out)" -eq 2 ] && [ -s tuned-pins/face-color.pin.yaml ] && [ -s tuned-pins/face-depth.pin.yaml ] &&
    [ "$(grep -c 'best of 2 rounds in 2 processes' last.out)" -eq 2 ] &&
    ok "bench --manifest: both variants timed in 2 processes each, and pinned" ||
    fail "bench --manifest: $(ls tuned-pins) $(grep -E '^##|^mesh' last.out)"
  expect 0 "build, pins: DIR" -- "$SG" build tune.variants.yaml -q --no-cache
  for pass in color depth; do
    frag=$E/face.frag; [ $pass = depth ] && frag=$E/depth.frag
    expect 0 "generate --pin, the $pass variant's pin" -- "$SG" generate --rig "$E/face.rig.yaml" -f "$frag" -r "$E/rules.yaml" \
      --pin tuned-pins/face-$pass.pin.yaml --emit glsl -o tuned-$pass.vert -q
    [ -n "$(glsl_rules tuned-$pass.vert)" ] && [ "$(glsl_rules tuned/face-$pass.vert)" = "$(glsl_rules tuned-$pass.vert)" ] &&
      grep -q "\"pin\": {\"file\": \"tuned-pins/face-$pass.pin.yaml\"" tuned/index.json &&
      ok "pins: DIR: face-$pass is its pin's plan, index.json names it" ||
      fail "pins: DIR, face-$pass: $(glsl_rules tuned/face-$pass.vert) vs $(glsl_rules tuned-$pass.vert)"
  done
  ;;

*)
  echo "unknown case $case_name" >&2
  exit 2
  ;;
esac

if [ "$fails" -ne 0 ]; then
  echo "$fails check(s) failed" >&2
  exit 1
fi
echo "all checks passed"
