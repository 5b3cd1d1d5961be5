// `shadergen pin merge`: one measured choice for several devices, from each device's own pin
// (bench --candidates K --pin-out), as pipeline/pin.h mergePins weighs them.
#include <fmt/format.h>

#include <iostream>

#include "cli/commands.h"
#include "pipeline/pin.h"

namespace sg {
namespace {

struct PinMergeCommand {
  std::vector<std::string> pins;
  std::string output;
  bool quiet = false;

  int run() {
    std::vector<Pin> read;
    std::vector<InputFile> inputs;
    for (const std::string& path : pins) {
      read.push_back(loadPin(path));
      inputs.push_back({path, "a pin"});
    }
    const Pin merged = mergePins(read);
    refuseClobbering({output}, inputs);
    writeFilesAtomically({{output, formatPin(merged)}});
    if (!quiet) {
      std::cout << fmt::format("{}: pins {} ({} of {} plans timed on every device)\n", output, merged.label, merged.candidates,
                               read[0].timed.size());
      std::cout << "| device | clock | its time (ns per vertex) | over the device's fastest | the generated plan's |\n";
      std::cout << "|---|---|---:|---:|---:|\n";
      for (const PinTiming& t : merged.devices)
        std::cout << fmt::format("| {} ({}) | {} | {:.4f} | {:.3f} | {:.3f} |\n", t.device, t.driver, t.clock, t.nsPerVertex,
                                 t.nsPerVertex / t.fastestNsPerVertex, t.generatedNsPerVertex / t.fastestNsPerVertex);
    }
    return 0;
  }
};

}  // namespace

void registerPin(CLI::App& app, CliState& state) {
  CLI::App* pin = app.add_subcommand("pin", "Measured choices (pins) over several devices");
  pin->require_subcommand(1);
  auto c = std::make_shared<PinMergeCommand>();
  CLI::App* merge = pin->add_subcommand(
      "merge", "One pin for several devices: of the plans each device's pin timed (bench --candidates K --pin-out, the same "
               "inputs and profiles on each), the one whose worst time over that device's fastest is least "
               "(docs/performance.md, \"Several devices\")");
  merge->add_option("pins", c->pins, "Each device's pin (bench --pin-out), two at least")->required()->expected(2, -1);
  merge->add_option("-o,--output", c->output, "The merged pin to write (generate --pin, a manifest's pins read it)")->required();
  merge->add_flag("-q,--quiet", c->quiet, "Do not print the regret table");
  merge->callback([c, &state] { state.run = [c] { return c->run(); }; });
}

}  // namespace sg
