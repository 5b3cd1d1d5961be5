#include "cli/commands.h"

namespace sg {

void registerCommands(CLI::App& app, CliState& state) {
  registerGenerate(app, state);
  registerValidate(app, state);
  registerCheck(app, state);
  registerExplain(app, state);
  registerRig(app, state);
  registerBake(app, state);
  registerBuild(app, state);
}

}  // namespace sg
