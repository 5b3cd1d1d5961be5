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
expand() {  # expand <token> <D> <O> <T>
  local t=$1
  t=${t//@D/$2}
  t=${t//@O/$3}
  t=${t//@T/$4}
  case "$t" in examples/* | rules/* | tests/* | templates/*) t=$SRC/$t ;; esac
  printf '%s' "$t"
}
snapshot() {  # every entry's type and size, then every regular file's checksum
  (cd "$1" && find . -printf '%y %s %p\n' | LC_ALL=C sort && find . -type f -print0 | LC_ALL=C sort -z | xargs -0 -r sha256sum)
}

fails=0 n=0
for D in "${cases[@]}"; do
  name="$AREA/$(basename "$D")"
  n=$((n + 1))
  if [ ! -f "$D/expect" ]; then echo "FAIL $name: no 'expect' file"; fails=$((fails + 1)); continue; fi
  C=$WORK/$n
  O=$C/out T=$C/scratch
  mkdir -p "$O" "$T"
  [ -f "$D/setup" ] && bash "$D/setup" "$T"
  before=$(snapshot "$D")
  # Tokens: shell-like words (quotes allowed, no expansion), then @-expansion per word.
  mapfile -t raw < <(xargs -n1 printf '%s\n' < "$D/run")
  args=()
  for w in "${raw[@]}"; do args+=("$(expand "$w" "$D" "$O" "$T")"); done
  want=$(head -n1 "$D/expect" | tr -d '[:space:]')
  cwd=$O
  [ -f "$D/cwd" ] && cwd=$(expand "$(tr -d '[:space:]' < "$D/cwd")" "$D" "$O" "$T")
  # Killed at the limit: one more try, so that a load spike on a shared machine is not
  # taken for a hang (a real hang is killed twice).
  # Only the commands that open a Vulkan device need the driver preloaded (sanitizer runs):
  # mapping lavapipe and its LLVM costs each other case 0.1 s. A command that opened one
  # unpreloaded would fail loudly (LeakSanitizer reports the unloaded driver's globals).
  sg=$SG_NO_DEVICE
  case "${args[0]-}" in validate | check | render | bench | calibrate | build) sg=$SG ;; esac
  for try in 1 2; do
    rm -rf "$O" && mkdir -p "$O"
    start=$(date +%s.%N)
    (cd "$cwd" && exec timeout -s KILL "$LIMIT" "$sg" "${args[@]}" </dev/null >"$C/stdout" 2>"$C/stderr")
    got=$?
    [ "$got" -eq 137 ] || break
  done
  secs=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.2f", b - a }')
  problems=()
  if [ "$got" -eq 137 ]; then problems+=("killed after ${LIMIT}s (hang or too slow)")
  elif [ "$got" -ge 128 ]; then problems+=("died of signal $((got - 128))")
  elif [ "$got" != "$want" ]; then problems+=("exit $got, expected $want"); fi
  while IFS= read -r line || [ -n "$line" ]; do
    [ -z "$line" ] && continue
    line=${line//@D/$D}
    line=${line//@O/$O}
    line=${line//@T/$T}
    grep -qF -- "$line" "$C/stderr" || problems+=("stderr lacks: $line")
  done < <(tail -n +2 "$D/expect")
  grep -q 'runtime error:\|AddressSanitizer\|LeakSanitizer\|UndefinedBehaviorSanitizer' "$C/stderr" &&
    problems+=("sanitizer report")
  after=$(snapshot "$D")
  [ "$before" == "$after" ] || problems+=("the case directory changed: $(diff <(echo "$before") <(echo "$after") | grep '^[<>]' | head -3 | tr '\n' ' ')")
  if [ "$got" -ne 0 ]; then
    left=$(cd "$O" && find . -mindepth 1 | head -5 | tr '\n' ' ')
    [ -z "$left" ] || problems+=("failed but wrote: $left")
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
