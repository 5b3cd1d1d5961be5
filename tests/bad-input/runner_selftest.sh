#!/usr/bin/env bash
# The corpus runner must fail a case for each thing it promises to catch: wrong status,
# missing message, a signal, a hang, a changed input, an output left behind on failure.
# A stand-in "shadergen" misbehaves on request; each case must be reported as FAIL.
set -uo pipefail
# The stand-in needs no Vulkan driver: no process here gets the sanitizer runs' preload.
unset LD_PRELOAD
RUNNER=$(realpath "$(dirname "$0")/run_corpus.sh")
T=$(mktemp -d "${TMPDIR:-/tmp}/sg-corpus-self-XXXXXX")
trap 'rm -rf "$T"' EXIT
cat >"$T/fake" <<'SH'
#!/usr/bin/env bash
case "$1" in
  ok) echo "x.yaml:1:2: error: as expected" >&2; exit 1 ;;
  status) echo "x.yaml:1:2: error: as expected" >&2; exit 2 ;;
  message) echo "x.yaml:9:9: error: something else" >&2; exit 1 ;;
  crash) kill -SEGV $$ ;;
  hang) exec sleep 30 ;;
  touch) echo changed >>"$2"; exit 1 ;;
  leave) echo partial >"$2"; exit 1 ;;
  ubsan) echo "x.cpp:3:4: runtime error: signed integer overflow" >&2; exit 1 ;;
esac
SH
chmod +x "$T/fake"
mk() {  # mk <case> <run line> <expect...>
  local d=$T/src/tests/bad-input/self/$1
  mkdir -p "$d"
  echo "$2" >"$d/run"
  shift 2
  printf '%s\n' "$@" >"$d/expect"
}
fails=0
check() {  # check <case> <want: ok|FAIL>
  out=$(SHADERGEN_CORPUS_TIME_SCALE=0.5 bash "$RUNNER" "$T/fake" "$T/src" self "$1" 2>&1)
  if grep -q "^$2 " <<<"$out"; then echo "ok: runner reports $2 for '$1'"; else
    echo "FAIL: runner did not report $2 for '$1':"; echo "$out" | sed 's/^/  | /'; fails=$((fails + 1)); fi
}
for c in ok status message crash hang ubsan; do mk "$c" "$c" 1 "x.yaml:1:2: error: as expected"; done
mk touch "touch @D/input.txt" 1; echo original >"$T/src/tests/bad-input/self/touch/input.txt"
mk leave "leave @O/out.vert" 1
check ok ok
for c in status message crash hang ubsan touch leave; do check "$c" FAIL; done
[ "$fails" -eq 0 ]
