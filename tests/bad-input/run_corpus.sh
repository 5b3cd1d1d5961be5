#!/usr/bin/env bash
# Runs the bad-input corpus (tests/bad-input/README.md): every case directory
# tests/bad-input/<area>/<case>/ holds its input files, `run` (the arguments) and
# `expect` (exit status, then strings stderr must contain).
#
#   run_corpus.sh <shadergen> <source dir> <area> [case...]
#
# Besides the exit status and the messages, every case must: finish within 2 s
# (times SHADERGEN_CORPUS_TIME_SCALE, e.g. 10 for sanitizer builds), die of no signal,
# leave its own directory byte-identical, and write nothing (no output, no temporary)
# when it fails. The command runs in the fresh output directory @O.
set -uo pipefail
[ -z "${LD_PRELOAD-}" ] || SG_SHADERGEN_PRELOAD=$LD_PRELOAD LD_PRELOAD= exec bash "$0" "$@"  # tests/support/preload_only_shadergen.sh
SG=$(realpath "$1") SRC=$(realpath "$2") AREA=$3
shift 3
SCALE=${SHADERGEN_CORPUS_TIME_SCALE:-1}
LIMIT=$(awk -v s="$SCALE" 'BEGIN { printf "%.2f", 2 * s }')
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp/shadergen-xdg}
mkdir -p "$XDG_RUNTIME_DIR" 2>/dev/null && chmod 700 "$XDG_RUNTIME_DIR" 2>/dev/null
WORK=$(mktemp -d "${TMPDIR:-/tmp}/sg-corpus-XXXXXX")
trap 'chmod -R u+rwx "$WORK" 2>/dev/null; rm -rf "$WORK"' EXIT
source "$SRC/tests/support/preload_only_shadergen.sh"
SG_NO_DEVICE=$SG
preload_only_shadergen SG "$WORK"

cases=()
if [ $# -gt 0 ]; then
  for c in "$@"; do cases+=("$SRC/tests/bad-input/$AREA/$c"); done
else
  for d in "$SRC/tests/bad-input/$AREA"/*/; do [ -f "$d/run" ] && cases+=("${d%/}"); done
fi
[ ${#cases[@]} -gt 0 ] || { echo "no cases in $SRC/tests/bad-input/$AREA" >&2; exit 1; }

# Repo paths in `run` (examples/..., rules/..., tests/..., templates/...) are relative to
# the source root; @D is the case directory, @O the output directory, @T a scratch
# directory that the optional `setup` script (bash setup @T) prepares (FIFOs...).
# Each case's bookkeeping runs in this shell (parameter expansion, read, $EPOCHREALTIME)
# rather than in $(...) subshells and small processes: forks are most of the cost of a case
# that shadergen refuses at once, above all under sanitizers.
expand() {  # expand <token> <D> <O> <T>: sets $x
  local t=$1
  t=${t//@D/$2}
  t=${t//@O/$3}
  t=${t//@T/$4}
  case "$t" in examples/* | rules/* | tests/* | templates/*) t=$SRC/$t ;; esac
  x=$t
}
snapshot() {  # every entry's type and size and every regular file's checksum, sorted (called in $(...))
  cd "$1" && find . -printf '%y %s %p\n' -type f -exec sha256sum {} + | LC_ALL=C sort
}
usecs() { local t=${EPOCHREALTIME//[!0-9]/}; printf -v "$1" '%s' "$((10#$t))"; }  # usecs VAR: now in microseconds

fails=0 n=0
for D in "${cases[@]}"; do
  name="$AREA/${D##*/}"
  n=$((n + 1))
  if [ ! -f "$D/expect" ]; then echo "FAIL $name: no 'expect' file"; fails=$((fails + 1)); continue; fi
  C=$WORK/$n
  O=$C/out T=$C/scratch
  mkdir -p "$O" "$T"
  [ -f "$D/setup" ] && bash "$D/setup" "$T"
  before=$(snapshot "$D")
  # Tokens: shell-like words (quotes allowed, no expansion), then @-expansion per word.
  mapfile -t raw < <(xargs printf '%s\n' < "$D/run")
  args=()
  for w in "${raw[@]}"; do expand "$w" "$D" "$O" "$T"; args+=("$x"); done
  want= && read -r want < "$D/expect"
  want=${want//[[:space:]]/}
  cwd=$O
  if [ -f "$D/cwd" ]; then
    cwd=$(<"$D/cwd") && expand "${cwd//[[:space:]]/}" "$D" "$O" "$T" && cwd=$x
  fi
  # Killed at the limit: one more try, so that a load spike on a shared machine is not
  # taken for a hang (a real hang is killed twice).
  # Only the commands that open a Vulkan device need the driver preloaded (sanitizer runs):
  # mapping lavapipe and its LLVM costs each other case 0.1 s. A command that opened one
  # unpreloaded would fail loudly (LeakSanitizer reports the unloaded driver's globals).
  sg=$SG_NO_DEVICE
  case "${args[0]-}" in validate | check | render | bench | calibrate | build) sg=$SG ;; esac
  for try in 1 2; do
    [ "$try" -eq 1 ] || { rm -rf "$O" && mkdir -p "$O"; }  # the first try's $O is new and empty
    usecs start
    (cd "$cwd" && exec timeout -s KILL "$LIMIT" "$sg" "${args[@]}" </dev/null >"$C/stdout" 2>"$C/stderr")
    got=$?
    [ "$got" -eq 137 ] || break
  done
  usecs end
  cs=$(((end - start + 5000) / 10000))
  printf -v secs '%d.%02d' $((cs / 100)) $((cs % 100))
  problems=()
  if [ "$got" -eq 137 ]; then problems+=("killed after ${LIMIT}s (hang or too slow)")
  elif [ "$got" -ge 128 ]; then problems+=("died of signal $((got - 128))")
  elif [ "$got" != "$want" ]; then problems+=("exit $got, expected $want"); fi
  {
    read -r _  # the exit status
    while IFS= read -r line || [ -n "$line" ]; do
      [ -z "$line" ] && continue
      line=${line//@D/$D}
      line=${line//@O/$O}
      line=${line//@T/$T}
      grep -qF -- "$line" "$C/stderr" </dev/null || problems+=("stderr lacks: $line")
    done
  } < "$D/expect"
  grep -q 'runtime error:\|AddressSanitizer\|LeakSanitizer\|UndefinedBehaviorSanitizer' "$C/stderr" &&
    problems+=("sanitizer report")
  after=$(snapshot "$D")
  [ "$before" == "$after" ] || problems+=("the case directory changed: $(diff <(echo "$before") <(echo "$after") | grep '^[<>]' | head -3 | tr '\n' ' ')")
  if [ "$got" -ne 0 ]; then
    shopt -s nullglob dotglob
    left=("$O"/*)
    shopt -u nullglob dotglob
    [ ${#left[@]} -eq 0 ] || problems+=("failed but wrote: $(cd "$O" && find . -mindepth 1 | head -5 | tr '\n' ' ')")
  fi
  if [ ${#problems[@]} -eq 0 ]; then
    echo "ok   $name (exit $got, ${secs}s)"
  else
    fails=$((fails + 1))
    echo "FAIL $name (${secs}s): $(IFS='; '; echo "${problems[*]}")"
    echo "     shadergen ${args[*]}"
    sed 's/^/     | /' "$C/stderr" | head -20
  fi
done
echo "$AREA: $((n - fails))/$n cases pass"
[ "$fails" -eq 0 ]
