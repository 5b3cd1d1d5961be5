#include "pipeline/generate.h"

#include <fmt/format.h>

#include <algorithm>
#include <functional>
#include <set>

#include "emit/templates.h"
#include "rig/gltf_import.h"

namespace sg {

const char* shadergenVersion() { return SHADERGEN_VERSION; }

LoadedInputs loadInputs(const GenerateOptions& opts) {
  LoadedInputs in;
  in.rig = loadRig(opts.rigPath);  // YAML, or a glTF model "model.glb#mesh/primitive"
  in.rules = loadRules(opts.rulesPaths);
  in.fragment = reflectFragmentFile(opts.fragmentPath);
  in.varyings = bindVaryings(in.fragment, in.rules, opts.overrides);
  in.problem = buildProblem(in.rig, in.rules, in.varyings);
  return in;
}

std::string explainUnreachable(const Problem& p, const RuleSet& rules) {
  std::vector<bool> reach = reachableFacts(p);
  std::vector<bool> producible(p.facts.size(), false);
  for (const auto& a : p.actions) producible[a.add] = true;
  std::string out;
  for (int g : p.goals) {
    if (reach[g]) continue;
    // Leaves: unreachable facts no instantiated rule produces (missing rig inputs).
    std::set<std::string> missing;
    std::vector<bool> seen(p.facts.size(), false);
    std::function<void(int)> walk = [&](int f) {
      if (seen[f] || reach[f]) return;
      seen[f] = true;
      if (!producible[f]) {
        missing.insert(p.facts[f].name);
        return;
      }
      for (const auto& a : p.actions)
        if (a.add == f)
          for (int q : a.pre) walk(q);
    };
    walk(g);
    std::string list;
    for (const auto& m : missing) list += (list.empty() ? "" : ", ") + m;
    out += fmt::format("cannot produce '{}': it needs {} which the rig does not provide and no applicable rule "
                       "produces",
                       p.facts[g].name, list.empty() ? "values" : list);
    std::string skipped;
    for (const auto& [r, why] : p.skippedRules)
      if (missing.count(rules.rules[r].produces) || rules.rules[r].produces == p.facts[g].name)
        skipped += fmt::format("; rule '{}' does not apply ({})", rules.rules[r].name, why);
    out += skipped + "\n";
  }
  return out;
}

GenerateResult generate(const GenerateOptions& opts) { return generateFrom(loadInputs(opts), opts); }

GenerateResult generateFrom(LoadedInputs in, const GenerateOptions& opts) {
  GenerateResult res;
  if (!opts.bannedRules.empty()) in.problem = withoutRules(in.problem, opts.bannedRules);
  auto h = makeHeuristic(opts.heuristic, in.problem);
  if (!h) throw InputError(SourceLoc{}, fmt::format("unknown heuristic '{}' (blind, hmax, lmcut)", opts.heuristic));
  std::optional<Plan> plan = astarSearch(in.problem, *h, &res.stats);
  if (!plan) {
    std::string why = explainUnreachable(in.problem, in.rules);
    // Point at the first fragment input whose request cannot be met.
    SourceLoc at{in.fragment.file, 0, 0};
    std::vector<bool> reach = reachableFacts(in.problem);
    for (const auto& v : in.varyings)
      for (const auto& s : v.semantics) {
        int f = in.problem.findFact(s);
        if (f >= 0 && !reach[f] && at.line == 0) at = v.loc.line ? v.loc : at;
      }
    if (!why.empty() && why.back() == '\n') why.pop_back();
    throw InputError(at, fmt::format("the request cannot be met for rig '{}':\n{}", in.rig.name, why));
  }
  res.plan = *plan;

  TemplateSet templates = TemplateSet::load(opts.templateDir.empty() ? defaultTemplateDir() : opts.templateDir);
  EmitOptions eo;
  eo.capture = opts.capture;
  eo.heuristic = opts.heuristic;
  eo.version = shadergenVersion();
  res.glsl = emitGlsl(in.rig, in.problem, res.plan, in.varyings, templates, in.fragment.file, eo);
  res.spirv = compileVertexShader(res.glsl, opts.outputName, opts.targetEnv);
  if (std::string err = validateSpirv(res.spirv.words, opts.targetEnv); !err.empty())
    throw InputError(SourceLoc{opts.outputName, 0, 0}, "generated SPIR-V fails validation: " + err);
  checkLink(res.glsl, in.fragment.source, in.fragment.file, opts.targetEnv);
  if (opts.optimize) {
    res.spirv.words = optimizeSpirv(res.spirv.words, opts.targetEnv);
    if (std::string err = validateSpirv(res.spirv.words, opts.targetEnv); !err.empty())
      throw InputError(SourceLoc{opts.outputName, 0, 0}, "optimised SPIR-V fails validation: " + err);
  }
  res.inputsRead.push_back(in.rig.file);
  res.inputsRead.push_back(in.fragment.file);
  for (const auto& f : in.rules.files) res.inputsRead.push_back(f);
  res.inputsRead.push_back(templates.file());
  res.in = std::move(in);
  return res;
}

}  // namespace sg
