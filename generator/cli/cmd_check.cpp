// `shadergen check RULES... [--rig RIG]`: static checks of rules files (analysis/check.h)
// and, with a rig, every applicable rule run alone on a device against its semantic's
// definition (validate/rule_check.h).
#include <iostream>

#include "analysis/check.h"
#include "cli/commands.h"
#include "validate/rule_check.h"

namespace sg {
namespace {

struct CheckCommand {
  CheckOptions opts;
  bool costs = false;
  bool noCompile = false;
  bool noRun = false;
  RuleCheckOptions device;

  int run() {
    if (costs && noCompile)
      throw CLI::ValidationError("--costs", "does not apply with --no-compile: the measured costs come from compiling");
    opts.compileSnippets = !noCompile;
    CheckReport r = checkRules(opts);
    // The device part needs rules that generate: only after a clean static check.
    if (!opts.rigPath.empty() && !noRun && !noCompile && !r.schemaError && r.errors == 0) {
      device.rigPath = opts.rigPath;
      device.rulesPaths = opts.rulesPaths;
      device.gltf.warningsAsErrors = opts.werror;
      RuleCheckReport rc = checkRulesOnDevice(device);
      std::cerr << formatRuleCheckSummary(rc);
      for (const auto& d : rc.errors) r.findings.push_back(d);
      r.errors += static_cast<int>(rc.errors.size());
    }
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
  sub->add_flag("--no-run", cmd->noRun, "With --rig: do not run each rule alone on the device against its definition");
  sub->add_option("--device", cmd->device.device, "With --rig: Vulkan device name (substring); default lavapipe");
  sub->add_flag("--no-validation-layers", [cmd](int64_t) { cmd->device.validationLayers = false; },
                "With --rig: run without the Khronos validation layer");
  sub->add_option("--seed", cmd->device.seed, "With --rig: seed of the hostile mesh and pose (default 1)");
  sub->add_flag("--all", cmd->opts.all, "Also show warnings and notes located in included files (the library)");
  sub->add_flag("--Werror", cmd->opts.werror, "Treat warnings as errors (exit status 1)");
  sub->callback([cmd, &state] { state.run = [cmd] { return cmd->run(); }; });
}

}  // namespace sg
