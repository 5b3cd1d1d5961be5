# Sourced by the suite's shell scripts: `preload_only_shadergen SG "$DIR"`.
# Sanitizer runs preload the Vulkan driver into the suite (cmake/sanitizers/env.sh says
# why). Only shadergen needs it; every other process a script starts (find, sort,
# sha256sum, timeout...) would spend ~35 ms mapping lavapipe and its LLVM, which was most
# of the bad-input corpus's time under sanitizers. So the preload leaves the script's
# environment and goes back to shadergen alone: the variable named by the first argument
# (holding shadergen's path) is pointed at a wrapper in DIR that execs shadergen (the
# same process, so timeouts and signals reach shadergen itself), with the driver preloaded
# for the subcommands that open a Vulkan device only: generate, explain, pack... never do,
# and mapping lavapipe cost each of their runs 0.1-0.2 s. One that did would fail loudly
# (LeakSanitizer reports the unloaded driver's globals).
#
# Unsetting LD_PRELOAD does not unmap the driver from the script's own shell, and every
# fork of a shell that has it mapped ($(...), pipelines, each command it starts) costs
# 4-5 times as much (24 ms instead of 6 ms a subshell): 60 of bad_input_cli's 90 s. So each
# script's first line, before anything else, starts it again without the driver mapped:
#   [ -z "${LD_PRELOAD-}" ] || SG_SHADERGEN_PRELOAD=$LD_PRELOAD LD_PRELOAD= exec bash "$0" "$@"
# and preload_only_shadergen takes the preload from SG_SHADERGEN_PRELOAD.
preload_only_shadergen() {  # preload_only_shadergen <variable> <dir>
  local preload=${LD_PRELOAD:-${SG_SHADERGEN_PRELOAD-}} wrapper=$2/shadergen-preloaded
  unset LD_PRELOAD SG_SHADERGEN_PRELOAD
  [ -n "$preload" ] || return 0
  printf '#!/usr/bin/env bash\ncase "${1-}" in %s) export LD_PRELOAD=%q ;; esac\nexec %q "$@"\n' \
    'validate | check | render | bench | calibrate | build' "$preload" "$(realpath "${!1}")" >"$wrapper"
  chmod +x "$wrapper"
  printf -v "$1" '%s' "$wrapper"
}
