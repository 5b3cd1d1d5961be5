#!/usr/bin/env bash
# One entry point for a fresh Debian machine: installs dependencies, builds, then
#   dawn  - generates the Dawn face vertex shader and validates it on lavapipe
#   test  - runs the whole test suite
#   build - only builds
set -euo pipefail
cd "$(dirname "$0")/.."
what=${1:-test}

packages=(
  build-essential cmake ninja-build pkg-config
  glslang-dev glslang-tools spirv-tools
  libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers
  libglm-dev libyaml-cpp-dev libfmt-dev libcli11-dev
  libtinygltf-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev graphviz
  libembree-dev
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
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo
cmake --build "$build"

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
    ;;
  build) ;;
  *) echo "usage: cmake/dev.sh [dawn|test|build]" >&2; exit 2 ;;
esac
