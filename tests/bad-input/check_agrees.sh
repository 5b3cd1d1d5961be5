#!/usr/bin/env bash
# `check` must refuse what `generate` refuses: for every rig and rules case whose `run`
# feeds a bad file to `generate` (--rig @D/F or -r @D/F), `shadergen check` on that file
# exits non-zero with a located error (F:line:col: error:) in a file of the case.
# Cases whose error depends on the plan (what the search picks), not on the file alone,
# are listed in PLAN_ONLY with the reason.
#
#   check_agrees.sh SHADERGEN SOURCE_ROOT
set -uo pipefail
[ -z "${LD_PRELOAD-}" ] || SG_SHADERGEN_PRELOAD=$LD_PRELOAD LD_PRELOAD= exec bash "$0" "$@"  # tests/support/preload_only_shadergen.sh
sg=$1 root=$2
cd "$root" || exit 2
W=$(mktemp -d "${TMPDIR:-/tmp}/sg-agrees-XXXXXX")
trap 'rm -rf "$W"' EXIT
# Sanitizer runs preload the Vulkan driver (tests/support/preload_only_shadergen.sh); no run
# here needs it: `check` stops at the bad file before it runs any rule on the device, and
# mapping lavapipe cost each of the ~100 runs 0.2 s (a third of this test). A run that did
# open a device unpreloaded would fail below (LeakSanitizer reports the unloaded driver).
unset LD_PRELOAD SG_SHADERGEN_PRELOAD
declare -A PLAN_ONLY=(
  # The block's size is what the chosen plan reads; check has no plan.
  [rig/bones_too_many_for_uniform_block]=1
  # A valid rig: what it lacks is for the request (gl_Position's camera); check has none.
  [rig/no_camera_for_gl_position]=1
)
checked=0 failed=0
for d in tests/bad-input/rig/*/ tests/bad-input/rules/*/; do
  d=${d%/} id=${d#tests/bad-input/}
  [ -n "${PLAN_ONLY[$id]:-}" ] && continue
  run=$(cat "$d/run")
  [[ $run == generate* ]] || continue
  # The expected error must be located in a file of the case.
  grep -qE '^@D/[^:]+:[0-9]+:[0-9]+: error' "$d/expect" || continue
  if [[ $run =~ --rig\ @D/([^ ]+) ]]; then
    file=$d/${BASH_REMATCH[1]} args=(--rig "$file" rules/standard.yaml)
  elif [[ $run =~ -r\ @D/([^ ]+) ]]; then
    file=$d/${BASH_REMATCH[1]} args=(--rig tests/bad-input/base/tiny.rig.yaml "$file")
  else
    continue
  fi
  checked=$((checked + 1))
  out=$(timeout 20 "$sg" check "${args[@]}" 2>&1)
  rc=$?
  if grep -q 'runtime error:\|AddressSanitizer\|LeakSanitizer\|UndefinedBehaviorSanitizer' <<<"$out"; then
    failed=$((failed + 1))
    printf 'FAIL %s: sanitizer report from check\n%s\n' "$id" "$(grep -m5 'Sanitizer\|runtime error' <<<"$out")"
  elif [ "$rc" -eq 0 ] || [ "$rc" -ge 124 ] || ! grep -qE "^$(printf '%s' "$d" | sed 's/[.[\*^$/]/\\&/g')/[^:]+:[0-9]+:[0-9]+: error: " <<<"$out"; then
    failed=$((failed + 1))
    printf 'FAIL %s: check exited %s without a located error in %s\n%s\n' "$id" "$rc" "$d/" "$(head -5 <<<"$out")"
  fi
done
echo "check agrees with generate on $((checked - failed)) of $checked rig and rules cases"
[ "$checked" -ge 50 ] || { echo "FAIL: only $checked cases checked; the corpus layout changed?"; exit 1; }
[ "$failed" -eq 0 ]
