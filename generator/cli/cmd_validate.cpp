// `shadergen validate`: generate, run on lavapipe, compare with the GLM reference.
#include "cli/commands.h"

namespace sg {

void registerValidate(CLI::App&, CliState&) {}

}  // namespace sg
