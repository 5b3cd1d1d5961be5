#include "cli/commands.h"

#include <cmath>
#include <cstdlib>
#include <map>

#include <fmt/format.h>

namespace sg {

void refuseOption(const CLI::App& cmd, const std::string& option, const std::string& why) {
  if (cmd.count(option) > 0) throw CLI::ValidationError(option, "does not apply " + why);
}

void addProcessesOption(CLI::App& cmd, uint32_t& processes, const std::string& what) {
  cmd.add_option("--processes", processes,
                 fmt::format("Time each {0} in N fresh processes and merge their rounds (default 1): a {0}'s figures are then "
                             "the best, and the median round that --pin-out decides by the median, over every process. On "
                             "lavapipe one process in seven ran a program 25 % slower in every round (bench/data/pin38)",
                             what))
      ->check(CLI::Range(1, 32))
      ->excludes("--one-process");
}

CLI::Validator finiteNumber(bool positive) {
  return CLI::Validator(
      [positive](std::string& s) -> std::string {
        char* end = nullptr;
        double v = std::strtod(s.c_str(), &end);
        bool ok = !s.empty() && *end == '\0' && std::isfinite(v) && (positive ? v > 0 : v >= 0);
        return ok ? "" : fmt::format("must be a finite number {} 0, got '{}'", positive ? ">" : ">=", s);
      },
      positive ? "NUMBER > 0" : "NUMBER >= 0");
}

void addGltfReadOptions(CLI::App& cmd, GltfReadOptions& o, bool werror) {
  cmd.add_flag("--normalize-weights,!--no-normalize-weights", o.normalizeWeights,
               "glTF skin weights that do not sum to 1 are renormalised, as three.js and Filament's viewers do "
               "(default); --no-normalize-weights keeps them as stored (docs/gltf.md#import-diagnostics-and-weights)");
  if (werror)
    cmd.add_flag("--Werror", o.warningsAsErrors,
                 "Treat the glTF import's warnings (weights, joints, rotations, frames) as errors (also -Werror)");
}

void addInputMemoryOption(CLI::App& cmd, rt::InputMemory& memory) {
  cmd.add_option("--input-memory", memory,
                 "Where the timed programs' inputs live: device-local (default; filled by a staging copy, as an engine keeps a "
                 "mesh) or mapped (host-visible memory written in place: on a discrete GPU a BAR window)")
      ->transform(CLI::CheckedTransformer(std::map<std::string, rt::InputMemory>{{"device-local", rt::InputMemory::DeviceLocal},
                                                                                {"mapped", rt::InputMemory::Mapped}}));
}

void addOneProcessFlag(CLI::App& cmd, bool& oneProcess, const std::string& what) {
  cmd.add_flag("--one-process", oneProcess,
               fmt::format("Time every {0} in this process instead of each in a fresh one (the default): quicker to start, but "
                           "on NVIDIA a {0}'s times then depend on the {0}s timed before it, by up to 30 % "
                           "(docs/device-profiles.md, \"One process per rig\")",
                           what));
}

void registerCommands(CLI::App& app, CliState& state) {
  registerGenerate(app, state);
  registerValidate(app, state);
  registerCheck(app, state);
  registerExplain(app, state);
  registerRig(app, state);
  registerBake(app, state);
  registerRender(app, state);
  registerCalibrate(app, state);
  registerBuild(app, state);
  registerPack(app, state);
  registerPin(app, state);
}

}  // namespace sg
