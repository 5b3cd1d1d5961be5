#!/usr/bin/env bash
# `shadergen build` against a real shared cache (nginx with WebDAV PUT, on 127.0.0.1, in this
# test's own temporary directory) and `build --validate` (docs/variants.md): one case a run.
#
#   remote_cache_test.sh <case> <shadergen> <source dir> [shared models dir]
#
# Cases: share (a second tree builds and validates everything from the server), unreachable,
# server_killed, corrupt, truncated, concurrent, killed_build, credentials, validate_dawn,
# validate_model.
set -uo pipefail
[ -z "${LD_PRELOAD-}" ] || SG_SHADERGEN_PRELOAD=$LD_PRELOAD LD_PRELOAD= exec bash "$0" "$@"  # tests/support/preload_only_shadergen.sh
case_name=$1 SG=$(realpath "$2") SRC=$3 MODELS=${4:-$SRC/../shared/models}
E=$SRC/examples/dawn
T=$(mktemp -d "${TMPDIR:-/tmp}/sg-remote-XXXXXX") || exit 1
cleanup() {
  nginx_dav_stop
  rm -rf "$T"
}
trap cleanup EXIT
[ -n "${SG_KEEP:-}" ] && trap "nginx_dav_stop" EXIT
source "$SRC/tests/support/preload_only_shadergen.sh"
preload_only_shadergen SG "$T"
cd "$T"
export CI=1  # no progress lines
unset SHADERGEN_CACHE_URL SHADERGEN_CACHE_AUTH

fails=0
fail() { echo "FAIL: $*" >&2; fails=$((fails + 1)); }
ok() { echo "ok: $*"; }
check() {  # check <description> <command...>: passes when the command succeeds
  local what=$1
  shift
  if "$@"; then ok "$what"; else fail "$what"; fi
}

# ---- the server (tests/support/nginx_dav.sh) ---------------------------------------------
source "$SRC/tests/support/nginx_dav.sh"
start_nginx() { nginx_dav_start "$T/nginx" "${1:-}"; }
stop_nginx() { nginx_dav_stop; }
server_entries() { find "$T/nginx/root" -type f | sort; }

# ---- manifests ---------------------------------------------------------------------------
# Dawn face and body, colour and depth passes: 4 variants (8 with INFLUENCES="[4, 1]");
# with VALIDATED=1 each is validated on lavapipe in one pose (POSES=N: N).
small_manifest() {  # small_manifest <file> [extra lines]
  local validate=""
  [ -n "${VALIDATED:-}" ] && validate="validate: { poses: ${POSES:-1}, validation_layers: false }"
  cat >"$1" <<EOF
output: out
rules: $E/rules.yaml
rigs:
  face: $E/face.rig.yaml
  body: $E/body.rig.yaml
passes:
  color: $E/face.frag
  depth: $E/depth.frag
axes:
  influences: ${INFLUENCES:-[4]}
$validate
${2:-}
EOF
}
# The summary line's counts.
generated() { sed -n 's/^.* variants: \([0-9]*\) generated.*/\1/p' "$1"; }
from_cache() { sed -n 's/^.*generated, \([0-9]*\) from the cache.*/\1/p' "$1"; }
same_bytes() {  # same_bytes <dir> <dir>: every file but the cache and the depfiles (they name their dir)
  diff -r -x .shadergen-cache -x '*.d' "$1" "$2" >/dev/null
}
# The same, but the index's validation times may differ (results made by different builds).
same_outputs() {
  diff -r -x .shadergen-cache -x '*.d' -x index.json "$1" "$2" >/dev/null &&
    cmp -s <(sed 's/"made": "[^"]*"/"made": ""/' "$1/index.json") <(sed 's/"made": "[^"]*"/"made": ""/' "$2/index.json")
}
# Every entry under a directory (local or the server's root) opens: its digest holds. The
# digest is recomputed here by sha256sum over the key and the body as length-prefixed fields
# (8 bytes little-endian, content_hash.h), independently of the tool.
le64() { local i; for i in 0 1 2 3 4 5 6 7; do printf "\\x$(printf %02x $((($1 >> (8 * i)) & 255)))"; done; }
all_entries_verify() {  # all_entries_verify <dir>
  local f key want got n
  for f in $(find "$1" -type f ! -name '*.tmp.*'); do
    key=$(basename "$f")
    want=$(head -c 82 "$f" | sed -n '1s/^shadergen-entry 1 //p')
    n=$(tail -c +84 "$f" | wc -c)
    got=$( { le64 ${#key}; printf '%s' "$key"; le64 "$n"; tail -c +84 "$f"; } | sha256sum | cut -c1-64)
    [ "$want" = "$got" ] || { echo "entry $f does not verify" >&2; return 1; }
  done
}

# A reference build: no cache at all.
reference() {
  small_manifest ref.yaml "${1:-}"
  "$SG" build ref.yaml -o ref --no-cache -q || { fail "reference build"; exit 1; }
}

case "$case_name" in

share)  # two trees, one server: the second builds and validates everything from the server
  export VALIDATED=1
  start_nginx
  small_manifest m.yaml
  "$SG" build m.yaml -o a --cache-dir cache-a --cache-url "$URL" >a.out 2>a.err
  check "first tree builds (exit 0)" [ $? -eq 0 ]
  check "first tree generates all 4" [ "$(generated a.out)" = 4 ]
  check "first tree validates all 4" grep -q "validated on .*: 4 run, 0 from the cache" a.out
  check "first tree stores 8 entries (4 outputs, 4 results)" grep -q "0 hits, 8 stored, 0 entries rejected" a.out
  check "8 entries on the server" [ "$(server_entries | wc -l)" = 8 ]
  check "server entries verify (sha256sum agrees with the stored digests)" all_entries_verify "$T/nginx/root"
  SHADERGEN_CACHE_URL=$URL "$SG" build m.yaml -o b --cache-dir cache-b >b.out 2>b.err
  check "second tree builds (exit 0)" [ $? -eq 0 ]
  check "second tree generates nothing" [ "$(generated b.out)" = 0 ]
  check "second tree validates nothing itself" grep -q "validated on .*: 0 run, 4 from the cache" b.out
  check "second tree: 8 remote hits" grep -q "8 hits, 0 stored" b.out
  check "same outputs and index bytes (the results' times come from the cache)" same_bytes a b
  check "index says validated, where and when" grep -q '"validated": true' b/index.json
  grep -q '"device": "llvmpipe' b/index.json && grep -q '"made": "20[0-9-]*T[0-9:]*Z"' b/index.json ||
    fail "index lacks the device or the time: $(grep -m1 validation b/index.json)"
  check "remote hits were stored locally" [ "$(find cache-b -type f | wc -l)" = 8 ]
  # Another device setting is another result: validated again, outputs still from the cache.
  small_manifest m2.yaml "cache_url: $URL"
  sed -i 's/poses: 1/poses: 2/' m2.yaml
  "$SG" build m2.yaml -o c --cache-dir cache-c >c.out 2>c.err
  check "other validation settings: 4 validated again, 0 generated" \
    grep -q "validated on .*: 4 run, 0 from the cache" c.out
  check "  ... and nothing generated" [ "$(generated c.out)" = 0 ]
  ;;

unreachable)  # a port nobody listens on: one warning, a bounded delay, a correct build
  reference
  small_manifest m.yaml
  start=$SECONDS
  "$SG" build m.yaml -o a --cache-url http://127.0.0.1:9/cache -j2 >a.out 2>a.err
  check "build succeeds without the server" [ $? -eq 0 ]
  check "one warning" [ "$(grep -c 'warning: remote cache http://127.0.0.1:9/cache unreachable' a.err)" = 1 ]
  check "within 30 s" [ $((SECONDS - start)) -lt 30 ]
  check "outputs as without a cache" same_outputs ref a
  ;;

server_killed)  # the server dies mid-build: the build completes from local work
  export VALIDATED=1 INFLUENCES="[4, 1]" POSES=6  # slow enough (lavapipe) to be killed mid-way
  reference
  start_nginx
  small_manifest m.yaml
  "$SG" build m.yaml -o a --cache-url "$URL" -j1 >a.out 2>a.err &
  build=$!
  for _ in $(seq 300); do  # until the first entries are on the server
    [ "$(server_entries | wc -l)" -ge 2 ] && break
    sleep 0.05
  done
  stop_nginx
  wait $build
  check "build succeeds after the server died" [ $? -eq 0 ]
  check "one warning" [ "$(grep -c 'warning: remote cache .* unreachable' a.err)" = 1 ]
  check "summary says so" grep -q "unreachable: built without it" a.out
  check "some entries reached the server before it died" [ "$(server_entries | wc -l)" -ge 2 ]
  check "  ... not all" [ "$(server_entries | wc -l)" -lt 16 ]
  check "outputs as without a cache" same_outputs ref a
  ;;

corrupt | truncated)  # a damaged entry on the server: rejected, rebuilt, overwritten
  start_nginx
  small_manifest m.yaml
  "$SG" build m.yaml -o a --cache-dir cache-a --cache-url "$URL" >a.out 2>a.err ||
    fail "first build"
  victim=$(server_entries | head -1)
  key=$(basename "$victim")
  if [ "$case_name" = corrupt ]; then
    at=$(($(stat -c %s "$victim") / 2))  # one byte changed: its value plus one
    byte=$(dd if="$victim" bs=1 skip=$at count=1 status=none | od -An -tu1 | tr -d ' ')
    printf "\\x$(printf %02x $(((byte + 1) % 256)))" | dd of="$victim" bs=1 seek=$at conv=notrunc status=none
  else
    truncate -s $(($(stat -c %s "$victim") * 2 / 3)) "$victim"
  fi
  "$SG" build m.yaml -o b --cache-dir cache-b --cache-url "$URL" >b.out 2>b.err
  check "build with a $case_name entry succeeds" [ $? -eq 0 ]
  check "the entry is reported" grep -q "warning: remote cache entry $key rejected: its SHA-256 does not match" b.err
  check "summary counts it" grep -q "3 hits, 1 stored, 1 entries rejected" b.out
  check "outputs as the undamaged cache gave" same_outputs a b
  check "the server's entry was rewritten" all_entries_verify "$T/nginx/root"
  "$SG" build m.yaml -o c --cache-dir cache-c --cache-url "$URL" >c.out 2>c.err
  check "a third tree finds all 4 intact" grep -q "4 hits, 0 stored, 0 entries rejected" c.out
  # The local directory is checked the same way.
  local_entry=$(find cache-c -type f | head -1)
  truncate -s 10 "$local_entry"
  "$SG" build m.yaml -o c --cache-dir cache-c --cache-url "$URL" >d.out 2>d.err
  check "a truncated local entry is reported" grep -q "warning: local cache entry $(basename "$local_entry") rejected" d.err
  check "  ... and taken from the server instead" grep -q "1 hits, 0 stored, 1 entries rejected" d.out
  ;;

concurrent)  # two builders writing the same entries at once: no torn entry, both correct
  reference
  start_nginx
  small_manifest m.yaml
  "$SG" build m.yaml -o a --cache-dir cache-a --cache-url "$URL" -j1 >a.out 2>a.err &
  pa=$!
  "$SG" build m.yaml -o b --cache-dir cache-b --cache-url "$URL" -j1 >b.out 2>b.err &
  pb=$!
  wait $pa; ra=$?
  wait $pb; rb=$?
  check "both builds succeed" [ $ra -eq 0 -a $rb -eq 0 ]
  check "first builder's outputs correct" same_outputs ref a
  check "second builder's outputs correct" same_outputs ref b
  check "neither saw a torn entry" bash -c "! grep -q rejected a.err b.err"
  check "every entry on the server verifies" all_entries_verify "$T/nginx/root"
  check "4 entries on the server" [ "$(server_entries | wc -l)" = 4 ]
  "$SG" build m.yaml -o c --cache-dir cache-c --cache-url "$URL" >c.out 2>c.err
  check "a third tree builds all from the server" grep -q "4 hits, 0 stored, 0 entries rejected" c.out
  ;;

killed_build)  # SIGKILL mid-way, then again: no partial outputs, no poisoned entry
  export VALIDATED=1 INFLUENCES="[4, 1]" POSES=6  # slow enough (lavapipe) to be killed mid-way
  reference
  start_nginx
  small_manifest m.yaml
  "$SG" build m.yaml -o a --cache-dir cache-a --cache-url "$URL" -j1 --validate >a.out 2>a.err &
  build=$!
  for _ in $(seq 300); do
    [ "$(find cache-a -type f 2>/dev/null | wc -l)" -ge 1 ] && break
    sleep 0.05
  done
  kill -9 $build
  wait $build 2>/dev/null
  check "killed before the end: no index" [ ! -e a/index.json ]
  check "killed mid-way: some entries were written" [ "$(find cache-a -type f | wc -l)" -ge 1 ]
  check "  ... not all" [ "$(find cache-a -type f ! -name '*.tmp.*' | wc -l)" -lt 16 ]
  partial=0
  for f in $(cd ref && find . -type f); do
    [ -e "a/$f" ] && ! cmp -s "ref/$f" "a/$f" && partial=1
  done
  check "no output written partly" [ $partial -eq 0 ]
  check "local entries verify" all_entries_verify cache-a
  check "server entries verify" all_entries_verify "$T/nginx/root"
  "$SG" build m.yaml -o a --cache-dir cache-a --cache-url "$URL" >b.out 2>b.err
  check "restarted build succeeds" [ $? -eq 0 ]
  check "restarted build: nothing rejected" bash -c "! grep -q rejected b.err"
  check "restarted build: outputs complete and right" same_outputs ref a
  ;;

credentials)  # credentials only from the environment, never printed
  small_manifest m.yaml
  "$SG" build m.yaml -o a --cache-url http://user:s3cret@127.0.0.1:9/c >a.out 2>a.err
  check "--cache-url with credentials is refused" [ $? -ne 0 ]
  check "  ... naming the environment" grep -q "SHADERGEN_CACHE_AUTH" a.err
  small_manifest m2.yaml "cache_url: http://user:s3cret@127.0.0.1:9/c"
  "$SG" build m2.yaml -o a >b.out 2>b.err
  check "a manifest with credentials is refused" [ $? -ne 0 ]
  check "  ... naming the line" grep -q "m2.yaml: error: line 12: .cache_url. .http://\*\*\*@127.0.0.1:9/c. holds credentials" b.err
  # A server that wants them (HTTP basic authentication, nginx's {PLAIN} password scheme).
  printf 'builder:{PLAIN}pw0rd\n' >"$T/htpasswd"
  start_nginx "auth_basic cache; auth_basic_user_file $T/htpasswd;"
  "$SG" build m.yaml -o c --cache-dir cache-c --cache-url "$URL" >c.out 2>c.err
  check "without credentials: built, one warning (HTTP 401)" \
    [ $? -eq 0 -a "$(grep -c 'answered HTTP 401' c.err)" -eq 1 ]
  SHADERGEN_CACHE_AUTH=builder:pw0rd "$SG" build m.yaml -o d --cache-dir cache-d --cache-url "$URL" >d.out 2>d.err
  check "SHADERGEN_CACHE_AUTH: entries stored" grep -q "0 hits, 4 stored" d.out
  SHADERGEN_CACHE_URL=${URL/http:\/\//http://builder:pw0rd@} "$SG" build m.yaml -o e --cache-dir cache-e >e.out 2>e.err
  check "credentials in SHADERGEN_CACHE_URL: entries read" grep -q "remote cache http://\*\*\*@127.0.0.1:$PORT/cache: 4 hits" e.out
  stop_nginx
  SHADERGEN_CACHE_URL=http://user:s3cret@127.0.0.1:9/c SHADERGEN_CACHE_AUTH=u:pw0rd \
    "$SG" build m.yaml -o f >f.out 2>f.err
  check "unreachable with credentials: built" [ $? -eq 0 ]
  check "  ... and the warning redacts them" grep -q "remote cache http://\*\*\*@127.0.0.1:9/c unreachable" f.err
  check "no secret in any output" bash -c "! grep -q -e s3cret -e pw0rd ?.out ?.err"
  ;;

validate_dawn | validate_model)  # a planted wrong rule fails the build and names the variants
  export VALIDATED=1
  cp -r "$SRC/rules" rules
  if [ "$case_name" = validate_dawn ]; then
    # The Dawn manifest of examples/cmake-consumer (16 variants), over this rules copy as
    # shadergen_add_shader_variants(RULES ...) gives it the standard library.
    cp "$SRC/examples/cmake-consumer/"* . 2>/dev/null
    printf 'validate: { poses: 1, validation_layers: false }\n' >>variants.yaml
    mv variants.yaml m.yaml
    set -- -r rules/standard.yaml -o out
  else
    [ -f "$MODELS/CesiumMan/CesiumMan.glb" ] || { echo "no shared models: skipped"; exit 0; }
    printf '#version 450\nlayout(location = 0) in vec3 world_eye_dir;\nlayout(location = 1) in vec3 world_normal;\n%s\n' \
      'layout(location = 0) out vec4 C; void main() { C = vec4(world_eye_dir + world_normal, 1.0); }' >lit.frag
    cat >m.yaml <<EOF
output: out
rules: rules/standard.yaml
rigs:
  cesium: $MODELS/CesiumMan/CesiumMan.glb#*
passes:
  lit: lit.frag
  depth: $E/depth.frag
validate: { time: [0, 1], validation_layers: false }
EOF
  fi
  [ "$case_name" = validate_model ] && set --
  names=$("$SG" build m.yaml "$@" --list)
  failing=$(echo "$names" | grep -e '-lit' -e '-color')  # the passes that read WorldEyeDir
  passing=$(echo "$names" | grep -- '-depth')
  check "variants on both sides" [ -n "$failing" -a -n "$passing" ]
  "$SG" build m.yaml "$@" --cache-dir cache >a.out 2>a.err
  check "unbroken rules validate" [ $? -eq 0 ]
  check "  ... the index says so" grep -q '"validated": true' out/index.json
  # Wrong sign: vertex -> eye instead of eye -> vertex (tests/validate/test_break.cpp).
  grep -q 'normalize(${world.position} - ${camera.position})' rules/view.yaml || fail "rule to break not found"
  sed -i 's/normalize(${world.position} - ${camera.position})/normalize(${camera.position} - ${world.position})/' \
    rules/view.yaml
  "$SG" build m.yaml "$@" --cache-dir cache --validate >b.out 2>b.err
  check "a planted wrong rule fails the build (exit 1)" [ $? -eq 1 ]
  for v in $failing; do
    check "names variant $v" grep -q "error: variant '$v' does not validate on llvmpipe" b.err
  done
  for v in $passing; do
    check "does not name $v" bash -c "! grep -q \"variant '$v' \" b.err"
  done
  check "names the broken output" grep -q "WorldEyeDir\|world_eye_dir" b.err
  check "no index left vouching for the build" [ ! -e out/index.json ]
  # Results cached: the unbroken build's, and the broken build's passing ones; no failure.
  results=$(grep -rlax "shadergen-validation 1" cache | wc -l)
  check "only passing results cached ($results)" \
    [ "$results" -eq $(($(echo "$names" | wc -l) + $(echo "$passing" | wc -l))) ]
  "$SG" build m.yaml "$@" --cache-dir cache >c.out 2>c.err
  check "the failure is found again, not taken from a cache" [ $? -eq 1 -a "$(grep -c 'does not validate' c.err)" -eq "$(echo "$failing" | wc -l)" ]
  ;;

*)
  echo "unknown case $case_name" >&2
  exit 2
  ;;
esac

if [ $fails -ne 0 ]; then
  echo "$fails check(s) failed" >&2
  exit 1
fi
echo "all checks passed"
