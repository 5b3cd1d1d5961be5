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

// One entry of a merged pin's `devices:`.
std::string formatTiming(const PinTiming& t) {
  std::string s = fmt::format("  - device: {}\n", quoted(t.device));
  s += fmt::format("    driver: {}\n", quoted(t.driver));
  s += fmt::format("    clock: {}\n", quoted(t.clock));
  s += fmt::format("    ns_per_vertex: {}\n", t.nsPerVertex);
  s += fmt::format("    fastest_ns_per_vertex: {}\n", t.fastestNsPerVertex);
  s += fmt::format("    generated_ns_per_vertex: {}\n", t.generatedNsPerVertex);
  return s;
}

// A bench pin's flat keys (`fastest`: false; its plan is its fastest) or a `devices:` entry.
PinTiming parseTiming(const YamlCtx& y, const YAML::Node& n, bool fastest) {
  PinTiming t;
  t.device = textOf(y, n["device"], "device");
  t.driver = textOf(y, n["driver"], "driver");
  t.clock = textOf(y, n["clock"], "clock");
  t.nsPerVertex = time(y, n["ns_per_vertex"], "ns_per_vertex");
  t.generatedNsPerVertex = time(y, n["generated_ns_per_vertex"], "generated_ns_per_vertex");
  t.fastestNsPerVertex = fastest ? time(y, n["fastest_ns_per_vertex"], "fastest_ns_per_vertex") : t.nsPerVertex;
  if (t.fastestNsPerVertex > t.nsPerVertex) y.fail(n, "fastest_ns_per_vertex: more than the pinned plan's ns_per_vertex");
  return t;
}

void requireKeys(const YamlCtx& y, const YAML::Node& n, std::initializer_list<const char*> keys, const char* writer) {
  for (const char* key : keys)
    if (!n[key]) y.fail(n, fmt::format("a pin needs '{}' ({} writes every key)", key, writer));
}

std::vector<std::string> bansOf(const YamlCtx& y, const YAML::Node& n, const std::vector<std::string>& rules) {
  std::vector<std::string> bans = names(y, n, "ban");
  for (const auto& b : bans)
    if (std::binary_search(rules.begin(), rules.end(), b)) y.fail(n, fmt::format("ban: '{}' is a rule of the pinned plan", b));
  return bans;
}

}  // namespace

std::string Pin::deviceNames() const {
  std::vector<std::string> names;
  for (const PinTiming& t : devices) names.push_back(t.device);
  return fmt::format("{}", fmt::join(names, " + "));
}

std::string formatPin(const Pin& p) {
  const bool merged = p.devices.size() != 1;
  std::string s = merged ? "# shadergen pin: the plan whose worst regret over these devices' timings is least (pin merge); "
                           "generate --pin writes it\n"
                         : "# shadergen pin: the plan this device timed fastest (bench --pin-out); generate --pin writes it\n";
  s += "# docs/performance.md, \"A measured choice\"\n";
  if (merged) {
    s += "devices:\n";
    for (const PinTiming& t : p.devices) s += formatTiming(t);
  } else {
    s += fmt::format("device: {}\ndriver: {}\nclock: {}\n", quoted(p.devices[0].device), quoted(p.devices[0].driver),
                     quoted(p.devices[0].clock));
  }
  s += fmt::format("candidates: {}\n", p.candidates);
  s += fmt::format("plan: {}\n", quoted(p.label));
  s += fmt::format("program: {}\n", quoted(p.program));
  if (!merged) {
    s += fmt::format("ns_per_vertex: {}\n", p.devices[0].nsPerVertex);  // shortest text that reads back as the same double
    s += fmt::format("generated_ns_per_vertex: {}\n", p.devices[0].generatedNsPerVertex);
  }
  s += fmt::format("rules: {}\n", flowList(p.rules));
  s += fmt::format("ban: {}\n", flowList(p.bans));
  s += fmt::format("inputs: {}\n", p.inputs);
  if (!p.timed.empty()) {
    s += "timed:  # every validated plan bench timed, its median round (pin merge weighs them)\n";
    for (const TimedPlan& t : p.timed)
      s += fmt::format("  - {{plan: {}, program: {}, ns_per_vertex: {}, rules: {}, ban: {}}}\n", quoted(t.label), quoted(t.program),
                       t.nsPerVertex, flowList(t.rules), flowList(t.bans));
  }
  return s;
}

Pin parsePin(const std::string& text, const std::string& file) {
  const YAML::Node root = parseYaml(text, file);
  YamlCtx y{file};
  y.expectMap(root, "a pin (bench --pin-out writes them)");
  const bool merged = bool(root["devices"]);
  if (merged) {
    y.checkKeys(root, {"devices", "candidates", "plan", "program", "rules", "ban", "inputs"});
    requireKeys(y, root, {"devices", "candidates", "plan", "program", "rules", "ban", "inputs"}, "pin merge");
  } else {
    y.checkKeys(root, {"device", "driver", "clock", "candidates", "plan", "program", "ns_per_vertex", "generated_ns_per_vertex", "rules",
                       "ban", "inputs", "timed"});
    requireKeys(y, root,
                {"device", "driver", "clock", "candidates", "plan", "program", "ns_per_vertex", "generated_ns_per_vertex", "rules", "ban",
                 "inputs"},
                "bench --pin-out");
  }
  Pin p;
  p.file = file;
  p.loc = locOf(root, file);
  if (merged) {
    y.expectSeq(root["devices"], "devices");
    if (root["devices"].size() < 2) y.fail(root["devices"], "devices: a merged pin weighs two devices at least");
    for (const auto& d : root["devices"]) {
      y.expectMap(d, "a device of a merged pin");
      y.checkKeys(d, {"device", "driver", "clock", "ns_per_vertex", "fastest_ns_per_vertex", "generated_ns_per_vertex"});
      requireKeys(y, d, {"device", "driver", "clock", "ns_per_vertex", "fastest_ns_per_vertex", "generated_ns_per_vertex"}, "pin merge");
      p.devices.push_back(parseTiming(y, d, true));
    }
  } else {
    p.devices.push_back(parseTiming(y, root, false));
  }
  const long long candidates = y.integer(root["candidates"], "candidates");
  if (candidates < 1) y.fail(root["candidates"], "candidates: expected a count of at least 1");
  p.candidates = size_t(candidates);
  p.label = textOf(y, root["plan"], "plan");
  p.program = textOf(y, root["program"], "program");
  p.rules = names(y, root["rules"], "rules");
  if (p.rules.empty()) y.fail(root["rules"], "rules: a plan has at least one rule");
  p.bans = bansOf(y, root["ban"], p.rules);
  p.inputs = y.scalar(root["inputs"], "inputs");
  if (p.inputs.size() != 64 || p.inputs.find_first_not_of("0123456789abcdef") != std::string::npos)
    y.fail(root["inputs"], "inputs: expected a SHA-256 (64 lowercase hex digits)");
  if (const YAML::Node timed = root["timed"]) {
    y.expectSeq(timed, "timed");
    for (const auto& t : timed) {
      y.expectMap(t, "a timed plan");
      y.checkKeys(t, {"plan", "program", "ns_per_vertex", "rules", "ban"});
      requireKeys(y, t, {"plan", "program", "ns_per_vertex", "rules", "ban"}, "bench --pin-out");
      TimedPlan plan;
      plan.label = textOf(y, t["plan"], "plan");
      plan.program = textOf(y, t["program"], "program");
      plan.nsPerVertex = time(y, t["ns_per_vertex"], "ns_per_vertex");
      plan.rules = names(y, t["rules"], "rules");
      if (plan.rules.empty()) y.fail(t["rules"], "rules: a plan has at least one rule");
      plan.bans = bansOf(y, t["ban"], plan.rules);
      p.timed.push_back(plan);
    }
  }
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
                                pin.deviceNames())};
}

Pin mergePins(const std::vector<Pin>& pins) {
  if (pins.size() < 2) throw InputError(SourceLoc{}, "pin merge: weighs two pins at least (one per device)");
  for (const Pin& p : pins) {
    if (p.devices.size() != 1)
      throw InputError(p.loc, "pin merge: a merged pin is not merged again (merge the devices' own pins, bench --pin-out)");
    if (p.timed.empty())
      throw InputError(p.loc, "pin merge: the pin lists no timed plans (bench --pin-out writes them since session 41: run it again)");
    if (p.inputs != pins[0].inputs)
      throw InputError(p.inputsLoc, fmt::format("pin merge: measured with other inputs' bytes than {} (the same rig, request, "
                                                "rules and templates on every device)",
                                                pins[0].file));
  }
  // A plan is the same on two devices where its rules and its program are.
  auto find = [](const Pin& p, const TimedPlan& t) -> const TimedPlan* {
    for (const TimedPlan& u : p.timed)
      if (u.rules == t.rules && u.program == t.program) return &u;
    return nullptr;
  };
  std::vector<double> fastest;
  for (const Pin& p : pins) {
    double f = INFINITY;
    for (const TimedPlan& t : p.timed) f = std::min(f, t.nsPerVertex);
    fastest.push_back(f);
  }
  const TimedPlan* best = nullptr;
  double bestRegret = INFINITY;
  size_t common = 0;
  for (const TimedPlan& t : pins[0].timed) {
    double worst = 0;
    bool everywhere = true;
    for (size_t d = 0; d < pins.size() && everywhere; ++d)
      if (const TimedPlan* u = find(pins[d], t)) worst = std::max(worst, u->nsPerVertex / fastest[d]);
      else everywhere = false;
    if (!everywhere) continue;
    ++common;
    if (worst < bestRegret) bestRegret = worst, best = &t;
  }
  if (!best)
    throw InputError(pins[0].loc, fmt::format("pin merge: no plan was timed on every device ({} plans here; time the same candidates "
                                              "everywhere: bench --candidates K with the same profiles)",
                                              pins[0].timed.size()));
  Pin out;
  out.label = best->label;
  out.program = best->program;
  out.rules = best->rules;
  out.bans = best->bans;
  out.inputs = pins[0].inputs;
  out.candidates = common;
  for (size_t d = 0; d < pins.size(); ++d) {
    PinTiming t = pins[d].devices[0];
    t.nsPerVertex = find(pins[d], *best)->nsPerVertex;
    t.fastestNsPerVertex = fastest[d];
    out.devices.push_back(t);
  }
  return out;
}

}  // namespace sg
