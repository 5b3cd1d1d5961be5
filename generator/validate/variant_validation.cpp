#include "validate/variant_validation.h"

#include <fmt/format.h>

#include <ctime>

#include "rig/gltf_import.h"
#include "validate/gltf_scene.h"

namespace sg {

ValidateOptions DeviceVariantValidator::options(const GenerateOptions& gen) const {
  ValidateOptions vo;
  vo.gen = gen;
  vo.crossCheck = settings_.crossCheck;
  vo.device = settings_.device;
  // The plan validated is the plan built: the device's limits do not re-plan it (a plan
  // over them fails on the device instead).
  vo.limits = {false, false, false};
  vo.validationLayers = settings_.validationLayers;
  vo.tolerance.abs = settings_.toleranceAbs;
  vo.tolerance.rel = settings_.toleranceRel;
  vo.checkFloatData = settings_.floatCheck;
  vo.strict = settings_.strict;
  return vo;
}

DeviceVariantValidator::DeviceVariantValidator(const ManifestValidation& settings) : settings_(settings) {
  auto first = std::make_unique<Validator>(options(GenerateOptions{}));
  device_ = first->deviceName();
  driver_ = first->harness().driver();
  idle_.push_back(std::move(first));
}

DeviceVariantValidator::~DeviceVariantValidator() = default;

std::string DeviceVariantValidator::identity() const {
  const ManifestValidation& s = settings_;
  std::string times;
  for (double t : s.times) times += fmt::format(" {:.17g}", t);
  return fmt::format(
      "shadergen {}\ndevice {}\ndriver {}\nmesh {} seed {} poses {}\ntimes{}\nanimation {}\nmorph_weight {}\n"
      "tolerance {:.17g} {:.17g}\ncross_check {} strict {} float_check {} layers {}\n",
      shadergenVersion(), device_, driver_, s.mesh, s.seed, s.poses, times, s.animation,
      s.morphWeight ? fmt::format("{:.17g}", *s.morphWeight) : "-", s.toleranceAbs, s.toleranceRel, s.crossCheck,
      s.strict, s.floatCheck, s.validationLayers);
}

std::shared_ptr<const ValidationScene> DeviceVariantValidator::sceneOf(const std::string& rigPath,
                                                                      const std::map<std::string, int64_t>& params,
                                                                      const GltfReadOptions& read) {
  // A level-of-detail variant (fewer targets or influences) is posed as its own rig.
  std::string key = rigPath;
  for (const auto& [name, value] : params) key += fmt::format("\n{}={}", name, value);
  {
    std::lock_guard<std::mutex> g(lock_);
    if (auto it = scenes_.find(key); it != scenes_.end()) return it->second;
  }
  std::shared_ptr<ValidationScene> scene;
  if (isGltfPath(rigPath)) {  // the model's own mesh, posed by its animation
    GltfSceneOptions so;
    so.times = settings_.times;
    so.animation = settings_.animation;
    so.morphWeight = settings_.morphWeight;
    so.read = read;  // the weights the variant was generated with (one choice per build)
    scene = std::make_shared<ValidationScene>(gltfScene(rigPath, so));
  } else {  // a procedural mesh in random poses, as `validate` makes for a YAML rig
    scene = std::make_shared<ValidationScene>(
        proceduralScene(rigPath, params, settings_.mesh, settings_.seed, settings_.poses));
  }
  std::lock_guard<std::mutex> g(lock_);
  return scenes_.emplace(key, scene).first->second;
}

ValidationResult DeviceVariantValidator::validate(const Variant&, const GenerateOptions& gen) {
  std::shared_ptr<const ValidationScene> scene = sceneOf(gen.rigPath, gen.rigParams, gen.gltf);
  std::unique_ptr<Validator> validator;
  {
    std::lock_guard<std::mutex> g(lock_);
    if (!idle_.empty()) {
      validator = std::move(idle_.back());
      idle_.pop_back();
    }
  }
  if (!validator) validator = std::make_unique<Validator>(options(gen));
  ValidateReport report;
  try {
    report = validator->run(*scene, gen);
  } catch (...) {
    std::lock_guard<std::mutex> g(lock_);
    idle_.push_back(std::move(validator));
    throw;
  }
  {
    std::lock_guard<std::mutex> g(lock_);
    idle_.push_back(std::move(validator));
  }
  ValidationResult r;
  r.pass = report.pass;
  r.device = device_;
  r.driver = driver_;
  r.tool = shadergenVersion();
  std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char made[32];
  std::strftime(made, sizeof made, "%Y-%m-%dT%H:%M:%SZ", &utc);
  r.made = made;
  r.runs = report.runs.size();
  for (const auto& run : report.runs)
    for (const auto& o : run.outputs) {
      if (o.unchecked) continue;
      if (r.worstOutput.empty() || o.maxRelError > r.maxRelError) {
        r.worstOutput = o.name;
        r.maxRelError = o.maxRelError;
      }
      r.maxAbsError = std::max(r.maxAbsError, o.maxAbsError);
    }
  if (r.pass) return r;
  // Why, per failing run and output: the plan's rules name the suspect.
  const SourceLoc at{gen.rigPath, 0, 0};
  for (const auto& run : report.runs) {
    if (run.pass) continue;
    std::string rules;
    for (const auto& rule : run.rules) rules += (rules.empty() ? "" : ", ") + rule;
    for (const auto& o : run.outputs) {
      if (o.pass) continue;
      std::string sems;
      for (const auto& s : o.semantics) sems += (sems.empty() ? "" : ", ") + s;
      std::string why = o.unchecked ? "unchecked: " + o.uncheckedReason
                                    : fmt::format("max abs error {:.3g}, rel {:.3g} at vertex {}", o.maxAbsError,
                                                  o.maxRelError, o.worstVertex);
      if (o.unchecked || o.storedPass) {
        if (o.floatCheck.ran && !o.floatCheck.pass)
          why = fmt::format("against the float data: deviation {:.3g} over tolerance {:.3g}", o.floatCheck.deviation,
                            o.floatCheck.tolerance);
      }
      r.errors.push_back(Diagnostic{Severity::Note, at,
                                    fmt::format("{}: output '{}' ({}) differs from its definition: {}; plan rules: {}",
                                                run.label, o.name, sems, why, rules)});
    }
    for (const auto& m : run.validationMessages)
      r.errors.push_back(Diagnostic{Severity::Note, at, fmt::format("{}: validation layer: {}", run.label, m)});
  }
  return r;
}

}  // namespace sg
