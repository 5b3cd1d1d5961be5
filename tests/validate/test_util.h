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

#include "validate/validate.h"

namespace sgtest {

namespace fs = std::filesystem;

inline std::string sourcePath(const std::string& rel) { return std::string(SG_SOURCE_DIR) + "/" + rel; }
inline std::string dataPath(const std::string& name) { return sourcePath("tests/validate/data/" + name); }

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

}  // namespace sgtest
