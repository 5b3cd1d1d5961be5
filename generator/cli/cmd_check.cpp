// `shadergen check RULES... [--rig RIG]`: static checks of rules files (analysis/check.h).
#include <iostream>

#include "analysis/check.h"
#include "cli/commands.h"

namespace sg {
namespace {

struct CheckCommand {
  CheckOptions opts;
  bool costs = false;
  bool noCompile = false;

  int run() {
    if (costs && noCompile)
      throw CLI::ValidationError("--costs", "does not apply with --no-compile: the measured costs come from compiling");
    opts.compileSnippets = !noCompile;
    CheckReport r = checkRules(opts);
    std::cerr << formatCheckReport(r);
    if (costs && !r.schemaError) std::cout << formatCostTable(r);
    return r.errors ? 1 : 0;
  }
};

}  // namespace

void registerCheck(CLI::App& app, CliState& state) {
  auto cmd = std::make_shared<CheckCommand>();
  CLI::App* sub = app.add_subcommand("check", "Check rules files: schema, names, cycles, dead rules, snippets, costs");
  sub->add_option("rules", cmd->opts.rulesPaths, "Rules file(s) (YAML)")->required();
  sub->add_option("--rig", cmd->opts.rigPath, "Check against this rig (default: built-in default rigs)");
  sub->add_flag("--costs", cmd->costs, "Print each rule's stated and measured (auto) cost");
  sub->add_flag("--no-compile", cmd->noCompile, "Do not compile snippets (no compile or cost findings)");
  sub->add_flag("--all", cmd->opts.all, "Also show warnings and notes located in included files (the library)");
  sub->add_flag("--Werror", cmd->opts.werror, "Treat warnings as errors (exit status 1)");
  sub->callback([cmd, &state] { state.run = [cmd] { return cmd->run(); }; });
}

}  // namespace sg
