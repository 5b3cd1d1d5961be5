#include "api/shadergen.h"

#include <fmt/format.h>

#include "emit/reflection.h"
#include "pipeline/generate.h"

namespace shadergen {
namespace {

Diagnostic convert(const sg::Diagnostic& d) {
  Diagnostic o;
  o.file = d.loc.file;
  o.line = d.loc.line;
  o.column = d.loc.col;
  o.severity = d.severity == sg::Severity::Error ? "error" : d.severity == sg::Severity::Warning ? "warning" : "note";
  o.message = d.message;
  o.code = d.code;
  return o;
}

}  // namespace

std::string Diagnostic::text() const {
  std::string where = file;
  if (line > 0) where += fmt::format(":{}", line);
  if (line > 0 && column > 0) where += fmt::format(":{}", column);
  return fmt::format("{}{}{}: {}{}", where, where.empty() ? "" : ": ", severity, message,
                     code.empty() ? "" : " [" + code + "]");
}

Result generate(const Options& options) {
  Result r;
  try {
    sg::GenerateOptions o;
    o.rigPath = options.rig;
    o.fragmentPath = options.fragment;
    o.rulesPaths = options.rules;
    o.rigParams = options.rigParameters;
    for (const auto& [name, sems] : options.maps) o.overrides.push_back(sg::VaryingOverride{name, sems});
    o.conventions = options.conventions;
    if (!sg::parseTargetEnv(options.targetEnv, o.targetEnv))
      throw sg::InputError(sg::SourceLoc{}, fmt::format("unknown target environment '{}' (vulkan1.0 .. vulkan1.3)",
                                                        options.targetEnv));
    o.optimize = options.optimize;
    o.templateDir = options.templates;
    o.deviceProfilePath = options.deviceProfile;
    o.portableProfilePaths = options.portableProfiles;
    o.bannedRules = options.bannedRules;
    const Workload& w = options.workload;
    o.workload.verticesPerDraw = w.verticesPerDraw;
    o.workload.jointsPerWarp = w.jointsPerWarp;
    o.workload.activeMorphTargets = w.activeMorphTargets;
    o.workload.invocationsPerVertex = w.invocationsPerVertex;
    o.workload.fragmentsPerVertex = w.fragmentsPerVertex;
    o.workload.paletteEntriesPerWarp = w.paletteEntriesPerWarp;
    if (o.workload.known()) o.workload.source = "given by the caller";
    o.gltf.normalizeWeights = options.normalizeSkinWeights;
    o.gltf.warningsAsErrors = options.warningsAsErrors;
    if (!options.hlslShaderModel.empty()) {
      o.hlsl = sg::HlslOptions{};
      if (!sg::parseShaderModel(options.hlslShaderModel, o.hlsl->shaderModel))
        throw sg::InputError(sg::SourceLoc{}, fmt::format("unsupported shader model '{}' (supported: {})",
                                                          options.hlslShaderModel, sg::kShaderModels));
    }
    if (!options.mslVersion.empty()) {
      o.msl = sg::MslOptions{};
      if (!sg::parseMslVersion(options.mslVersion, *o.msl))
        throw sg::InputError(sg::SourceLoc{}, fmt::format("unsupported Metal Shading Language version '{}' (supported: {})",
                                                          options.mslVersion, sg::kMslVersions));
      if (!sg::parseMslPlatform(options.mslPlatform, o.msl->platform))
        throw sg::InputError(sg::SourceLoc{}, fmt::format("unknown Metal platform '{}' (macos, ios)", options.mslPlatform));
    }
    sg::GenerateResult g = sg::generate(o);
    if (g.hlsl) r.hlsl = g.hlsl->text;
    if (g.msl) r.msl = g.msl->text;
    r.glsl = g.glsl.text;
    r.spirv = g.spirv.words;
    r.reflection = sg::reflectionOf(g);
    r.cost = g.plan.cost;
    for (int a : g.plan.actions) r.rules.push_back(g.in.problem.actions[a].name);
    if (g.in.profile) {
      const sg::PlanCostPrediction c = sg::predictPlanCost(g.plan, g.in.problem, *g.in.profile);
      for (int t = 0; t < sg::kTermCount; ++t) {
        r.termAmounts[sg::termName(t)] = c.amounts[static_cast<size_t>(t)];
        r.termNanoseconds[sg::termName(t)] = c.nanoseconds[static_cast<size_t>(t)];
      }
      r.predictedNanoseconds = c.totalNanoseconds;
    }
    for (const auto& d : g.in.notes)
      if (!d.code.empty()) r.diagnostics.push_back(convert(d));  // the glTF import's findings
    r.ok = true;
  } catch (const sg::InputError& e) {
    r.diagnostics.push_back(convert(e.diagnostic()));
    for (const auto& d : e.related) r.diagnostics.push_back(convert(d));
  } catch (const std::exception& e) {
    r.diagnostics.push_back(Diagnostic{"", 0, 0, "error", e.what()});
  }
  return r;
}

const char* version() { return sg::shadergenVersion(); }

}  // namespace shadergen
