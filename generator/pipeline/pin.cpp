#include "pipeline/pin.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "common/input_file.h"
#include "common/yaml_util.h"

namespace sg {
namespace {

// A YAML flow sequence of plain names (rule names are identifiers; quoted all the same).
std::string flowList(const std::vector<std::string>& names) {
  std::vector<std::string> quoted;
  for (const auto& n : names) quoted.push_back(YAML::Dump(YAML::Node(n)));
  return "[" + fmt::format("{}", fmt::join(quoted, ", ")) + "]";
}

std::string quoted(const std::string& s) {
  YAML::Emitter e;
  e << YAML::DoubleQuoted << s;
  return e.c_str();
}

std::vector<std::string> names(const YamlCtx& y, const YAML::Node& n, const char* what) {
  y.expectSeq(n, what);
  std::vector<std::string> out;
  for (const auto& item : n) out.push_back(y.scalar(item, what));
  std::vector<std::string> sorted = out;
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) y.fail(n, fmt::format("{} names a rule twice", what));
  return sorted;
}

double time(const YamlCtx& y, const YAML::Node& n, const char* what) {
  const std::string text = y.scalar(n, what);
  double v = NAN;
  size_t used = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
  }
  if (used != text.size() || !std::isfinite(v) || v <= 0) y.fail(n, fmt::format("{}: expected a positive number of nanoseconds", what));
  return v;
}

}  // namespace

std::string formatPin(const Pin& p) {
  std::string s = "# shadergen pin: the plan this device timed fastest (bench --pin-out); generate --pin writes it\n";
  s += "# docs/performance.md, \"A measured choice\"\n";
  s += fmt::format("device: {}\n", quoted(p.device));
  s += fmt::format("driver: {}\n", quoted(p.driver));
  s += fmt::format("clock: {}\n", quoted(p.clock));
  s += fmt::format("candidates: {}\n", p.candidates);
  s += fmt::format("plan: {}\n", quoted(p.label));
  s += fmt::format("program: {}\n", quoted(p.program));
  s += fmt::format("ns_per_vertex: {:.4f}\n", p.nsPerVertex);
  s += fmt::format("generated_ns_per_vertex: {:.4f}\n", p.generatedNsPerVertex);
  s += fmt::format("rules: {}\n", flowList(p.rules));
  s += fmt::format("ban: {}\n", flowList(p.bans));
  s += fmt::format("inputs: {}\n", p.inputs);
  return s;
}

Pin parsePin(const std::string& text, const std::string& file) {
  const YAML::Node root = parseYaml(text, file);
  YamlCtx y{file};
  y.expectMap(root, "a pin (bench --pin-out writes them)");
  y.checkKeys(root, {"device", "driver", "clock", "candidates", "plan", "program", "ns_per_vertex", "generated_ns_per_vertex", "rules",
                     "ban", "inputs"});
  for (const char* key : {"device", "driver", "clock", "candidates", "plan", "program", "ns_per_vertex", "generated_ns_per_vertex",
                          "rules", "ban", "inputs"})
    if (!root[key]) y.fail(root, fmt::format("a pin needs '{}' (bench --pin-out writes every key)", key));
  Pin p;
  p.file = file;
  p.device = y.scalar(root["device"], "device");
  p.driver = y.scalar(root["driver"], "driver");
  p.clock = y.scalar(root["clock"], "clock");
  const long long candidates = y.integer(root["candidates"], "candidates");
  if (candidates < 1) y.fail(root["candidates"], "candidates: expected a count of at least 1");
  p.candidates = size_t(candidates);
  p.label = y.scalar(root["plan"], "plan");
  p.program = y.scalar(root["program"], "program");
  p.nsPerVertex = time(y, root["ns_per_vertex"], "ns_per_vertex");
  p.generatedNsPerVertex = time(y, root["generated_ns_per_vertex"], "generated_ns_per_vertex");
  p.rules = names(y, root["rules"], "rules");
  if (p.rules.empty()) y.fail(root["rules"], "rules: a plan has at least one rule");
  p.bans = names(y, root["ban"], "ban");
  for (const auto& b : p.bans)
    if (std::binary_search(p.rules.begin(), p.rules.end(), b))
      y.fail(root["ban"], fmt::format("ban: '{}' is a rule of the pinned plan", b));
  p.inputs = y.scalar(root["inputs"], "inputs");
  if (p.inputs.size() != 64 || p.inputs.find_first_not_of("0123456789abcdef") != std::string::npos)
    y.fail(root["inputs"], "inputs: expected a SHA-256 (64 lowercase hex digits)");
  p.rulesLoc = locOf(root["rules"], file);
  p.banLoc = locOf(root["ban"], file);
  p.inputsLoc = locOf(root["inputs"], file);
  return p;
}

Pin loadPin(const std::string& path) { return parsePin(readInputFile(path), path); }

}  // namespace sg
