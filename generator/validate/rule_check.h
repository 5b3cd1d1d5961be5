// Rule-level checking (`shadergen check --rig R RULES`, docs/rules-authoring.md "Checking
// rules on a device"): every rule that can appear in a plan for the rig runs ALONE on the
// device, its computed needs fed as vertex attributes whose values are their definitions
// evaluated on a hostile mesh, over poses drawn to break rules; its product is compared
// with its semantic's definition. One way to feed a program to a device: each check is an
// ordinary generation (the product as the only varying, every other producer of it banned)
// run by the Validator.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "validate/validate.h"

namespace sg {

struct RuleCheckOptions {
  std::string rigPath;
  std::vector<std::string> rulesPaths;
  std::string device;  // "" = lavapipe
  bool validationLayers = true;
  uint32_t seed = 1;
  Tolerance tolerance;
  std::vector<std::string> only;  // check only the rules of these names (empty: every rule)
  GltfReadOptions gltf;           // a glTF rig's import (check --Werror makes its warnings errors)
};

struct RuleCheckResult {
  // InNoPlan: the rule applies, but a need of it cannot be derived from the rig's inputs,
  // so no program generated for the rig contains it; it is not run (its needs would be
  // values the rig does not have).
  enum class Status { Agrees, Disagrees, Unchecked, NotApplicable, InNoPlan };
  std::string rule;
  std::string produces;
  SourceLoc loc;        // the rule's name
  Status status = Status::NotApplicable;
  std::string rig;      // the check rig it ran on ("dawn-face", "dawn-face + morph.tangent")
  std::string detail;   // why unchecked; for a disagreement, the message
  std::vector<std::string> fed;  // needs fed from their definitions
};

struct RuleCheckReport {
  std::string device;
  std::vector<RuleCheckResult> results;  // in rule order
  std::vector<Diagnostic> errors;        // one per disagreeing rule, at the rule
  size_t vertices = 0;
  size_t poses = 0;
};

// Throws InputError for a rig or rules file that does not load.
RuleCheckReport checkRulesOnDevice(const RuleCheckOptions& opts);

// "rules run alone on lavapipe ...: N agree, M disagree; K skipped: in no plan for the
// rig" and the unchecked, not-applicable and skipped rules with why.
std::string formatRuleCheckSummary(const RuleCheckReport& r);

}  // namespace sg
