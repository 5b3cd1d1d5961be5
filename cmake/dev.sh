#!/usr/bin/env bash
# One entry point for a fresh Debian machine: installs dependencies, builds, then
#   dawn     - generates the Dawn face vertex shader and validates it on lavapipe
#   test     - runs the whole test suite, then `sanitize` and `fuzz` (what CI runs)
#   build    - only builds
#   sanitize - builds everything with ASan + UBSan (Clang, build-sanitize/) and runs the
#              whole test suite there
#   fuzz     - builds that tree and runs each libFuzzer target for SHADERGEN_FUZZ_SECONDS
#              (default 60) seconds, seeded from the repository (tests/fuzz/run.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
what=${1:-test}

packages=(
  build-essential cmake ninja-build pkg-config
  glslang-dev glslang-tools spirv-tools
  libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers
  libglm-dev libyaml-cpp-dev libfmt-dev libcli11-dev
  libtinygltf-dev nlohmann-json3-dev libmeshoptimizer-dev
  libgtest-dev libgmock-dev libbenchmark-dev graphviz
  clang-14 libclang-rt-14-dev
  libglpk-dev
  libembree-dev
  libpng-dev
  spirv-cross libspirv-cross-c-shared-dev
)
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

# The Vulkan loader wants a runtime dir; lavapipe needs nothing else.
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp/shadergen-xdg}
mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"

build=${SHADERGEN_BUILD_DIR:-build}
plain_build() {
  cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo
  cmake --build "$build"
}
# One instrumented tree serves both the sanitizer suite and the fuzz targets.
sanitize_build=${SHADERGEN_SANITIZE_BUILD_DIR:-build-sanitize}
sanitize_build() {
  cmake -S . -B "$sanitize_build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++-14 \
    -DSHADERGEN_SANITIZE=ON -DSHADERGEN_FUZZ=ON -DSHADERGEN_BUILD_BENCH=OFF
  (source cmake/sanitizers/env.sh && cmake --build "$sanitize_build")
}
sanitize_test() {
  # Sanitized binaries run several times slower: the corpus's per-case limit scales with it.
  (source cmake/sanitizers/env.sh && SHADERGEN_CORPUS_TIME_SCALE=${SHADERGEN_CORPUS_TIME_SCALE:-10} \
     LD_PRELOAD=$sg_vulkan_driver ctest --test-dir "$sanitize_build" --output-on-failure -j2)
}
fuzz_run() { bash tests/fuzz/run.sh "$sanitize_build" "${SHADERGEN_FUZZ_SECONDS:-60}"; }

case "$what" in
  sanitize) sanitize_build && sanitize_test; exit ;;
  fuzz) sanitize_build && fuzz_run; exit ;;
esac
plain_build

case "$what" in
  dawn)
    mkdir -p "$build/dawn"
    "$build/generator/cli/shadergen" generate \
      --rig examples/dawn/face.rig.yaml -f examples/dawn/face.frag -r examples/dawn/rules.yaml \
      --emit glsl,spv,reflection -o "$build/dawn/face"
    spirv-val "$build/dawn/face.spv" && echo "spirv-val: $build/dawn/face.spv is valid"
    if "$build/generator/cli/shadergen" validate --help >/dev/null 2>&1; then
      "$build/generator/cli/shadergen" validate \
        --rig examples/dawn/face.rig.yaml -f examples/dawn/face.frag -r examples/dawn/rules.yaml \
        --mesh dawn --cross-check
    fi
    ;;
  test)
    ctest --test-dir "$build" --output-on-failure -j2
    sanitize_build
    sanitize_test
    fuzz_run
    ;;
  build) ;;
  *) echo "usage: cmake/dev.sh [dawn|test|build|sanitize|fuzz]" >&2; exit 2 ;;
esac
