#include "pipeline/generate.h"

#include <fmt/format.h>

#include <algorithm>
#include <functional>
#include <set>

#include "analysis/cost.h"
#include "analysis/explain.h"
#include "analysis/probe.h"
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
  for (const auto& b : opts.bannedRules)  // a misspelt --ban would otherwise change nothing silently
    if (std::none_of(in.rules.rules.begin(), in.rules.rules.end(), [&](const Rule& r) { return r.name == b; }))
      throw InputError(SourceLoc{}, fmt::format("--ban {}: no rule of that name in the rules files", b));
  resolveAutoCosts(in.rules, in.rig);  // `cost: auto`: measured for this rig
  in.problem = buildProblem(in.rig, in.rules, in.varyings);
  return in;
}

std::string explainUnreachable(const Problem& p, const RuleSet& rules) {
  // Minimal sets of missing rig inputs per unreachable goal (analysis/explain.h).
  return formatUnreachable(p, analyzeUnreachable(p, rules, {}));
}

GenerateResult generate(const GenerateOptions& opts) { return generateFrom(loadInputs(opts), opts); }

GenerateResult generateFrom(LoadedInputs in, const GenerateOptions& opts) {
  GenerateResult res;
  if (!opts.bannedRules.empty()) in.problem = withoutRules(in.problem, opts.bannedRules);
  if (!makeHeuristic(opts.heuristic, in.problem))
    throw InputError(SourceLoc{}, fmt::format("unknown heuristic '{}' (blind, hmax, lmcut)", opts.heuristic));
  std::optional<Plan> plan;
  try {
    plan = findPlan(in.problem, SearchOptions{opts.searchEngine, opts.heuristic, opts.searchLimits}, &res.stats);
  } catch (const std::invalid_argument& e) {  // unknown engine, or regression on a cyclic rule graph
    throw InputError(SourceLoc{}, e.what());
  }
  if (!plan) {
    std::string why = formatUnreachable(in.problem, analyzeUnreachable(in.problem, in.rules, in.varyings));
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
  try {
    res.spirv = compileVertexShader(res.glsl, opts.outputName, opts.targetEnv);
  } catch (const InputError& e) {
    // glslang reports lines only: point the columns at the snippet text in the rules file.
    std::vector<SourceLoc> snippetLines;
    for (int a : res.plan.actions)
      for (const auto& l : in.problem.actions[a].code) snippetLines.push_back(l.loc);
    throw refineSnippetError(e, snippetLines);
  }
  if (std::string err = validateSpirv(res.spirv.words, opts.targetEnv); !err.empty())
    throw InputError(SourceLoc{opts.outputName, 0, 0}, "generated SPIR-V fails validation: " + err);
  if (res.spirv.uniformBlockSize > opts.maxUniformBlockBytes) {
    // Point at the largest uniform the plan reads (a bone palette, usually).
    SourceLoc at{in.rig.file, 0, 0};
    std::string list;
    int64_t largest = -1;
    for (const auto& u : res.glsl.uniforms) {
      const RigUniform& ru = in.rig.uniforms[u.uniform];
      int64_t bytes = int64_t{componentCount(ru.type)} * 4 * std::max(1, ru.arraySize);
      list += fmt::format("{}{} {}{}", list.empty() ? "" : ", ", glslName(ru.type), ru.name,
                          ru.arraySize ? fmt::format("[{}]", ru.arraySize) : "");
      if (bytes > largest) {
        largest = bytes;
        at = ru.loc;
      }
    }
    throw InputError(at, fmt::format("the uniform block is {} bytes (std140: {}), larger than the {} bytes of "
                                     "maxUniformBufferRange that every Vulkan device supports",
                                     res.spirv.uniformBlockSize, list, opts.maxUniformBlockBytes));
  }
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
