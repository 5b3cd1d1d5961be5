#!/usr/bin/env bash
# One entry point for a fresh Debian machine: installs dependencies, builds, then
#   dawn     - generates the Dawn face vertex shader and validates it on lavapipe
#   test     - what CI runs: builds the product as users get it (GCC, Release: CLI, libraries,
#              benchmarks) and runs the tests that need it uninstrumented (CMake package,
#              benchmark smoke), then `sanitize` (every test, under ASan + UBSan) and `fuzz`
#   plain    - builds everything uninstrumented and runs the whole suite there (4 min on
#              2 cores: the quick full run while developing)
#   build    - only builds
#   sanitize - builds everything with ASan + UBSan (Clang, build-sanitize/) and runs the
#              whole test suite there
#   fuzz     - builds that tree and runs each libFuzzer target for SHADERGEN_FUZZ_SECONDS
#              (default 60) seconds, seeded from the repository (tests/fuzz/run.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
what=${1:-test}

# What the CLI needs to build and run; the suite adds its frameworks, the sanitized tree Clang.
packages=(
  build-essential cmake ninja-build pkg-config
  glslang-dev glslang-tools spirv-tools
  libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers
  libglm-dev libyaml-cpp-dev libfmt-dev libcli11-dev
  libtinygltf-dev nlohmann-json3-dev libmeshoptimizer-dev
  libglpk-dev
  libceres-dev
  libembree-dev
  libpng-dev
  spirv-cross libspirv-cross-c-shared-dev
  libssl-dev libcurl4-openssl-dev  # `build`: SHA-256 (libcrypto), the shared cache's HTTP client
)
# nginx: the shared cache's server in tests/variants (Debian's nginx has http_dav_module).
test_packages=(libgtest-dev libgmock-dev libbenchmark-dev graphviz nginx)
sanitize_packages=(clang-14 libclang-rt-14-dev lld-14)
case "$what" in
  dawn) ;;
  build) packages+=("${test_packages[@]}") ;;
  *) packages+=("${test_packages[@]}" "${sanitize_packages[@]}") ;;
esac
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  echo "installing: ${missing[*]}"
  $sudo apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# The suite's outside implementations (three.js, the Khronos glTF-Validator) are npm packages
# pinned by tests/js/package-lock.json; Node.js comes from Debian where the machine has none.
if [ "$what" = test ] || [ "$what" = plain ] || [ "$what" = build ] || [ "$what" = sanitize ]; then
  if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
    sudo=""; [ "$(id -u)" -eq 0 ] || sudo="sudo"
    $sudo apt-get update -q
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends nodejs npm
  fi
  # npm ci once per lockfile: the stamp is the lockfile it installed.
  if ! cmp -s tests/js/package-lock.json tests/js/node_modules/.sg-installed-lock 2>/dev/null; then
    (cd tests/js && npm ci --no-audit --no-fund --loglevel=error && cp package-lock.json node_modules/.sg-installed-lock)
  fi
fi

# The Vulkan loader wants a runtime dir; lavapipe needs nothing else.
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp/shadergen-xdg}
mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"

# Each phase prints its wall time, so a slow CI run shows where the time went.
timed() {  # timed NAME COMMAND...
  local t0=$SECONDS rc=0
  "${@:2}" || rc=$?
  echo "== dev.sh: $1 took $((SECONDS - t0)) s (exit $rc)"
  return $rc
}
build=${SHADERGEN_BUILD_DIR:-build}
# Release: debug information costs a third of the compile time and most of the link time;
# configure a tree of your own with RelWithDebInfo or Debug to debug.
build_type=${SHADERGEN_BUILD_TYPE:-Release}
# Unity builds: the big headers (glslang, yaml-cpp, CLI11, tinygltf, fmt) are parsed once per
# batch of 8 files instead of once per file, which halves a cold build (the CLI: 322 s ->
# 168 s on 2 cores). A tree configured by hand builds file by file; SHADERGEN_UNITY=OFF here.
unity=(-DCMAKE_UNITY_BUILD="${SHADERGEN_UNITY:-ON}" -DCMAKE_UNITY_BUILD_BATCH_SIZE=8)
plain_build() {  # plain_build [target...]: only those targets; the suite is configured if asked
  local suite=${SHADERGEN_SUITE:-ON}
  [ $# -gt 0 ] && suite=${SHADERGEN_SUITE:-OFF}
  # -O2 for Release too: CMake's -O3 compiles slower and bought nothing measurable here.
  cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE="$build_type" -DCMAKE_CXX_FLAGS_RELEASE="-O2 -DNDEBUG" \
    "${unity[@]}" -DSHADERGEN_BUILD_TESTS=$suite -DSHADERGEN_BUILD_BENCH=$suite >/dev/null
  if [ $# -gt 0 ]; then cmake --build "$build" --target "$@"; else cmake --build "$build"; fi
}
# The product (CLI, libraries, benchmarks) in the plain tree, with the suite configured so
# that its uninstrumented tests can run: labels cmake and bench, and the tests that shrink or
# skip their data under sanitizers (`SG_SANITIZED`; tests/validate: `kSanitized`), which are built for it.
full_scale_tests='^(Buffers\.Face52TargetsAt180kVerticesDenseAndSparse|Program\.AgreesWithTreeOnDawnSubset|Program\.AgreesWithTreeOnRandomDefinitions|RuleCheck\.StandardLibraryOverSeveralRigsChecksEveryRule|ThreeJs\.EverySharedModelAgreesWithThreeJs)$'
product_build() {
  SHADERGEN_SUITE=ON plain_build generator/all runtime/all generator/validate/all generator/render/all generator/measure/all \
    generator/bake/all generator/cli/all bench/all test_validate_buffers test_validate_program test_validate_rule_check \
    test_gltf_three
}
product_test() {
  local n labelled
  n=$(ctest --test-dir "$build" -N -R "$full_scale_tests" | sed -n 's/^Total Tests: //p')
  [ "$n" = 5 ] || { echo "dev.sh: $n of the 5 full-scale tests found (renamed? update full_scale_tests)" >&2; return 1; }
  # One ctest run for both sets: three of the cmake tests hold one lock (cmake_configure) and
  # run one after another for about a minute; the full-scale tests fill the other core
  # meanwhile instead of running afterwards (two runs: 88 s on 2 cores).
  labelled=$(ctest --test-dir "$build" -N -L 'cmake|bench' | sed -n 's/^ *Test *#[0-9]*: //p' | paste -sd'|')
  [ -n "$labelled" ] || { echo "dev.sh: no tests labelled cmake or bench" >&2; return 1; }
  ctest --test-dir "$build" --output-on-failure -j"$(nproc)" -R "^($labelled)\$|$full_scale_tests"
}
# One instrumented tree serves both the sanitizer suite and the fuzz targets.
sanitize_build=${SHADERGEN_SANITIZE_BUILD_DIR:-build-sanitize}
# LLD links its ~50 instrumented executables in a third of GNU ld's time (138 -> 45 CPU s
# for all of them, about 45 s of the build on 2 cores); the objects and the runtime are the same.
sanitize_build() {
  cmake -S . -B "$sanitize_build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++-14 \
    -DCMAKE_EXE_LINKER_FLAGS=-fuse-ld=lld-14 \
    "${unity[@]}" -DSHADERGEN_SANITIZE=ON -DSHADERGEN_FUZZ=ON -DSHADERGEN_BUILD_BENCH=OFF
  (source cmake/sanitizers/env.sh && cmake --build "$sanitize_build")
}
sanitize_test() {
  # Sanitized binaries run several times slower: the corpus's per-case limit scales with it.
  (source cmake/sanitizers/env.sh && SHADERGEN_CORPUS_TIME_SCALE=${SHADERGEN_CORPUS_TIME_SCALE:-10} \
     LD_PRELOAD=$sg_vulkan_driver ctest --test-dir "$sanitize_build" --output-on-failure -j"$(nproc)")
}
fuzz_run() { bash tests/fuzz/run.sh "$sanitize_build" "${SHADERGEN_FUZZ_SECONDS:-60}"; }

case "$what" in
  sanitize) timed sanitize-build sanitize_build && timed sanitize-test sanitize_test; exit ;;
  fuzz) timed sanitize-build sanitize_build && timed fuzz fuzz_run; exit ;;
  dawn)
    # Only the CLI: the tests and benchmarks are not needed to generate and validate.
    timed build plain_build shadergen
    mkdir -p "$build/dawn"
    "$build/generator/cli/shadergen" generate \
      --rig examples/dawn/face.rig.yaml -f examples/dawn/face.frag -r examples/dawn/rules.yaml \
      --emit glsl,spv,reflection -o "$build/dawn/face"
    spirv-val "$build/dawn/face.spv" && echo "spirv-val: $build/dawn/face.spv is valid"
    timed validate "$build/generator/cli/shadergen" validate \
      --rig examples/dawn/face.rig.yaml -f examples/dawn/face.frag -r examples/dawn/rules.yaml \
      --mesh dawn --cross-check
    ;;
  test)
    # Every test runs once, in the sanitized tree; the plain tree contributes the product's
    # GCC build and the tests the sanitized tree cannot run. Running the whole suite twice
    # doubled CI's test time for the same assertions (docs/design.md, "CI runs each test once").
    timed build product_build
    timed test product_test
    timed sanitize-build sanitize_build
    timed sanitize-test sanitize_test
    # CI's share of fuzzing: the seeds replayed and 10 s of search per target (the `fuzz`
    # job runs 60 s, and longer with SHADERGEN_FUZZ_SECONDS).
    SHADERGEN_FUZZ_SECONDS=${SHADERGEN_FUZZ_SECONDS:-10} timed fuzz fuzz_run
    ;;
  plain)
    timed build plain_build
    timed test ctest --test-dir "$build" --output-on-failure -j"$(nproc)"
    ;;
  build) timed build plain_build ;;
  *) echo "usage: cmake/dev.sh [dawn|test|plain|build|sanitize|fuzz]" >&2; exit 2 ;;
esac
