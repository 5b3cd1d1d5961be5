// `shadergen explain`: the chosen plan as a tree with each choice's cheapest alternative;
// `shadergen graph`: the plan as Graphviz DOT (and SVG through `dot`). analysis/explain.h,
// analysis/graph.h.
#include <fmt/format.h>

#include <filesystem>
#include <iostream>

#include "analysis/explain.h"
#include "analysis/graph.h"
#include "cli/commands.h"
#include "cli/output_files.h"
#include "common/content_hash.h"
#include "pipeline/generate.h"
#include "search/astar.h"

namespace sg {
namespace {

// Loads the inputs with --ban applied and searches as generate does (pipeline/generate.h: the
// device limits, several profiles' regret), so that the plan shown is the plan generated;
// nullopt plan = a request no rule reaches (explained by the caller). No plan within the device
// limits: generate's located error.
std::pair<LoadedInputs, std::optional<Plan>> loadAndSearch(const GenerateOptions& o) {
  LoadedInputs in = loadInputs(o);
  if (!o.bannedRules.empty()) in.problem = withoutRules(in.problem, o.bannedRules);
  const std::vector<bool> reachable = reachableFacts(in.problem);
  for (int g : in.problem.goals)
    if (!reachable[static_cast<size_t>(g)]) return {std::move(in), std::nullopt};
  GenerateOptions searched = o;
  searched.bannedRules.clear();  // applied above
  Plan plan = searchUnderOptions(in, searched);
  if (o.pin) {  // as generate checks and warns
    checkPin(*o.pin, in.problem, plan);
    if (auto changed = pinInputsChanged(*o.pin, sha256OfFiles(pinnedInputs(in, loadTemplatesStage(o.templateDir)))))
      std::cerr << formatDiagnostic(*changed) << "\n";
  }
  return {std::move(in), std::move(plan)};
}

// explain and graph search with the default engine and write no shader: the generate
// options about the engine, its limits and the templates would be silently ignored.
void refuseSearchAndEmitOptions(const CLI::App& cmd) {
  for (const char* o : {"--search", "--search-time-limit", "--max-expansions", "--templates"})
    refuseOption(cmd, o, fmt::format("to '{}': it searches with the default engine and writes no shader", cmd.get_name()));
}

struct ExplainCommand {
  CLI::App* cmd = nullptr;
  GenerateArgs args;
  bool noAlternatives = false;
  std::string mesh;

  int run() {
    refuseSearchAndEmitOptions(*cmd);
    GenerateOptions o = args.resolve();
    measureWorkloadOf(o, mesh);
    auto [in, plan] = loadAndSearch(o);
    if (!plan) {
      std::cout << fmt::format("the request cannot be met for rig '{}' and fragment shader '{}':\n", in.rig.name,
                               std::filesystem::path(in.fragment.file).filename().string());
      std::cout << formatUnreachable(in.problem, analyzeUnreachable(in.problem, in.rules, in.varyings));
      return 1;
    }
    ExplainOptions eo;
    eo.heuristic = o.heuristic;
    eo.alternatives = !noAlternatives;
    std::cout << formatExplanation(in, explainPlan(in, *plan, eo));
    return 0;
  }
};

struct GraphCommand {
  CLI::App* cmd = nullptr;
  GenerateArgs args;
  std::string output;
  std::string svg;

  int run() {
    refuseSearchAndEmitOptions(*cmd);
    GenerateOptions o = args.resolve();
    if (!svg.empty() && findOnPath("dot").empty())
      throw std::runtime_error("cannot write " + svg + ": Graphviz 'dot' is not on PATH (install graphviz)");
    auto [in, plan] = loadAndSearch(o);
    if (!plan) {
      std::string why = formatUnreachable(in.problem, analyzeUnreachable(in.problem, in.rules, in.varyings));
      if (!why.empty() && why.back() == '\n') why.pop_back();
      throw InputError(SourceLoc{in.fragment.file, 0, 0},
                       fmt::format("the request cannot be met for rig '{}':\n{}", in.rig.name, why));
    }
    std::string dot = planToDot(in, *plan);
    std::vector<std::string> outs;
    if (!output.empty() && output != "-") outs.push_back(output);
    if (!svg.empty()) outs.push_back(svg);
    refuseClobbering(outs, inputFiles(in));
    if (output.empty() || output == "-") std::cout << dot;
    else writeFilesAtomically({{output, dot}});
    if (!svg.empty()) renderSvg(dot, svg);
    return 0;
  }
};

}  // namespace

void registerExplain(CLI::App& app, CliState& state) {
  auto ex = std::make_shared<ExplainCommand>();
  CLI::App* sub = app.add_subcommand("explain", "Show the chosen plan, its costs, and each choice's best alternative");
  ex->cmd = sub;
  ex->args.add(*sub);
  sub->add_flag("--no-alternatives", ex->noAlternatives, "Do not re-search for each choice's alternative");
  sub->add_option("--mesh", ex->mesh,
                  "YAML rig: the procedural mesh the program will draw (head, limb, dawn), whose workload is shown and "
                  "priced by a device profile; a glTF rig is measured on its own mesh. Default: unknown")
      ->check(CLI::IsMember({"head", "limb", "dawn"}));
  sub->callback([ex, &state] { state.run = [ex] { return ex->run(); }; });

  auto gr = std::make_shared<GraphCommand>();
  CLI::App* g = app.add_subcommand("graph", "Write the chosen plan as a Graphviz DOT graph (and SVG)");
  gr->cmd = g;
  gr->args.add(*g);
  g->add_option("-o", gr->output, "DOT output path (default: standard output)");
  g->add_option("--svg", gr->svg, "Also render SVG with Graphviz 'dot' (must be on PATH)");
  g->callback([gr, &state] { state.run = [gr] { return gr->run(); }; });
}

}  // namespace sg
