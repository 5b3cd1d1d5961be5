#include "pipeline/pin.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>

#include "common/input_file.h"
#include "common/yaml_util.h"

namespace sg {
namespace {

// Written by yaml-cpp's emitter, so that any name or text reads back as itself.
std::string flowList(const std::vector<std::string>& names) {
  YAML::Emitter e;
  e << YAML::Flow << YAML::BeginSeq;
  for (const auto& n : names) e << YAML::DoubleQuoted << n;
  e << YAML::EndSeq;
  return e.c_str();
}

std::string quoted(const std::string& s) {
  YAML::Emitter e;
  e << YAML::DoubleQuoted << s;
  return e.c_str();
}

// Well-formed UTF-8 without control characters: what bench writes (device names, labels, rule
// names), and what the writer's quoting gives back unchanged.
bool plainText(const std::string& s) {
  for (size_t i = 0; i < s.size();) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    size_t n = c < 0x80 ? 0 : (c & 0xE0) == 0xC0 ? 1 : (c & 0xF0) == 0xE0 ? 2 : (c & 0xF8) == 0xF0 ? 3 : 4;
    if (n == 4 || (n == 0 && (c < 0x20 || c == 0x7F)) || (n == 1 && c < 0xC2) || (n > 0 && i + n >= s.size())) return false;
    uint32_t cp = n == 0 ? c : c & (0x3F >> n);
    for (size_t k = 1; k <= n; ++k) {
      const unsigned char d = static_cast<unsigned char>(s[i + k]);
      if ((d & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (d & 0x3F);
    }
    // Overlong forms, surrogates and code points past Unicode.
    if ((n == 2 && cp < 0x800) || (n == 3 && cp < 0x10000) || (cp >= 0xD800 && cp <= 0xDFFF) || cp > 0x10FFFF) return false;
    i += n + 1;
  }
  return true;
}

std::string textOf(const YamlCtx& y, const YAML::Node& n, const char* what) {
  std::string s = y.scalar(n, what);
  if (!plainText(s)) y.fail(n, fmt::format("{}: expected text (UTF-8, no control characters)", what));
  return s;
}

std::vector<std::string> names(const YamlCtx& y, const YAML::Node& n, const char* what) {
  y.expectSeq(n, what);
  std::vector<std::string> out;
  for (const auto& item : n) out.push_back(textOf(y, item, what));
  std::vector<std::string> sorted = out;
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) y.fail(n, fmt::format("{} names a rule twice", what));
  return sorted;
}

double time(const YamlCtx& y, const YAML::Node& n, const char* what) {
  const std::string number = y.scalar(n, what);
  double v = NAN;
  size_t used = 0;
  try {
    v = std::stod(number, &used);
  } catch (const std::exception&) {
  }
  if (used != number.size() || !std::isfinite(v) || v <= 0) y.fail(n, fmt::format("{}: expected a positive number of nanoseconds", what));
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
  s += fmt::format("ns_per_vertex: {}\n", p.nsPerVertex);  // shortest text that reads back as the same double
  s += fmt::format("generated_ns_per_vertex: {}\n", p.generatedNsPerVertex);
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
  p.device = textOf(y, root["device"], "device");
  p.driver = textOf(y, root["driver"], "driver");
  p.clock = textOf(y, root["clock"], "clock");
  const long long candidates = y.integer(root["candidates"], "candidates");
  if (candidates < 1) y.fail(root["candidates"], "candidates: expected a count of at least 1");
  p.candidates = size_t(candidates);
  p.label = textOf(y, root["plan"], "plan");
  p.program = textOf(y, root["program"], "program");
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

std::optional<Diagnostic> pinInputsChanged(const Pin& pin, const std::string& inputsDigest) {
  if (inputsDigest == pin.inputs) return std::nullopt;
  return Diagnostic{Severity::Warning, pin.inputsLoc,
                    fmt::format("the inputs' bytes differ from those the pin was measured with on {} (the pin still "
                                "gives its plan; its timing may not hold)",
                                pin.device)};
}

}  // namespace sg
