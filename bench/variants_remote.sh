#!/usr/bin/env bash
# Two build trees (two local caches, standing in for two machines) sharing one cache server
# (nginx with WebDAV, tests/support/nginx_dav.sh): the first builds and validates a manifest
# of 240 variants on lavapipe and fills the server; the second, with an empty local cache,
# builds and validates the same manifest from the server. Both timed in this one run; the
# outputs (index.json included) must be byte-identical. Prints a Markdown table
# (docs/variants.md, "The remote cache").
#
#   bench/variants_remote.sh [build-dir]
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$here/build}"
sg="$build/generator/cli/shadergen"
[[ -x "$sg" ]] || { echo "build shadergen first: $sg" >&2; exit 1; }
work="$(mktemp -d)"
source "$here/tests/support/nginx_dav.sh"
trap 'nginx_dav_stop; rm -rf "$work"' EXIT
export CI=1

# The Dawn face and body over the six passes of bench/variants, morph target counts and
# influence counts: face 6 x 6 x 4 = 144, body 6 x 1 x 4 = 24, plus the face's packed
# rig 6 x 3 x 4 = 72: 240 variants, each validated on the procedural head in 2 poses.
d="$here/examples/dawn" b="$here/bench/variants"
cat >"$work/remote.variants.yaml" <<YAML
rules: $d/rules.yaml
rigs:
  face: $d/face.rig.yaml
  body: $d/body.rig.yaml
  packed: $d/face-packed.rig.yaml
passes:
  color: $d/face.frag
  depth: $d/depth.frag
  shadow: $b/shadow.frag
  gbuffer: $b/gbuffer.frag
  lit: $b/lit.frag
  eye: $b/eye.frag
axes:
  rig: [face, body, packed]
  morph_targets: [5, 4, 3, 2, 1, 0]
  influences: [4, 3, 2, 1]
exclude:
$(for m in 5 4 3 2 1; do echo "  - { rig: body, morph_targets: $m }"; done)
$(for m in 4 2 0; do echo "  - { rig: packed, morph_targets: $m }"; done)
validate: { poses: 2 }
YAML
count=$("$sg" build "$work/remote.variants.yaml" --list | wc -l)
nginx_dav_start "$work/server"

now() { date +%s%N; }
secs() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", (b - a) / 1e9 }'; }
t0=$(now)
"$sg" build "$work/remote.variants.yaml" -o "$work/a" --cache-dir "$work/cache-a" --cache-url "$URL" --validate \
  >"$work/a.out"
t1=$(now)
"$sg" build "$work/remote.variants.yaml" -o "$work/b" --cache-dir "$work/cache-b" --cache-url "$URL" --validate \
  >"$work/b.out"
t2=$(now)
diff -r -x "*.d" "$work/a" "$work/b" >/dev/null || { echo "the two trees' outputs differ" >&2; exit 1; }
grep -q "^$count variants: 0 generated, $count from the cache" "$work/b.out" ||
  { echo "the second tree did not take everything from the cache:" >&2; cat "$work/b.out" >&2; exit 1; }
grep -q "validated on .*: 0 run, $count from the cache" "$work/b.out" ||
  { echo "the second tree validated again:" >&2; cat "$work/b.out" >&2; exit 1; }

first=$(secs "$t0" "$t1") second=$(secs "$t1" "$t2")
echo "| $count variants, build + validate ($(nproc) cores) | seconds | |"
echo "|---|---:|---|"
echo "| first tree: empty local cache, empty server | $first | $(sed -n 's/^.*: \([0-9]* run, [0-9]* from the cache\)/\1/p' "$work/a.out") |"
echo "| second tree: empty local cache, the server filled | $second | $(sed -n 's/^remote cache [^ ]*: //p' "$work/b.out") |"
awk -v a="$first" -v b="$second" 'BEGIN { printf "\nsecond / first = %.4f\n", b / a }'
echo "outputs of the two trees byte-identical (index.json included)"
