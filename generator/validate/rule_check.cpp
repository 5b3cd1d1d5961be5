#include "validate/rule_check.h"

#include <fmt/format.h>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <set>

#include "analysis/explain.h"
#include "pipeline/stages.h"
#include "rules/instantiate.h"
#include "validate/interpreter.h"
#include "validate/poses.h"

namespace sg {
namespace {

constexpr const char* kOutputName = "rule_output";
constexpr size_t kCheckVertices = 256;

bool provides(const Rig& rig, const std::string& semantic) {
  for (const auto& a : rig.attributes)
    for (const auto& p : a.provides)
      if (p.semantic == semantic) return true;
  for (const auto& u : rig.uniforms)
    if (u.semantic == semantic) return true;
  return false;
}

// The rig, and the rig with the data that makes the library's other forms apply: morphed
// tangents (the morphed tangent rules and their buffer forms), then an active-target list
// (the sparse forms). A rule is checked on the first of these it applies to.
struct CheckRig {
  Rig rig;
  std::string name;
};
std::vector<CheckRig> checkRigs(const Rig& rig) {
  std::vector<CheckRig> out{{rig, rig.name}};
  if (rig.morphTargets() == 0) return out;
  Rig r = rig;
  std::string name = rig.name;
  if (provides(rig, "vertex.tangent") && !provides(rig, "morph.tangent")) {
    RigAttribute a;
    a.name = "check_tangent_morph";
    a.format = VertexFormat::Float32x3;
    a.shaderType = Type::Vec3;
    a.perMorphTarget = true;
    a.provides = {{"morph.tangent", ""}};
    a.loc = SourceLoc{rig.file, 0, 0};
    r.attributes.push_back(a);
    r.morphedAttributes.push_back("tangent");
    name += " + morph.tangent";
    out.push_back({r, name});
  }
  if (!provides(rig, "morph.active_targets")) {
    r.params["max_active_targets"] = std::min(3, rig.morphTargets());
    RigUniform list;
    list.name = "check_active";
    list.semantic = "morph.active_targets";
    list.type = Type::UInt;
    list.arraySizeParam = "morph_targets";
    list.arraySize = rig.morphTargets();
    list.loc = SourceLoc{rig.file, 0, 0};
    RigUniform count = list;
    count.name = "check_active_count";
    count.semantic = "morph.active_count";
    count.arraySizeParam.clear();
    count.arraySize = 0;
    r.uniforms.push_back(list);
    r.uniforms.push_back(count);
    out.push_back({r, name + " + morph.active_targets (3 active)"});
  }
  return out;
}

// Why each rule can appear in no plan for `rig` (""  where some plan can contain it, or
// where the rule has no instance: its `when` is false, or the rig provides its product,
// which the caller says). A rule can appear in a plan when every need of one of its
// instances is reachable from the rig's inputs: the search's own analysis
// (reachableFacts) over the problem of every rule with nothing requested. Run alone, such
// a rule would be fed needs the rig cannot have (an occlusion for a rig without one),
// and its disagreement would say nothing about any program generated for the rig.
std::vector<std::string> unreachableRules(const Rig& rig, RuleSet rules) {
  // Costs play no part in reachability: `cost: auto` need not be measured for it.
  for (auto& r : rules.rules)
    if (r.costAuto && r.cost.empty()) r.cost = Expr::parse("0", r.loc);
  Problem p = buildProblem(rig, rules, {});
  const std::vector<bool> reach = reachableFacts(p);
  std::vector<std::string> why(rules.rules.size());
  std::vector<bool> fires(rules.rules.size(), false);
  for (const auto& a : p.actions)
    if (a.rule >= 0) fires[a.rule] = fires[a.rule] || std::all_of(a.pre.begin(), a.pre.end(), [&](int f) { return reach[f]; });
  for (const auto& a : p.actions) {
    if (a.rule < 0 || fires[a.rule] || !why[a.rule].empty()) continue;
    const auto need = std::find_if(a.pre.begin(), a.pre.end(), [&](int f) { return !reach[f]; });
    // The rig inputs that would make the need derivable (explain's analysis of a goal).
    p.goals = {*need};
    const std::vector<UnreachableGoal> u = analyzeUnreachable(p, rules, {});
    std::string with;
    int shown = 0;
    const std::vector<std::string> itself{p.facts[*need].name};
    for (const auto& set : u.empty() ? std::vector<std::vector<std::string>>{} : u.front().missingInputs)
      if (set != itself && shown++ < 3) with += fmt::format("{}{{{}}}", with.empty() ? "; a rig providing " : " or ", compactFactList(set));
    if (!with.empty()) with += " could";
    why[a.rule] = fmt::format("needs '{}', which the rig neither provides nor derives{}", p.facts[*need].name, with);
  }
  return why;
}

void setAt(rt::Mesh& m, const std::string& sem, size_t v, glm::vec4 x) {
  auto it = m.streams.find(sem);
  if (it != m.streams.end() && v < it->second.size()) it->second[v] = x;
}

// The hostile vertices (docs/rules-authoring.md lists them): degenerate tangents, zero,
// tiny and huge normals (with unmorphed normals there, so morphing keeps them so), a
// tangent that one target's delta makes parallel, joints at the palette's ends.
void makeHostile(rt::Mesh& m, const Rig& rig) {
  if (m.vertexCount < 10 || !m.has("vertex.normal")) return;
  const int targets = rig.morphTargets();
  const float lastBone = static_cast<float>(std::max<int64_t>(0, rig.param("bones") - 1));
  auto normal = [&](size_t v) { return glm::normalize(glm::vec3(m.at("vertex.normal")[v])); };
  auto zeroDeltas = [&](size_t v, const char* family) {
    for (int i = 0; i < targets; ++i) setAt(m, fmt::format("{}[{}]", family, i), v, glm::vec4(0));
  };
  for (size_t v = 0; v < 7; ++v) {
    zeroDeltas(v, "morph.normal");
    if (v < 3) zeroDeltas(v, "morph.tangent");
  }
  // The parallel frames are axis-aligned: every normal and tangent format (float16, snorm8,
  // octahedral) stores them exactly, so they stay exactly degenerate on the data as the
  // device reads it. -N rounded to float16 beside an snorm8 N is merely ill-conditioned,
  // and float32 Gram-Schmidt there differs from the exact definition by 3e-5.
  auto setNormal = [&](size_t v, glm::vec3 n) {
    if (m.has("vertex.normal")) setAt(m, "vertex.normal", v, glm::vec4(n, m.at("vertex.normal")[v].w));
  };
  auto setTangent = [&](size_t v, glm::vec3 t) {
    if (m.has("vertex.tangent")) setAt(m, "vertex.tangent", v, glm::vec4(t, m.at("vertex.tangent")[v].w));
  };
  setAt(m, "vertex.tangent", 0, glm::vec4(0));  // zero
  setNormal(1, {0, 1, 0});
  setTangent(1, {0, 2, 0});  // parallel
  setNormal(2, {0, 0, 1});
  setTangent(2, {0, 0, -1});  // antiparallel
  setNormal(3, {1, 0, 0});
  setTangent(3, {0, 1, 0});
  if (m.has("vertex.tangent") && targets > 0)  // parallel (1.5 N) when target 0 alone is on
    setAt(m, "morph.tangent[0]", 3, glm::vec4(1.5f, -1.0f, 0.0f, 0.0f));
  setAt(m, "vertex.normal", 4, glm::vec4(0, 0, 0, m.at("vertex.normal")[4].w));          // zero
  setAt(m, "vertex.normal", 5, glm::vec4(1e-15f * normal(5), m.at("vertex.normal")[5].w));  // tiny
  setAt(m, "vertex.normal", 6, glm::vec4(1e15f * normal(6), m.at("vertex.normal")[6].w));   // huge
  for (int s = 0; s < (rig.param("influences") + 3) / 4; ++s) {  // the palette's first and last joints
    setAt(m, fmt::format("skin.joints[{}]", s), 7, glm::vec4(0, lastBone, 0, lastBone));
    setAt(m, fmt::format("skin.joints[{}]", s), 8, glm::vec4(lastBone));
  }
}

// Poses that break rules: weights 0 (an empty active list), negative and above 1, one
// target alone, and mirrored (negative scale) skinning, besides the validation's hostile
// random pose (non-uniform scale unless the rig declares uniform_scale).
struct NamedPose {
  std::string name;
  rt::Pose pose;
};
std::vector<NamedPose> hostilePoses(const Rig& rig, const rt::Pose& base) {
  std::vector<NamedPose> out{{"random hostile pose", base}};
  auto weights = [&](const char* name, auto f) {
    rt::Pose p = base;
    for (size_t i = 0; i < p.morphWeights.size(); ++i) p.morphWeights[i] = f(i);
    out.push_back({name, p});
  };
  if (!base.morphWeights.empty()) {
    weights("all morph weights 0", [](size_t) { return 0.0f; });
    weights("morph weights -0.5 and 1.5", [](size_t i) { return i % 2 ? 1.5f : -0.5f; });
    weights("morph target 0 alone at weight 1", [](size_t i) { return i == 0 ? 1.0f : 0.0f; });
  }
  rt::Pose mirrored = base;
  const glm::mat4 flip = glm::scale(glm::mat4(1.0f), rig.param("uniform_scale") ? glm::vec3(-1.0f) : glm::vec3(-1, 1, 1));
  for (auto& b : mirrored.bones) b = b * flip;
  mirrored.model = mirrored.model * flip;
  out.push_back({"mirrored (negative scale)", mirrored});
  // The sparse protocol uploads at most max_active_targets non-zero weights: keep the first.
  const int64_t keep = rig.param("max_active_targets", -1);
  if (keep >= 0)
    for (auto& p : out) {
      int64_t on = 0;
      for (float& w : p.pose.morphWeights)
        if (w != 0.0f && ++on > keep) w = 0.0f;
    }
  return out;
}

std::string showValues(const std::vector<double>& v) {
  std::string s;
  for (double x : v) s += (s.empty() ? "" : ", ") + (std::isnan(x) ? std::string("nan") : fmt::format("{:.7g}", x));
  return v.size() == 1 ? s : "(" + s + ")";
}

// The fragment shader that asks for the product alone.
std::string requestShader(Type t) {
  std::string use;
  switch (t) {
    case Type::Vec2: case Type::UVec2: use = "vec4(v, 0.0, 0.0)"; break;
    case Type::Vec3: use = "vec4(v, 0.0)"; break;
    case Type::Vec4: use = "v"; break;
    case Type::Mat3: use = "vec4(v[0], 0.0)"; break;
    case Type::Mat4: use = "v[0]"; break;
    case Type::IVec4: case Type::UVec4: use = "vec4(v)"; break;
    default: use = "vec4(float(v))"; break;
  }
  const bool flat = scalarKind(t) != ScalarKind::Float;
  return fmt::format("#version 450\nlayout(location = 0) {}in {} {};\nlayout(location = 0) out vec4 color;\n"
                     "void main() {{ {} v = {}; color = {}; }}\n",
                     flat ? "flat " : "", glslName(t), kOutputName, glslName(t), kOutputName, use);
}

// A matrix is not a varying: the product's columns are (a mat4 output packs them), each
// from a move rule and defined as the column of the product's definition.
std::vector<std::string> addColumnSemantics(RuleSet& rules, const SemanticDecl& product) {
  const int n = product.type == Type::Mat3 ? 3 : 4;
  std::string text = "semantics:\n";
  std::vector<std::string> names;
  for (int c = 0; c < n; ++c) {
    names.push_back(fmt::format("rule_check.column{}", c));
    text += fmt::format("  {}: {{ type: vec{}, definition: \"{}[{}]\" }}\n", names.back(), n, product.name, c);
  }
  text += "rules:\n";
  for (int c = 0; c < n; ++c)
    text += fmt::format("  - name: rule_check_column{}\n    produces: {}\n    needs: [{}]\n    cost: 0\n"
                        "    glsl: |\n      ${{out}} = ${{{}}}[{}];\n",
                        c, names[static_cast<size_t>(c)], product.name, product.name, c);
  loadRulesText(rules, text, "rule-check columns");
  checkDefinitions(rules);
  return names;
}

class Checker {
 public:
  Checker(const RuleSet& rules, Validator& validator, std::string device)
      : rules_(rules), validator_(validator), device_(std::move(device)) {}

  // Checks rule `ri` on one check rig; false (and `why`) when it cannot run there.
  bool check(int ri, const CheckRig& cr, const RigShape& shape, const rt::Mesh& mesh,
             const std::vector<NamedPose>& poses, RuleCheckResult& res, std::string& why) {
    const Rule& rule = rules_.rules[static_cast<size_t>(ri)];
    const SemanticDecl* product = rules_.findSemantic(rule.produces);
    if (!product || !product->definition) {
      res.status = RuleCheckResult::Status::Unchecked;
      res.detail = fmt::format("'{}' has no definition", rule.produces);
      return true;
    }
    if (shape.provided.count(rule.produces)) {
      why = fmt::format("the rig provides '{}'", rule.produces);
      return false;
    }
    RuleInstance inst;
    try {
      inst = instantiateRule(rules_, ri, shape, "out", [](const std::string& s) { return s; });
    } catch (const InputError& e) {
      why = e.diagnostic().message;
      return false;
    }
    // Needs the rig does not provide: vectors are fed from their definitions, evaluated in
    // each pose; matrices and integers come from the rules the search picks for them.
    // A need defined over uniforms alone (camera.view_projection) becomes a uniform of the
    // variant rig, computed from its definition as validation computes such uniforms.
    std::vector<std::string> fed, fedUniforms;
    for (const auto& n : inst.needs) {
      if (shape.provided.count(n)) continue;
      const SemanticDecl* d = rules_.findSemantic(splitIndexed(n).first);
      if (d && d->definition && d->arrayParam.empty() && d->count.empty() && isUniformValue(cr.rig, shape, mesh, poses, n)) {
        fedUniforms.push_back(n);
        continue;
      }
      if (!d || !d->bufferOf.empty() || isMatrix(d->type) || scalarKind(d->type) != ScalarKind::Float) continue;
      if (!d->definition) {
        res.status = RuleCheckResult::Status::Unchecked;
        res.detail = fmt::format("its need '{}' has no definition", n);
        return true;
      }
      fed.push_back(n);
    }
    // The variant rig: each fed need is a float attribute of its own.
    Rig rig = cr.rig;
    for (size_t k = 0; k < fed.size(); ++k) {
      const SemanticDecl* d = rules_.findSemantic(splitIndexed(fed[k]).first);
      const int n = componentCount(d->type);
      RigAttribute a;
      a.name = fmt::format("check_need{}", k);
      a.format = n == 1 ? VertexFormat::Float32x1 : n == 2 ? VertexFormat::Float32x2 : n == 3 ? VertexFormat::Float32x3 : VertexFormat::Float32x4;
      a.shaderType = d->type;
      a.provides = {{fed[k], ""}};
      a.loc = SourceLoc{rig.file, 0, 0};
      rig.attributes.push_back(a);
    }
    for (size_t k = 0; k < fedUniforms.size(); ++k) {
      RigUniform u;
      u.name = fmt::format("check_uniform{}", k);
      u.semantic = fedUniforms[k];
      u.type = rules_.findSemantic(fedUniforms[k])->type;
      u.loc = SourceLoc{rig.file, 0, 0};
      rig.uniforms.push_back(u);
    }
    res.fed = fed;
    res.fed.insert(res.fed.end(), fedUniforms.begin(), fedUniforms.end());

    GenerateOptions gen;
    gen.capture = true;
    gen.maxVertices = static_cast<int64_t>(mesh.vertexCount) + 1;
    for (const auto& r : rules_.rules)
      if (r.produces == rule.produces && r.name != rule.name) gen.bannedRules.push_back(r.name);
    GenerateResult g;
    try {
      FragmentInterface frag = reflectFragmentSource(requestShader(product->type), "rule-check.frag");
      RuleSet rules = rules_;
      std::vector<std::string> request{rule.produces};
      if (isMatrix(product->type)) request = addColumnSemantics(rules, *product);
      LoadedInputs in = instantiateStage(rig, std::move(rules), frag, {VaryingOverride{kOutputName, request}}, {"none"});
      g = generateFrom(std::move(in), gen);
    } catch (const InputError& e) {
      res.status = RuleCheckResult::Status::Unchecked;
      res.detail = fmt::format("cannot generate a shader with it alone: {}", e.diagnostic().message);
      return true;
    }
    for (size_t pi = 0; pi < poses.size(); ++pi) {
      ValidationScene scene;
      scene.poses = {poses[pi].pose};
      try {
        scene.mesh = fedMesh(cr.rig, shape, mesh, poses[pi].pose, fed);
      } catch (const std::exception& e) {
        res.status = RuleCheckResult::Status::Unchecked;
        res.detail = fmt::format("its needs cannot be evaluated from their definitions: {}", e.what());
        return true;
      }
      RunReport run = validator_.runOne(g, scene, rule.name);
      const OutputReport* out = nullptr;
      for (const auto& o : run.outputs)
        if (o.name == kOutputName) out = &o;
      if (!out) throw std::logic_error("rule check: no output " + std::string(kOutputName));
      if (out->unchecked) {
        res.status = RuleCheckResult::Status::Unchecked;
        res.detail = out->uncheckedReason;
        return true;
      }
      if (out->pass) continue;
      res.status = RuleCheckResult::Status::Disagrees;
      res.detail = disagreement(rule, g, scene.mesh, poses[pi], *out);
      return true;
    }
    res.status = RuleCheckResult::Status::Agrees;
    return true;
  }

 private:
  // Can `semantic` be evaluated from the pose's uniforms alone?
  bool isUniformValue(const Rig& rig, const RigShape& shape, const rt::Mesh& mesh, const std::vector<NamedPose>& poses,
                      const std::string& semantic) {
    try {
      UniformValues u = uniformValues(rig, rules_, shape, mesh, poses.front().pose);
      Interpreter in(rules_, shape, mesh, u);
      in.evaluateUniform(semantic);
      return true;
    } catch (const std::exception&) {
      return false;
    }
  }

  // The mesh with each fed need's definition evaluated in `pose` (the values depend on the
  // pose: morph weights, bones) as a stream of its own.
  rt::Mesh fedMesh(const Rig& rig, const RigShape& shape, const rt::Mesh& mesh, const rt::Pose& pose,
                   const std::vector<std::string>& fed) {
    // On the data as the device reads it (integer and normalized formats rounded), which
    // is what the reference of the product reads too.
    rt::Mesh out = quantizeForRig(rig, mesh);
    if (fed.empty()) return out;
    std::vector<rt::Pose> drawn{pose};
    drawDeclaredUniforms(drawn, rig, rules_);
    UniformValues u = uniformValues(rig, rules_, shape, out, drawn[0]);
    Interpreter in(rules_, shape, out, u);
    const std::vector<std::vector<double>> values = in.evaluate(fed);
    for (size_t k = 0; k < fed.size(); ++k) {
      const size_t n = values[k].size() / std::max<size_t>(1, mesh.vertexCount);
      auto& s = out.streams[fed[k]];
      s.assign(mesh.vertexCount, glm::vec4(0));
      for (size_t v = 0; v < mesh.vertexCount; ++v)
        for (size_t c = 0; c < n; ++c) s[v][static_cast<int>(c)] = static_cast<float>(values[k][v * n + c]);
    }
    return out;
  }

  // "... at input vertex.tangent = (...), ...": the values the definition read at the worst vertex.
  std::string disagreement(const Rule& rule, const GenerateResult& g, const rt::Mesh& fedMesh, const NamedPose& pose,
                           const OutputReport& out) {
    std::string inputs;
    try {
      const rt::Mesh q = quantizeForRig(g.in.rig, fedMesh);
      std::vector<rt::Pose> ps{pose.pose};
      drawDeclaredUniforms(ps, g.in.rig, rules_);
      const RigShape shape = shapeOfRig(g.in.rig, rules_);
      UniformValues u = uniformValues(g.in.rig, rules_, shape, q, ps[0]);
      Interpreter in(rules_, shape, q, u);
      for (const auto& line : in.inputsAt(rule.produces, out.worstVertex)) inputs += (inputs.empty() ? "" : ", ") + line;
    } catch (const std::exception& e) {
      inputs = fmt::format("(not available: {})", e.what());
    }
    return fmt::format("rule '{}' disagrees with the definition of '{}' ({}, vertex {} of the hostile mesh, {}): "
                       "the GPU gives {}, the definition {} (max abs error {:.3g}) at input {}",
                       rule.name, rule.produces, device_, out.worstVertex, pose.name, showValues(out.worstGpu),
                       showValues(out.worstReference), out.maxAbsError, inputs);
  }

  const RuleSet& rules_;
  Validator& validator_;
  std::string device_;
};

}  // namespace

RuleCheckReport checkRulesOnDevice(const RuleCheckOptions& opts) {
  RuleCheckReport report;
  const Rig rig = loadRigStage(opts.rigPath, opts.gltf);
  const RuleSet rules = loadRulesStage(opts.rulesPaths);
  ValidateOptions vo;
  vo.device = opts.device;
  vo.validationLayers = opts.validationLayers;
  vo.tolerance = opts.tolerance;
  vo.tolerance.nonFiniteAgrees = true;
  vo.checkFloatData = false;  // the fed values are the definitions', not float data a format rounded
  Validator validator(vo);
  report.device = validator.deviceName();
  Checker checker(rules, validator, report.device);

  report.results.resize(rules.rules.size());
  std::vector<std::string> whyNot(rules.rules.size());
  std::vector<bool> done(rules.rules.size(), false), selected(rules.rules.size(), true);
  for (size_t i = 0; i < rules.rules.size(); ++i) {
    selected[i] = opts.only.empty() || std::find(opts.only.begin(), opts.only.end(), rules.rules[i].name) != opts.only.end();
    done[i] = !selected[i];
    report.results[i].rule = rules.rules[i].name;
    report.results[i].produces = rules.rules[i].produces;
    report.results[i].loc = rules.rules[i].loc;
  }
  for (const CheckRig& cr : checkRigs(rig)) {
    const RigShape shape = shapeOfRig(cr.rig, rules);
    const std::vector<std::string> unreachable = unreachableRules(cr.rig, rules);
    ValidationScene scene = proceduralScene(cr.rig, "head", opts.seed, 1);
    // The first vertices of the head are enough besides the hostile ones, and keep the
    // reference (per vertex, per pose, per rule) quick.
    scene.mesh.vertexCount = std::min<size_t>(scene.mesh.vertexCount, kCheckVertices);
    for (auto& [name, stream] : scene.mesh.streams) stream.resize(scene.mesh.vertexCount);
    makeHostile(scene.mesh, cr.rig);
    std::vector<rt::Pose> drawn{scene.poses.front()};
    drawDeclaredUniforms(drawn, cr.rig, rules);
    const std::vector<NamedPose> poses = hostilePoses(cr.rig, drawn.front());
    report.vertices = scene.mesh.vertexCount;
    report.poses = std::max(report.poses, poses.size());
    for (size_t i = 0; i < rules.rules.size(); ++i) {
      if (done[i]) continue;
      bool applies = false;
      try {
        applies = ruleApplies(rules.rules[i], shape);
      } catch (const InputError& e) {
        whyNot[i] = e.diagnostic().message;
        continue;
      }
      if (!applies) {
        if (whyNot[i].empty()) whyNot[i] = fmt::format("when '{}' is false for {}", rules.rules[i].when.text(), cr.name);
        continue;
      }
      if (!unreachable[i].empty()) {
        if (whyNot[i].empty()) {
          whyNot[i] = unreachable[i];
          report.results[i].status = RuleCheckResult::Status::InNoPlan;
        }
        continue;
      }
      RuleCheckResult& res = report.results[i];
      if (!checker.check(static_cast<int>(i), cr, shape, scene.mesh, poses, res, whyNot[i])) {
        res.status = RuleCheckResult::Status::NotApplicable;
        continue;
      }
      res.rig = cr.name;
      done[i] = true;
    }
  }
  std::vector<RuleCheckResult> results;
  for (size_t i = 0; i < rules.rules.size(); ++i) {
    if (!selected[i]) continue;
    RuleCheckResult& res = report.results[i];
    if (!done[i]) res.detail = whyNot[i];
    if (res.status == RuleCheckResult::Status::Disagrees)
      report.errors.push_back(Diagnostic{Severity::Error, res.loc, res.detail});
    results.push_back(std::move(res));
  }
  report.results = std::move(results);
  return report;
}

std::string formatRuleCheckSummary(const RuleCheckReport& r) {
  size_t agree = 0, inNoPlan = 0;
  std::string unchecked, notApplicable, noPlan;
  for (const auto& x : r.results) {
    switch (x.status) {
      case RuleCheckResult::Status::Agrees: ++agree; break;
      case RuleCheckResult::Status::Disagrees: break;
      case RuleCheckResult::Status::Unchecked: unchecked += fmt::format("  {}: {}\n", x.rule, x.detail); break;
      case RuleCheckResult::Status::NotApplicable: notApplicable += fmt::format("  {}: {}\n", x.rule, x.detail); break;
      case RuleCheckResult::Status::InNoPlan:
        ++inNoPlan;
        noPlan += fmt::format("  {}: {}\n", x.rule, x.detail);
        break;
    }
  }
  std::string s = fmt::format("rules run alone on {} against their definitions ({} vertices, {} poses): "
                              "{} agree, {} disagree; {} skipped: in no plan for the rig\n",
                              r.device, r.vertices, r.poses, agree, r.errors.size(), inNoPlan);
  if (!unchecked.empty()) s += "unchecked:\n" + unchecked;
  if (!notApplicable.empty()) s += "not applicable to the rig:\n" + notApplicable;
  if (!noPlan.empty()) s += "skipped, in no plan for the rig:\n" + noPlan;
  return s;
}

}  // namespace sg
