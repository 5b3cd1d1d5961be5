// `shadergen validate`: generate, run on lavapipe, compare with the GLM reference.
#include <fmt/format.h>

#include <iostream>

#include "cli/commands.h"
#include "validate/validate.h"

namespace sg {
namespace {

struct ValidateCommand {
  GenerateArgs args;
  std::string mesh = "head";
  uint32_t seed = 1;
  int poses = 2;
  bool crossCheck = false;
  std::string device;
  bool noLayers = false;
  Tolerance tol;

  int run() {
    ValidateOptions vo;
    vo.gen = args.resolve();
    vo.crossCheck = crossCheck;
    vo.device = device;
    vo.validationLayers = !noLayers;
    vo.tolerance = tol;
    Rig rig = loadRigFile(vo.gen.rigPath);
    ValidationScene scene = proceduralScene(rig, mesh, seed, poses);
    Validator v(vo);
    ValidateReport report = v.run(scene);
    std::cout << fmt::format("mesh '{}' ({} vertices), {} pose(s) from seed {}\n", scene.mesh.name,
                             scene.mesh.vertexCount, scene.poses.size(), seed);
    std::cout << formatReport(report);
    return report.pass ? 0 : 1;
  }
};

}  // namespace

void registerValidate(CLI::App& app, CliState& state) {
  auto cmd = std::make_shared<ValidateCommand>();
  CLI::App* sub = app.add_subcommand("validate", "Generate, run on lavapipe and compare with the GLM reference");
  cmd->args.add(*sub);
  sub->add_option("--mesh", cmd->mesh, "Procedural mesh: head (default), limb, dawn (180k vertices)")
      ->check(CLI::IsMember({"head", "limb", "dawn"}));
  sub->add_option("--seed", cmd->seed, "Seed of the random poses");
  sub->add_option("--poses", cmd->poses, "Number of random poses")->check(CLI::Range(1, 100));
  sub->add_flag("--cross-check", cmd->crossCheck, "Also force and check every alternative derivation");
  sub->add_option("--device", cmd->device, "Vulkan device name (substring); default lavapipe");
  sub->add_flag("--no-validation-layers", cmd->noLayers, "Run without the Khronos validation layer");
  sub->add_option("--tolerance-abs", cmd->tol.abs, "Absolute tolerance (see docs/validation.md)");
  sub->add_option("--tolerance-rel", cmd->tol.rel, "Relative tolerance (see docs/validation.md)");
  sub->callback([cmd, &state] { state.run = [cmd] { return cmd->run(); }; });
}

}  // namespace sg
