# Sourced by the suite's shell scripts: `preload_only_shadergen SG "$DIR"`.
# Sanitizer runs preload the Vulkan driver into the suite (cmake/sanitizers/env.sh says
# why). Only shadergen needs it; every other process a script starts (find, sort,
# sha256sum, timeout...) would spend ~35 ms mapping lavapipe and its LLVM, which was most
# of the bad-input corpus's time under sanitizers. So the preload leaves the script's
# environment and goes back to shadergen alone: the variable named by the first argument
# (holding shadergen's path) is pointed at a wrapper in DIR that execs shadergen (the
# same process, so timeouts and signals reach shadergen itself).
preload_only_shadergen() {  # preload_only_shadergen <variable> <dir>
  local preload=${LD_PRELOAD-} wrapper=$2/shadergen-preloaded
  unset LD_PRELOAD
  [ -n "$preload" ] || return 0
  printf '#!/usr/bin/env bash\nLD_PRELOAD=%q exec %q "$@"\n' "$preload" "$(realpath "${!1}")" >"$wrapper"
  chmod +x "$wrapper"
  printf -v "$1" '%s' "$wrapper"
}
