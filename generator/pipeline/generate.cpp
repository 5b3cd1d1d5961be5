#include "pipeline/generate.h"

#include <fmt/format.h>

#include <algorithm>
#include <queue>
#include <set>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "analysis/cost.h"
#include "analysis/explain.h"
#include "analysis/probe.h"
#include "emit/reflection.h"
#include "rig/gltf_import.h"
#include "rig/rig_lod.h"
#include "rig/vertex_encoding.h"
#include "search/search.h"

namespace sg {

const char* shadergenVersion() { return SHADERGEN_VERSION; }

// ---- stages -----------------------------------------------------------------------------

Rig loadRigStage(const std::string& path, const GltfReadOptions& gltf) { return loadRig(path, gltf); }

RuleSet loadRulesStage(const std::vector<std::string>& paths) { return loadRules(paths); }

FragmentInterface loadFragmentStage(const std::string& path, TargetEnv env) { return reflectFragmentFile(path, env); }

TemplateSet loadTemplatesStage(const std::string& dir) {
  return TemplateSet::load(dir.empty() ? defaultTemplateDir() : dir);
}

namespace {

// One error per fragment input whose semantics no plan can produce, at its declaration,
// with the smallest sets of missing rig inputs (analysis/explain.h). Empty if all are reachable.
std::vector<Diagnostic> unreachableInputs(const LoadedInputs& in) {
  const Problem& p = in.problem;
  std::vector<UnreachableGoal> goals = analyzeUnreachable(p, in.rules, in.varyings);
  std::vector<Diagnostic> out;
  for (const auto& v : in.varyings) {
    std::vector<UnreachableGoal> mine;
    for (const auto& g : goals)
      if (std::find(v.semantics.begin(), v.semantics.end(), p.facts[g.fact].name) != v.semantics.end()) mine.push_back(g);
    if (mine.empty()) continue;
    std::string why = formatUnreachable(p, mine);
    if (!why.empty() && why.back() == '\n') why.pop_back();
    // gl_Position is requested by no declaration: what it lacks (a camera) is the rig's.
    SourceLoc at = v.loc.line ? v.loc : in.rig.nameLoc.line ? in.rig.nameLoc : SourceLoc{in.fragment.file, 0, 0};
    out.push_back(Diagnostic{Severity::Error, at, fmt::format("the request cannot be met for rig '{}': {}", in.rig.name, why)});
  }
  return out;
}

// Several located errors as one InputError, in source order (the first is the primary one),
// then the notes that explain them.
[[noreturn]] void throwAll(std::vector<Diagnostic> errors, const std::vector<Diagnostic>& notes = {}) {
  std::stable_sort(errors.begin(), errors.end(), [](const Diagnostic& a, const Diagnostic& b) {
    return std::tie(a.loc.file, a.loc.line, a.loc.col) < std::tie(b.loc.file, b.loc.line, b.loc.col);
  });
  InputError e(errors[0]);
  e.related.assign(errors.begin() + 1, errors.end());
  e.related.insert(e.related.end(), notes.begin(), notes.end());
  throw e;
}

// Validation captures a vertex's outputs, gl_Position first, into one transform-feedback
// buffer (glsl.captureStride bytes a vertex): the record must fit the device that runs it.
// Located at the fragment input whose output first crosses the limit.
void checkCaptureFits(const LoadedInputs& in, const EmittedGlsl& glsl, uint32_t maxBytes) {
  if (glsl.captureStride <= maxBytes) return;
  SourceLoc at{in.fragment.file, 0, 0};
  std::string crossing;
  for (const auto& o : glsl.outputs) {
    const uint32_t end = o.captureOffset + 4u * static_cast<uint32_t>(componentCount(o.type) * std::max(1, o.arraySize));
    if (end <= maxBytes || !crossing.empty()) continue;
    crossing = o.name;
    for (const auto& v : in.varyings)
      if (v.name == o.name && v.loc.line) at = v.loc;
  }
  throw InputError(at, fmt::format("validation captures gl_Position and every output of the program, {} bytes a vertex "
                                   "({} components), in one transform-feedback buffer; the device captures at most {} "
                                   "bytes a vertex (the least of its maxTransformFeedbackBufferDataStride, "
                                   "maxTransformFeedbackBufferDataSize and maxTransformFeedbackStreamDataSize); '{}' "
                                   "is past it",
                                   glsl.captureStride, glsl.captureStride / 4, maxBytes, crossing));
}

}  // namespace

LoadedInputs instantiateStage(Rig rig, RuleSet rules, FragmentInterface fragment,
                              const std::vector<VaryingOverride>& overrides, const std::vector<std::string>& conventions) {
  LoadedInputs in;
  in.rig = std::move(rig);
  in.rules = std::move(rules);
  in.fragment = std::move(fragment);
  VaryingBinding bound = bindVaryingsCollect(in.fragment, in.rules, overrides, conventions);
  in.varyings = std::move(bound.varyings);
  resolveAutoCosts(in.rules, in.rig);  // `cost: auto`: measured for this rig
  in.problem = buildProblem(in.rig, in.rules, in.varyings);
  if (!bound.errors.empty()) {
    // Every problem in one run: the unmapped inputs, and those mapped but unproducible.
    std::vector<Diagnostic> all = std::move(bound.errors);
    for (auto& d : unreachableInputs(in)) all.push_back(std::move(d));
    throwAll(std::move(all));
  }
  return in;
}

DeviceProfile loadDeviceProfileStage(const std::string& path) { return loadDeviceProfile(path); }

void priceStage(LoadedInputs& in, const DeviceProfile& profile) {
  measureAccessTerms(in.problem, in.rules, in.rig);
  applyDeviceProfile(in.problem, profile);
  in.profile = profile;
}

Plan searchStage(const LoadedInputs& in, const SearchOptions& opts, SearchStats* stats) {
  const Problem& p = in.problem;
  if (!makeHeuristic(opts.heuristic, p))
    throw InputError(SourceLoc{}, fmt::format("unknown heuristic '{}' (blind, hmax, lmcut)", opts.heuristic));
  std::optional<Plan> plan;
  try {
    plan = findPlan(p, opts, stats);
  } catch (const std::invalid_argument& e) {  // unknown engine, or regression on a cyclic rule graph
    throw InputError(SourceLoc{}, e.what());
  }
  if (plan) return *plan;
  std::vector<bool> reachable = reachableFacts(p);
  if (std::all_of(p.goals.begin(), p.goals.end(), [&](int g) { return reachable[g]; })) {
    // Every goal can be derived, so the device limits exclude every plan: name the limits
    // the cheapest plan without them breaks.
    Problem unlimited = p;
    for (auto& l : unlimited.limits) l.max = INT64_MAX;
    std::optional<Plan> best = findPlan(unlimited, opts);
    std::string broken;
    SourceLoc at{in.rig.file, 0, 0};
    if (best) {
      std::vector<int64_t> use = resourceUsage(p, best->actions);
      for (size_t l = 0; l < p.limits.size(); ++l) {
        if (use[l] <= p.limits[l].max) continue;
        // The rig inputs on this limit, largest first; the error points at the largest.
        std::vector<int> facts;
        for (int a : best->actions)
          for (int q : p.actions[a].pre) facts.push_back(q);
        facts.insert(facts.end(), p.goals.begin(), p.goals.end());
        std::vector<std::pair<int64_t, int>> items;  // (amount, fact)
        std::vector<bool> seen(p.resources.size(), false);
        for (int f : facts) {
          int r = p.facts[f].resource;
          if (r < 0 || seen[r] || p.resources[r].limit != static_cast<int>(l)) continue;
          seen[r] = true;
          items.emplace_back(p.resources[r].amount, f);
        }
        std::stable_sort(items.begin(), items.end(), [](auto& x, auto& y) { return x.first > y.first; });
        std::string list;
        for (size_t i = 0; i < items.size() && i < 4; ++i)
          list += fmt::format("{}{} {}", i ? ", " : "", p.resources[p.facts[items[i].second].resource].name,
                              items[i].first);
        if (items.size() > 4) list += ", ...";
        if (!items.empty() && at.line == 0) {
          const Fact& f = p.facts[items[0].second];
          if (f.source == Fact::Source::Uniform) at = in.rig.uniforms[f.rigIndex].loc;
          else if (f.source == Fact::Source::Attribute) at = in.rig.attributes[f.rigIndex].loc;
        }
        broken += fmt::format("{}{} ({})", broken.empty() ? "" : "; ", describeExceeded(p, use, static_cast<int>(l)),
                              list);
      }
    }
    // Buffers the draw's size ruled out: why the buffer forms did not help.
    std::string oversized;
    for (const auto& b : p.buffers)
      if (!b.oversize.empty())
        oversized += fmt::format("{} {} ({})", oversized.empty() ? "; storage buffers were ruled out by the draw's size:" : ",",
                                 p.facts[b.fact].name, b.oversize);
    throw InputError(at,
                     fmt::format("no plan for rig '{}' fits the device limits: the cheapest plan reads {}; no "
                                 "alternative rule (rules/buffers.yaml reads morph targets, influences and bones "
                                 "from storage buffers) stays within them{}",
                                 in.rig.name, broken.empty() ? "more than the limits allow" : broken, oversized));
  }
  // A glTF import's notes say which of the model's attributes the rig does not carry.
  std::vector<Diagnostic> notes = in.notes;
  for (const std::string& n : in.rig.importNotes) notes.push_back({Severity::Note, SourceLoc{in.rig.file, 0, 0}, n, ""});
  if (std::vector<Diagnostic> all = unreachableInputs(in); !all.empty()) throwAll(std::move(all), notes);
  std::string why = formatUnreachable(p, analyzeUnreachable(p, in.rules, in.varyings));
  // Point at the first fragment input whose request cannot be met.
  SourceLoc at{in.fragment.file, 0, 0};
  std::vector<bool> reach = reachableFacts(p);
  for (const auto& v : in.varyings)
    for (const auto& s : v.semantics) {
      int f = p.findFact(s);
      if (f >= 0 && !reach[f] && at.line == 0) at = v.loc.line ? v.loc : at;
    }
  if (!why.empty() && why.back() == '\n') why.pop_back();
  InputError err(at, fmt::format("the request cannot be met for rig '{}':\n{}", in.rig.name, why));
  err.related = notes;
  throw err;
}

EmittedGlsl emitStage(const LoadedInputs& in, const Plan& plan, const TemplateSet& templates,
                      const EmitOptions& opts) {
  return emitGlsl(in.rig, in.problem, plan, in.varyings, templates, in.fragment.file, opts);
}

CompiledVertexShader compileStage(const LoadedInputs& in, const Plan& plan, const EmittedGlsl& glsl,
                                  const std::string& glslName, TargetEnv env, uint32_t maxCaptureBytes) {
  try {
    return compileVertex(glsl, glslName, env, maxCaptureBytes);
  } catch (const InputError& e) {
    // glslang reports lines only: point the columns at the snippet text in the rules file.
    std::vector<SourceLoc> snippetLines;
    for (int a : plan.actions)
      for (const auto& l : in.problem.actions[a].code) snippetLines.push_back(l.loc);
    throw refineSnippetError(e, snippetLines);
  }
}

std::vector<uint32_t> checkStage(const LoadedInputs& in, const EmittedGlsl& glsl, const CompiledVertexShader& vertex,
                                 const ShaderCheckOptions& opts) {
  std::vector<uint32_t> words = vertex.module.words;
  if (std::string err = validateSpirv(words, opts.env); !err.empty())
    throw InputError(SourceLoc{opts.glslName, 0, 0}, "generated SPIR-V fails validation: " + err);
  if (vertex.module.uniformBlockSize > opts.maxUniformBlockBytes) {
    // Point at the largest uniform the plan reads (a bone palette, usually).
    SourceLoc at{in.rig.file, 0, 0};
    std::string list;
    int64_t largest = -1;
    for (const auto& u : glsl.uniforms) {
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
                                     vertex.module.uniformBlockSize, list, opts.maxUniformBlockBytes));
  }
  checkLink(vertex.parsed, GlslShader(GlslUnit{Stage::Fragment, in.fragment.source, in.fragment.file, {}}, opts.env));
  if (opts.optimize) {
    words = optimizeSpirv(words, opts.env);
    if (std::string err = validateSpirv(words, opts.env); !err.empty())
      throw InputError(SourceLoc{opts.glslName, 0, 0}, "optimised SPIR-V fails validation: " + err);
  }
  return words;
}

std::vector<std::string> inputsRead(const LoadedInputs& in, const TemplateSet& templates) {
  std::vector<std::string> files = in.rig.sourceFiles;
  files.push_back(in.fragment.file);
  files.insert(files.end(), in.rules.files.begin(), in.rules.files.end());
  files.push_back(templates.file());
  if (in.profile && !in.profile->file.empty()) files.push_back(in.profile->file);
  for (const DeviceProfile& d : in.portable)
    if (!d.file.empty()) files.push_back(d.file);
  return files;
}

// ---- the stages in order ------------------------------------------------------------------

std::vector<std::string> pinnedInputs(const LoadedInputs& in, const TemplateSet& templates) {
  std::set<std::string> profiles;
  if (in.profile) profiles.insert(in.profile->file);
  for (const DeviceProfile& d : in.portable) profiles.insert(d.file);
  std::vector<std::string> files;
  for (const auto& f : inputsRead(in, templates))
    if (!profiles.count(f)) files.push_back(f);
  return files;
}

// After searching with the pin's bans: the plan's rule names must be the pin's, else the
// inputs changed what the bans leave and the pin is stale (a located error at its rules).
void checkPin(const Pin& pin, const Problem& problem, const Plan& plan) {
  std::set<std::string> got;
  for (int a : plan.actions) got.insert(problem.actions[size_t(a)].name);
  if (!std::equal(got.begin(), got.end(), pin.rules.begin(), pin.rules.end())) {
    std::vector<std::string> missing, extra;
    for (const auto& r : pin.rules)
      if (!got.count(r)) missing.push_back(r);
    for (const auto& r : got)
      if (!std::binary_search(pin.rules.begin(), pin.rules.end(), r)) extra.push_back(r);
    throw InputError(pin.rulesLoc,
                     fmt::format("the pinned plan is not what these inputs give under its bans (without: {}; instead: {}): "
                                 "the rig, request or rules changed since it was measured; time the candidates again "
                                 "(bench --candidates N --pin-out)",
                                 missing.empty() ? "-" : fmt::format("{}", fmt::join(missing, ", ")),
                                 extra.empty() ? "-" : fmt::format("{}", fmt::join(extra, ", "))));
  }
}

Plan searchUnderOptions(LoadedInputs& in, const GenerateOptions& opts, SearchStats* stats) {
  if (!opts.bannedRules.empty()) in.problem = withoutRules(in.problem, opts.bannedRules);
  if (opts.pin && !opts.pin->bans.empty()) in.problem = withoutRules(in.problem, opts.pin->bans);
  setDeviceLimits(in.problem, opts.maxAttributes, opts.maxUniformBlockBytes, opts.maxStorageBuffers);
  dropOversizedBuffers(in.problem, opts.maxVertices, opts.maxStorageBufferBytes);
  const SearchOptions search{opts.searchEngine, opts.heuristic, opts.searchLimits};
  if (in.profile && !in.portable.empty()) {
    // Least worst-case regret: each device's own optimum first, under the same bans and limits,
    // unless the caller gave the optima to measure regret against (LoadedInputs::portableBest).
    std::vector<DeviceProfile> all{*in.profile};
    all.insert(all.end(), in.portable.begin(), in.portable.end());
    if (in.portableBest.size() != all.size()) {
      in.portableBest.clear();
      for (const DeviceProfile& d : all) {
        LoadedInputs one = in;
        applyDeviceProfile(one.problem, d);
        in.portableBest.push_back(searchStage(one, search, nullptr).cost);
      }
    }
    applyPortableProfiles(in.problem, all, in.portableBest);
  }
  return searchStage(in, search, stats);
}

std::vector<RankedPlan> cheapestPlans(const LoadedInputs& in, const GenerateOptions& opts, size_t k, size_t maxSearches) {
  struct Node {
    int64_t cost;
    std::string names;  // the plan's rule names, sorted and joined: the tie-break and the identity
    std::vector<std::string> bans;
    std::vector<std::string> rules;
  };
  auto later = [](const Node& a, const Node& b) { return std::tie(a.cost, a.names, a.bans) > std::tie(b.cost, b.names, b.bans); };
  std::priority_queue<Node, std::vector<Node>, decltype(later)> open(later);
  std::set<std::vector<std::string>> tried;
  std::set<std::string> found;
  size_t searches = 0;
  auto expand = [&](std::vector<std::string> bans) {
    std::sort(bans.begin(), bans.end());
    if (!tried.insert(bans).second || searches >= maxSearches) return;
    ++searches;
    LoadedInputs one = in;
    GenerateOptions o = opts;
    o.bannedRules.insert(o.bannedRules.end(), bans.begin(), bans.end());
    try {
      Plan plan = searchUnderOptions(one, o, nullptr);
      std::set<std::string> names;
      for (int a : plan.actions) names.insert(one.problem.actions[size_t(a)].name);
      std::vector<std::string> rules(names.begin(), names.end());
      open.push(Node{plan.cost, fmt::format("{}", fmt::join(rules, " ")), std::move(bans), std::move(rules)});
    } catch (const InputError&) {
      // nothing serves the request without these rules
    }
  };
  expand({});
  std::vector<RankedPlan> out;
  while (!open.empty() && out.size() < k) {
    Node n = open.top();
    open.pop();
    // The same plan by another set of bans is not listed again, but its bans still partition
    // what is left: a cheaper plan may need them and one more.
    if (found.insert(n.names).second) out.push_back(RankedPlan{n.bans, n.rules, n.cost});
    for (const std::string& r : n.rules) {
      std::vector<std::string> child = n.bans;
      child.push_back(r);
      expand(std::move(child));
    }
  }
  return out;
}

std::vector<RankedPlan> eachDevicesCheapest(const LoadedInputs& in, const GenerateOptions& opts) {
  std::vector<RankedPlan> out;
  if (!in.profile || in.portable.empty()) return out;
  std::vector<DeviceProfile> all{*in.profile};
  all.insert(all.end(), in.portable.begin(), in.portable.end());
  for (const DeviceProfile& d : all) {
    LoadedInputs one = in;
    one.profile = d;
    one.portable.clear();
    one.portableBest.clear();
    applyDeviceProfile(one.problem, d);
    const Plan plan = searchUnderOptions(one, opts, nullptr);
    std::set<std::string> names;
    for (int a : plan.actions) names.insert(one.problem.actions[size_t(a)].name);
    out.push_back(RankedPlan{bansPinning(one.problem, plan, {}), {names.begin(), names.end()}, plan.cost});
  }
  return out;
}

std::vector<std::string> bansPinning(const Problem& p, const Plan& plan, const std::vector<std::string>& searchedWith) {
  std::set<std::string> used, others(searchedWith.begin(), searchedWith.end());
  std::set<int> facts;
  for (int a : plan.actions) {
    used.insert(p.actions[size_t(a)].name);
    facts.insert(p.actions[size_t(a)].add);
  }
  for (const auto& act : p.actions)
    if (facts.count(act.add) && !used.count(act.name)) others.insert(act.name);
  return {others.begin(), others.end()};
}

namespace {

// A profile prices the workload of the generation: the draw's vertices (its per-draw weights)
// and the mesh's features (terms scaled by one), each where known. Here, so that every path
// that prepares inputs (generate, build's variants) prices alike.
DeviceProfile pricedFor(DeviceProfile d, const GenerateOptions& opts) {
  d.workload = opts.workload;
  const double vertices = opts.maxVertices > 0 ? double(opts.maxVertices) : opts.workload.verticesPerDraw;
  if (vertices > 0 && !d.drawSizes.empty()) return d.atDrawSize(vertices);  // the weights at the draw's size
  if (d.hasDrawWeights() && vertices > 0) d.verticesPerDraw = vertices;
  return d;
}

LoadedInputs instantiateAndPrice(Rig rig, const RuleSet& rules, const FragmentInterface& fragment,
                                 const GenerateOptions& opts, const std::optional<DeviceProfile>& profile,
                                 const std::vector<DeviceProfile>& portable) {
  LoadedInputs in = instantiateStage(std::move(rig), rules, fragment, opts.overrides, opts.conventions);
  in.workload = opts.workload;  // before pricing: a profile's weights may depend on it
  if (profile) priceStage(in, pricedFor(*profile, opts));
  for (const DeviceProfile& d : portable) in.portable.push_back(pricedFor(d, opts));
  return in;
}

// A rig that stores a value both as itself and encoded (docs/rig-format.md, "Encodings")
// offers a choice the planning model cannot state: a provided value is true from the
// start, so its decode rule would never be used. Each combination of one form per
// encoding is instantiated and searched (the plain form: every value the encoding decodes
// that the rig stores plainly), and the cheapest plan's inputs kept (ties: the plain form).
// At most four encodings, so at most sixteen searches.
LoadedInputs cheapestStoredForms(const Rig& rig, const RuleSet& rules, const FragmentInterface& fragment,
                                 const GenerateOptions& opts, const std::optional<DeviceProfile>& profile,
                                 const std::vector<DeviceProfile>& portable, std::vector<Diagnostic>& notes) {
  auto plain = [&](const VertexEncoding& e) {
    std::vector<std::string> out;
    for (const std::string& s : e.decodes())
      if (attributeProviding(rig, s)) out.push_back(s);
    return out;
  };
  std::vector<const VertexEncoding*> twice;
  for (const auto& e : vertexEncodings())
    if (attributeProviding(rig, e.encoded) && !plain(e).empty()) twice.push_back(&e);
  if (twice.empty()) return instantiateAndPrice(rig, rules, fragment, opts, profile, portable);
  std::optional<LoadedInputs> best;
  int64_t bestCost = 0;
  uint32_t bestMask = 0;
  for (uint32_t mask = 0; mask < (1u << twice.size()); ++mask) {
    std::set<std::string> dropped;
    for (size_t i = 0; i < twice.size(); ++i) {
      if ((mask >> i) & 1) {
        for (const std::string& s : plain(*twice[i])) dropped.insert(s);
      } else {
        dropped.insert(twice[i]->encoded);
      }
    }
    try {
      LoadedInputs cand = instantiateAndPrice(withoutProvided(rig, dropped), rules, fragment, opts, profile, portable);
      LoadedInputs searched = cand;
      const int64_t cost = searchUnderOptions(searched, opts, nullptr).cost;
      if (!best || cost < bestCost) best = std::move(cand), bestCost = cost, bestMask = mask;
    } catch (const InputError&) {
      continue;  // this combination cannot serve the request; another may
    }
  }
  if (!best) return instantiateAndPrice(rig, rules, fragment, opts, profile, portable);  // the full rig's own error
  for (size_t i = 0; i < twice.size(); ++i) {
    const VertexEncoding* e = twice[i];
    const std::vector<std::string> plainForm = plain(*e);
    const std::string plainText = fmt::format("{}", fmt::join(plainForm, ", "));
    const bool encoded = (bestMask >> i) & 1;
    const std::string& used = encoded ? e->encoded : plainText;
    const std::string& other = encoded ? plainText : e->encoded;
    notes.push_back(Diagnostic{Severity::Note, attributeProviding(rig, encoded ? e->encoded : plainForm.front())->loc,
                               fmt::format("{}: the plan reads {}; the rig also stores {}, which would not make it "
                                           "cheaper", e->decodesText(), used, other)});
  }
  return std::move(*best);
}

}  // namespace

LoadedInputs prepareInputs(Rig rig, const RuleSet& rules, const FragmentInterface& fragment, const GenerateOptions& opts,
                           const std::optional<DeviceProfile>& profile, const std::vector<DeviceProfile>& portable) {
  std::vector<Diagnostic> notes = std::exchange(rig.importDiagnostics, {});
  if (!opts.maxError.empty()) rig = withinErrorBudgets(rig, opts.maxError, notes);
  LoadedInputs in;
  try {
    in = cheapestStoredForms(rig, rules, fragment, opts, profile, portable, notes);
  } catch (InputError& e) {  // a request the budgets made unsatisfiable says so
    e.related.insert(e.related.end(), notes.begin(), notes.end());
    throw;
  }
  in.notes = std::move(notes);
  return in;
}

LoadedInputs loadInputs(const GenerateOptions& opts) {
  Rig rig = loadRigStage(opts.rigPath, opts.gltf);
  if (!opts.rigParams.empty()) rig = rigWithParameters(rig, opts.rigParams, SourceLoc{});
  const RuleSet rules = loadRulesStage(opts.rulesPaths);
  const FragmentInterface fragment = loadFragmentStage(opts.fragmentPath, opts.targetEnv);
  std::optional<DeviceProfile> profile;
  std::vector<DeviceProfile> portable;
  if (!opts.portableProfilePaths.empty() && opts.deviceProfilePath.empty())
    throw InputError(SourceLoc{}, "a portable choice needs at least two device profiles (--device-profile given twice)");
  if (!opts.deviceProfilePath.empty()) profile = loadDeviceProfileStage(opts.deviceProfilePath);
  for (const std::string& path : opts.portableProfilePaths) portable.push_back(loadDeviceProfileStage(path));
  LoadedInputs in = prepareInputs(std::move(rig), rules, fragment, opts, profile, portable);
  for (const auto& b : opts.bannedRules)  // a misspelt --ban would otherwise change nothing silently
    if (!in.rules.findRule(b))
      throw InputError(SourceLoc{}, fmt::format("--ban {}: no rule of that name in the rules files", b));
  if (opts.pin)
    for (const auto& b : opts.pin->bans)
      if (!in.rules.findRule(b))
        throw InputError(opts.pin->banLoc, fmt::format("the pin bans '{}', a rule the rules files do not have: they changed "
                                                       "since it was measured; time the candidates again "
                                                       "(bench --candidates N --pin-out)", b));
  return in;
}

std::string reflectionOf(const GenerateResult& r) {
  const CrossShader* hlsl = r.hlsl ? &*r.hlsl : nullptr;
  const CrossShader* msl = r.msl ? &*r.msl : nullptr;
  if (!r.in.profile) return reflectionJson(r.in.rig, r.glsl, r.spirv, nullptr, nullptr, hlsl, msl);
  const PlanCostPrediction c = predictPlanCost(r.plan, r.in.problem, *r.in.profile);
  return reflectionJson(r.in.rig, r.glsl, r.spirv, &*r.in.profile, &c, hlsl, msl, &r.in.workload);
}

std::string explainUnreachable(const Problem& p, const RuleSet& rules) {
  // Minimal sets of missing rig inputs per unreachable goal (analysis/explain.h).
  return formatUnreachable(p, analyzeUnreachable(p, rules, {}));
}

GenerateResult generate(const GenerateOptions& opts) { return generateFrom(loadInputs(opts), opts); }

GenerateResult generateFrom(LoadedInputs in, const GenerateOptions& opts) {
  return generateWith(std::move(in), loadTemplatesStage(opts.templateDir), opts);
}

GenerateResult generateWith(LoadedInputs in, const TemplateSet& templates, const GenerateOptions& opts) {
  GenerateResult res;
  res.plan = searchUnderOptions(in, opts, &res.stats);
  if (opts.pin) checkPin(*opts.pin, in.problem, res.plan);
  EmitOptions eo;
  eo.capture = opts.capture;
  eo.heuristic = opts.heuristic;
  eo.search = searchMethod(res.stats);
  eo.version = shadergenVersion();
  res.glsl = emitStage(in, res.plan, templates, eo);
  if (opts.maxCaptureBytes > 0) checkCaptureFits(in, res.glsl, opts.maxCaptureBytes);
  CompiledVertexShader compiled =
      compileStage(in, res.plan, res.glsl, opts.outputName, opts.targetEnv, opts.capture ? opts.maxCaptureBytes : 0);
  res.spirv = compiled.module;
  res.spirv.words =
      checkStage(in, res.glsl, compiled, ShaderCheckOptions{opts.outputName, opts.targetEnv, opts.optimize, opts.maxUniformBlockBytes});
  if (opts.hlsl) res.hlsl = translateToHlsl(res.spirv.words, res.glsl, *opts.hlsl, opts.outputName);
  if (opts.msl) res.msl = translateToMsl(res.spirv.words, res.glsl, *opts.msl, opts.outputName);
  res.inputsRead = inputsRead(in, templates);
  res.pinnedInputs = pinnedInputs(in, templates);
  if (opts.pin) res.inputsRead.push_back(opts.pin->file);
  res.in = std::move(in);
  return res;
}

}  // namespace sg
