// Helpers shared by the validation tests.
#pragma once
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "rig/rig.h"
#include "runtime/procedural.h"
#include "validate/validate.h"

namespace sgtest {

namespace fs = std::filesystem;

// The ASan + UBSan build (cmake/Sanitizers.cmake, `cmake/dev.sh sanitize`), where code runs
// several times slower: tests whose point is not the mesh size use a smaller one there. The
// tests' own code is not instrumented (tests/CMakeLists.txt), so the build says so.
#if defined(SG_SANITIZED)
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif

inline std::string sourcePath(const std::string& rel) { return std::string(SG_SOURCE_DIR) + "/" + rel; }
inline std::string dataPath(const std::string& name) { return sourcePath("tests/validate/data/" + name); }
// rules/standard.yaml, loaded once.
inline const sg::RuleSet& standardRules() {
  static const sg::RuleSet rules = sg::loadRules({sourcePath("rules/standard.yaml")});
  return rules;
}

inline std::string readText(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + p.string());
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline void writeText(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  if (!out) throw std::runtime_error("cannot write " + p.string());
  out << text;
}

// Replaces the single occurrence of `from` in `text`; fails the test if there is none or
// several (so the tests notice when the rules they break change).
inline bool replaceOnce(std::string& text, const std::string& from, const std::string& to) {
  size_t at = text.find(from);
  if (at == std::string::npos) {
    ADD_FAILURE() << "'" << from << "' not found";
    return false;
  }
  if (text.find(from, at + 1) != std::string::npos) {
    ADD_FAILURE() << "'" << from << "' occurs more than once";
    return false;
  }
  text.replace(at, from.size(), to);
  return true;
}

// A private copy of the rules library (rules/*.yaml) and of examples/dawn/rules.yaml,
// whose include points at the copied library. Removed on destruction.
class RulesCopy {
 public:
  explicit RulesCopy(const std::string& tag) {
    root_ = fs::temp_directory_path() / ("sg_validate_" + tag + "_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_ / "rules");
    for (const auto& e : fs::directory_iterator(sourcePath("rules")))
      if (e.path().extension() == ".yaml") fs::copy_file(e.path(), root_ / "rules" / e.path().filename());
    std::string dawn = readText(sourcePath("examples/dawn/rules.yaml"));
    replaceOnce(dawn, "include: [../../rules/standard.yaml]",
                "include: [" + (root_ / "rules" / "standard.yaml").string() + "]");
    writeText(dawnRules(), dawn);
  }
  ~RulesCopy() {
    std::error_code ec;
    fs::remove_all(root_, ec);
  }
  RulesCopy(const RulesCopy&) = delete;
  RulesCopy& operator=(const RulesCopy&) = delete;

  fs::path root() const { return root_; }
  fs::path dawnRules() const { return root_ / "dawn_rules.yaml"; }
  fs::path rulesFile(const std::string& name) const { return root_ / "rules" / name; }

  // Breaks a rule on purpose: replaces `from` (exactly one occurrence) in rules/<file>.
  bool edit(const std::string& file, const std::string& from, const std::string& to) {
    std::string text = readText(rulesFile(file));
    if (!replaceOnce(text, from, to)) return false;
    writeText(rulesFile(file), text);
    return true;
  }

 private:
  fs::path root_;
};

inline std::set<std::string> failingOutputs(const sg::RunReport& run) {
  std::set<std::string> out;
  for (const auto& o : run.outputs)
    if (!o.pass) out.insert(o.name);
  return out;
}

inline std::set<std::string> allOutputs(const sg::RunReport& run) {
  std::set<std::string> out;
  for (const auto& o : run.outputs) out.insert(o.name);
  return out;
}

inline bool planHas(const sg::RunReport& run, const std::string& rule) {
  for (const auto& r : run.rules)
    if (r == rule) return true;
  return false;
}

// Largest error over every output of every run (for the tolerance table of docs/validation.md).
struct ErrorMax {
  double abs = 0, rel = 0;
  std::string absAt, relAt;
};
inline ErrorMax maxErrors(const sg::ValidateReport& rep) {
  ErrorMax m;
  for (const auto& run : rep.runs)
    for (const auto& o : run.outputs) {
      if (o.maxAbsError > m.abs) m.abs = o.maxAbsError, m.absAt = o.name;
      if (o.maxRelError > m.rel) m.rel = o.maxRelError, m.relAt = o.name;
    }
  return m;
}

// A rig file for a procedural mesh built with `mo` (every stream it carries, every uniform).
inline sg::Rig rigFor(const sg::rt::MeshOptions& mo, bool model, bool uniformScale) {
  std::string y = "rig: oracle\ndeformers:\n";
  y += "  bones: " + std::to_string(mo.influences ? mo.bones : 0) + "\n  influences: " + std::to_string(mo.influences) +
       "\n  morph_targets: " + std::to_string(mo.morphTargets) + "\n  uniform_scale: " + (uniformScale ? "1" : "0") + "\n";
  if (mo.morphTargets) y += std::string("  morphs: [position") + (mo.morphNormals ? ", normal" : "") + (mo.morphTangents ? ", tangent" : "") + "]\n";
  y += "attributes:\n  p: { format: float32x3, provides: vertex.position }\n"
       "  n: { format: float32x4, provides: { vertex.normal: xyz, vertex.occlusion: w } }\n"
       "  t: { format: float32x4, provides: { vertex.tangent: xyz, vertex.handedness: w } }\n";
  if (mo.morphTargets) {
    y += "  dp: { format: float32x3, per_target: true, provides: morph.position }\n";
    if (mo.morphNormals) y += "  dn: { format: float32x4, per_target: true, provides: { morph.normal: xyz, morph.occlusion: w } }\n";
    if (mo.morphTangents) y += "  dt: { format: float32x3, per_target: true, provides: morph.tangent }\n";
  }
  for (int s = 0; s < (mo.influences + 3) / 4; ++s)
    y += "  j" + std::to_string(s) + ": { format: float32x4, provides: \"skin.joints[" + std::to_string(s) + "]\" }\n" +
         "  w" + std::to_string(s) + ": { format: float32x4, provides: \"skin.weights[" + std::to_string(s) + "]\" }\n";
  y += "uniforms:\n";
  if (mo.influences) y += "  bones: { type: mat4, array: bones, semantic: skin.bones }\n";
  if (mo.morphTargets) y += "  mw: { type: float, array: morph_targets, semantic: morph.weights }\n";
  if (model) y += "  model: { type: mat4, semantic: model.matrix }\n";
  y += "  cam: { type: vec3, semantic: camera.position }\n  view: { type: mat4, semantic: camera.view }\n"
       "  proj: { type: mat4, semantic: camera.projection }\n  dapple: { type: mat4, semantic: dapple.matrix }\n";
  return sg::loadRigText(y, "oracle.rig.yaml");
}

// One procedural case: the mesh, the rig file describing it, and the reference's shape.
struct ProceduralCase {
  std::string which;  // "head" or "limb"
  sg::rt::MeshOptions mo;
  bool uniformScale = false;
  sg::rt::Mesh mesh;
  sg::Rig rig;
  sg::rt::RigShape shape;
};

// Every rig form on small procedural meshes: 0, 1, 2, 4 and 8 influences, with and without
// 3 morph targets (tangents morphed for even influence counts), uniform scale or not (the
// unskinned ones without it get a model matrix), head and limb.
template <class F>
void forEachProceduralCase(F f) {
  for (int influences : {0, 1, 2, 4, 8})
    for (int targets : {0, 3})
      for (bool uniformScale : {false, true})
        for (const char* which : {"head", "limb"}) {
          ProceduralCase c;
          c.which = which;
          c.uniformScale = uniformScale;
          c.mo.influences = influences;
          c.mo.morphTargets = targets;
          c.mo.morphTangents = targets > 0 && influences % 2 == 0;
          c.mo.bones = 6;
          const bool model = influences == 0 && !uniformScale;
          c.mesh = c.which == "head" ? sg::rt::makeHead(12, 16, c.mo) : sg::rt::makeLimb(10, 12, c.mo);
          c.rig = rigFor(c.mo, model, uniformScale);
          c.shape = sg::rt::rigShapeFor(c.mo);
          c.shape.hasModelMatrix = model;
          c.shape.uniformScale = uniformScale;
          SCOPED_TRACE(::testing::Message() << which << " influences " << influences << " targets " << targets
                                            << " uniform_scale " << uniformScale);
          f(c);
        }
}

}  // namespace sgtest
