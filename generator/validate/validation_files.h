// What `validate --report FILE.json` and `validate --save-outputs DIR` write
// (docs/validation.md, "Reports and saved outputs"): plain bytes by file name, which the CLI
// writes with its all-or-nothing writer. Deterministic: the same validation, the same bytes.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "validate/gltf_scene.h"
#include "validate/validate.h"

namespace sg {

// One primitive as validated: its report and what its poses were (instance-major:
// pose i * times.size() + k is instance i at times[k]).
struct ValidatedPart {
  std::string name;  // gltfPartName ("m2p1-Head"): the stem of its saved files
  std::string rig;   // "MODEL.glb#2/1"
  ValidateReport report;
  std::vector<GltfInstance> instances;
  std::vector<std::string> instanceNotes;  // instances left out, and why
  std::vector<double> times;
  size_t vertices = 0;
  int mode = 4;                    // glTF primitive mode
  std::vector<uint32_t> indices;   // as stored (empty: none)
  std::string error;               // the primitive failed before it ran ("": it ran)
};

// Header of a report: the command's settings.
struct ValidationContext {
  std::string model;      // the rig path as given
  std::string animation;  // "" = none
  Tolerance tolerance;
  bool strict = false;
};

// The JSON report: per primitive, run (the chosen plan, then forced alternatives), instance,
// time and output: pass, worst error and where, the tolerances, the plan's rules, the
// device and its driver.
std::string validationReportJson(const ValidationContext& ctx, const std::vector<ValidatedPart>& parts);

// The files of --save-outputs (names relative to the directory), from the chosen plan's
// captured outputs (ValidateOptions::keepOutputs): per primitive, instance, time and output
// `<part>.i<instance>.t<time>.<output>.bin` (little-endian float32, `components` per vertex),
// per primitive and time `<part>.t<time>.glb` (every instance's posed world positions, and
// normals when an output carries world.normal, as a glTF 2.0 binary), and `outputs.json`
// describing them all.
std::vector<std::pair<std::string, std::string>> savedOutputFiles(const ValidationContext& ctx,
                                                                   const std::vector<ValidatedPart>& parts);

}  // namespace sg
