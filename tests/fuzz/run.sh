#!/usr/bin/env bash
# Runs the libFuzzer targets of a SHADERGEN_FUZZ build, two at a time, each for SECONDS,
# seeded from the repository (examples, rules, test data, the bad-input corpus), and prints
# one line per target: runs, exec/s, corpus size, result. Exit status 1 if any target found
# something (its reproducer is in BUILD/fuzz/artifacts/).
#
#   tests/fuzz/run.sh BUILD SECONDS [target...]      targets: rig rules expr fragment gltf generate profile pin
set -uo pipefail
BUILD=$(cd "$1" && pwd) SECS=$2
shift 2
SRC=$(cd "$(dirname "$0")/../.." && pwd)
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(rig rules expr fragment gltf generate profile pin)
source "$SRC/cmake/sanitizers/env.sh"
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp/shadergen-xdg}
W=$BUILD/fuzz
mkdir -p "$W/artifacts"

# seeds TARGET DIR: copies the target's seed files (at most 256 KiB each) into DIR.
seeds() {
  local t=$1 d=$2 f
  rm -rf "$d" && mkdir -p "$d"
  add() { for f in "$@"; do [ -f "$f" ] && [ "$(stat -c %s "$f")" -le 262144 ] && cp "$f" "$d/$(echo "$f" | tr '/' '_')"; done; return 0; }
  shopt -s nullglob globstar
  case $t in
    rig) add "$SRC"/examples/**/*.rig.yaml "$SRC"/tests/**/*.rig.yaml "$SRC"/tests/bad-input/rig/**/*.yaml ;;
    rules) add "$SRC"/rules/*.yaml "$SRC"/examples/**/*rules*.yaml "$SRC"/tests/**/*rules*.yaml \
             "$SRC"/tests/bad-input/rules/**/*.yaml ;;
    expr)  # the expressions of the rules library and examples, one per file
      local n=0 line
      while IFS= read -r line; do
        n=$((n + 1)) && printf '%s' "$line" > "$d/expr-$n"
      done < <(grep -hoE '(when|cost|count): *[^#]+' "$SRC"/rules/*.yaml "$SRC"/examples/**/*.yaml |
               sed -E 's/^(when|cost|count): *//; s/^"(.*)"$/\1/' | sort -u)
      add "$SRC"/tests/bad-input/expr/**/* ;;
    fragment) add "$SRC"/examples/**/*.frag "$SRC"/tests/**/*.frag ;;
    gltf) add "$SRC"/tests/bad-input/gltf/**/*.gltf "$SRC"/tests/bad-input/gltf/**/*.glb "$SRC"/tests/gltf/data/gltfpack/*.glb \
            "$SRC"/../shared/models/**/*.gltf "$SRC"/../shared/models/**/*.glb ;;
    pin) add "$SRC"/tests/bad-input/cli/*/pin.yaml "$SRC"/bench/data/**/*.pin.yaml ;;
    profile)
      add "$SRC"/devices/*.yaml "$SRC"/tests/bad-input/profile/**/*.yaml
      # The fitted profiles of bench/data, one per set of keys: each input searches the Dawn face
      # several times (0.7 s under the sanitizers), and the 58 profiles there, replayed whole, took
      # 80 s of a 10 s run; profiles of one shape differ in their numbers only (15 shapes).
      local -A shapes=()
      local key
      for f in "$SRC"/bench/data/**/*.yaml; do
        [[ $f == *.pin.yaml ]] && continue  # the pin target's
        key=$(grep -oE '^ *[a-z_]+:' "$f" | tr -d ' ' | sort -u | md5sum | cut -c1-32)
        [ -n "${shapes[$key]-}" ] || { shapes[$key]=1; add "$f"; }
      done ;;
    generate)  # rig %% fragment %% rules triples from the examples
      local ex=$SRC/examples
      for combo in "dawn/face.rig.yaml dawn/face.frag dawn/rules.yaml" "dawn/body.rig.yaml dawn/depth.frag dawn/rules.yaml" \
                   "cmake-consumer/face.rig.yaml cmake-consumer/face.frag cmake-consumer/face.rules.yaml" \
                   "cmake-consumer/prop.rig.yaml cmake-consumer/prop.frag cmake-consumer/prop.rules.yaml"; do
        set -- $combo
        { cat "$ex/$1"; printf '\n%%%%\n'; cat "$ex/$2"; printf '\n%%%%\n'; cat "$ex/$3"; } > "$d/$(echo "$1" | tr '/' '_').txt"
      done
      for f in "$SRC"/tests/bad-input/rig/**/*.yaml; do [ -f "$f" ] && cp "$f" "$d/rig-$(echo "$f" | md5sum | cut -c1-8)"; done
      for f in "$SRC"/tests/bad-input/fragment/**/*.frag; do
        [ -f "$f" ] && { cat "$ex/dawn/face.rig.yaml"; printf '\n%%%%\n'; cat "$f"; } > "$d/frag-$(echo "$f" | md5sum | cut -c1-8)"
      done ;;
  esac
  add "$SRC"/tests/fuzz/regressions/"$t"/*  # earlier findings, replayed first
  shopt -u nullglob globstar
}

one() {  # one TARGET: runs it, leaves its log in $W/TARGET.log
  local t=$1 bin=$BUILD/tests/fuzz/fuzz_$1
  seeds "$t" "$W/seeds/$t"
  rm -rf "$W/corpus/$t" && mkdir -p "$W/corpus/$t"
  "$bin" -max_total_time="$SECS" -timeout=10 -rss_limit_mb=2560 -print_final_stats=1 \
    -artifact_prefix="$W/artifacts/$t-" "$W/corpus/$t" "$W/seeds/$t" > "$W/$t.log" 2>&1
  echo $? > "$W/$t.rc"
}

for ((i = 0; i < ${#targets[@]}; i += 2)); do
  one "${targets[$i]}" &
  [ $((i + 1)) -lt ${#targets[@]} ] && one "${targets[$((i + 1))]}" &
  wait
done

fails=0
printf '%-10s %10s %8s %8s %8s  %s\n' target runs seconds exec/s corpus result
for t in "${targets[@]}"; do
  log=$W/$t.log rc=$(cat "$W/$t.rc")
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | awk '{print $2}' | tail -1)
  secs=$(grep -o 'Done [0-9]* runs in [0-9]* second' "$log" | awk '{print $5}' | tail -1)
  eps=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "$log" | awk '{print $2}' | tail -1)
  files=$(find "$W/corpus/$t" -type f | wc -l)
  result="no finding"
  if [ "$rc" != 0 ]; then
    fails=$((fails + 1))
    result="FINDING (exit $rc): $(grep -m1 -E 'ERROR: |runtime error|==[0-9]+==' "$log" | cut -c1-150)"
  fi
  printf '%-10s %10s %8s %8s %8s  %s\n' "$t" "${runs:-?}" "${secs:-?}" "${eps:-?}" "$files" "$result"
  [ "$rc" != 0 ] && { grep -E 'SUMMARY|artifact|Test unit written' "$log" | head -5 | sed 's/^/    /'; }
done
[ "$fails" -eq 0 ]
