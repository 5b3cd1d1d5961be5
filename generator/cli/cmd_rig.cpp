#include "cli/commands.h"

namespace sg {

void registerRig(CLI::App&, CliState&) {}

}  // namespace sg
