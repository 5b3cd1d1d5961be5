#include "analysis/graph.h"

#include "analysis/explain.h"

#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>

extern char** environ;

namespace sg {
namespace {

std::string dotQuote(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

// Label text: '\n' becomes DOT's centred line break.
std::string label(const std::string& s) {
  std::string q = dotQuote(s);
  std::string out;
  for (char c : q) out += c == '\n' ? std::string("\\n") : std::string(1, c);
  return out;
}

std::string familyOf(const std::string& fact) { return fact.substr(0, fact.find('[')); }

}  // namespace

std::string planToDot(const LoadedInputs& in, const Plan& plan) {
  const Problem& p = in.problem;
  std::map<int, int> producer;  // fact -> action
  for (int a : plan.actions) producer[p.actions[a].add] = a;
  std::map<int, int> uses;
  for (int a : plan.actions)
    for (int q : p.actions[a].pre) ++uses[q];
  for (const auto& v : in.varyings)
    for (const auto& s : v.semantics)
      if (int f = p.findFact(s); f >= 0) ++uses[f];

  // Input nodes: one per provided semantic, one per indexed family.
  std::map<std::string, std::vector<int>> inputs;  // node key -> facts
  auto inputKey = [&](int f) { return familyOf(p.facts[f].name); };
  auto noteInput = [&](int f) {
    auto& v = inputs[inputKey(f)];
    if (std::find(v.begin(), v.end(), f) == v.end()) v.push_back(f);
  };
  for (int a : plan.actions)
    for (int q : p.actions[a].pre)
      if (!producer.count(q)) noteInput(q);
  for (const auto& v : in.varyings)
    for (const auto& s : v.semantics)
      if (int f = p.findFact(s); f >= 0 && !producer.count(f)) noteInput(f);

  auto inputId = [](const std::string& key) { return dotQuote("in:" + key); };
  auto ruleId = [&](int a) { return dotQuote("rule:" + p.actions[a].name); };
  auto outId = [](const std::string& name) { return dotQuote("out:" + name); };

  std::string d;
  d += "digraph plan {\n";
  d += fmt::format("  graph [rankdir=LR, fontname=\"Helvetica\", fontsize=12, labelloc=t, nodesep=0.25, ranksep=0.6,\n"
                   "         label={}];\n",
                   label(fmt::format("rig '{}' -> {}: {} rules, total cost {} (each value paid once)", in.rig.name,
                                     std::filesystem::path(in.fragment.file).filename().string(),
                                     plan.actions.size(), plan.cost)));
  d += "  node [fontname=\"Helvetica\", fontsize=10];\n";
  d += "  edge [color=\"#666666\", arrowsize=0.6];\n\n";

  d += "  // rig inputs (vertex attributes and uniforms)\n";
  d += "  { rank=source;\n";
  for (const auto& [key, facts] : inputs) {
    const Fact& f0 = p.facts[facts.front()];
    std::vector<int> sorted = facts;  // fact order keeps family instances in index order
    std::sort(sorted.begin(), sorted.end());
    std::vector<std::string> names;
    for (int f : sorted) names.push_back(p.facts[f].name);
    std::string name = compactFactList(names);
    std::string from;
    if (f0.source == Fact::Source::Attribute && f0.rigIndex >= 0) from = "attribute " + in.rig.attributes[f0.rigIndex].name;
    else if (f0.source == Fact::Source::Uniform && f0.rigIndex >= 0) from = "uniform " + in.rig.uniforms[f0.rigIndex].name;
    if (facts.size() > 1 && f0.source == Fact::Source::Attribute) from += fmt::format(" x{}", facts.size());
    d += fmt::format("    {} [shape=ellipse, style=filled, fillcolor=\"#e3ecfa\", color=\"#7a9cc6\", label={}];\n",
                     inputId(key), label(name + (from.empty() ? "" : "\n" + from)));
  }
  d += "  }\n\n  // rules of the plan: produced value and cost\n";
  for (int a : plan.actions) {
    const Action& act = p.actions[a];
    int n = uses[act.add];
    bool shared = n > 1;
    std::string text = fmt::format("{}\n{}\ncost {}", act.name, p.facts[act.add].name, act.cost);
    if (shared) text += fmt::format("\nshared by {}, paid once", n);
    d += fmt::format("  {} [shape=box, style=\"rounded,filled\", fillcolor={}, color={}, penwidth={}, label={}];\n",
                     ruleId(a), shared ? "\"#ffe2b8\"" : "\"#fff7e0\"", shared ? "\"#d08a1e\"" : "\"#c9a64a\"",
                     shared ? 2 : 1, label(text));
  }
  d += "\n  // fragment shader inputs\n  { rank=sink;\n";
  for (const auto& v : in.varyings) {
    std::string sems;
    for (const auto& s : v.semantics) sems += (sems.empty() ? "" : ", ") + s;
    std::string where = v.location >= 0 ? fmt::format("location {}", v.location) : "gl_Position";
    d += fmt::format("    {} [shape=cds, style=filled, fillcolor=\"#dff2e1\", color=\"#5c9e68\", label={}];\n",
                     outId(v.name), label(fmt::format("{}\n{} ({})", v.name, glslName(v.type), where)));
  }
  d += "  }\n\n  // edges: value flow\n";
  std::set<std::pair<std::string, std::string>> edges;
  std::vector<std::pair<std::string, std::string>> ordered;
  auto edge = [&](const std::string& from, const std::string& to) {
    if (edges.insert({from, to}).second) ordered.push_back({from, to});
  };
  for (int a : plan.actions)
    for (int q : p.actions[a].pre) {
      auto it = producer.find(q);
      edge(it != producer.end() ? ruleId(it->second) : inputId(inputKey(q)), ruleId(a));
    }
  for (const auto& v : in.varyings)
    for (const auto& s : v.semantics) {
      int f = p.findFact(s);
      if (f < 0) continue;
      auto it = producer.find(f);
      edge(it != producer.end() ? ruleId(it->second) : inputId(inputKey(f)), outId(v.name));
    }
  for (const auto& [from, to] : ordered) d += fmt::format("  {} -> {};\n", from, to);
  d += "}\n";
  return d;
}

std::string findOnPath(const std::string& program) {
  const char* path = std::getenv("PATH");
  if (!path) return "";
  std::string all = path;
  for (size_t start = 0;;) {
    size_t colon = all.find(':', start);
    std::string dir = all.substr(start, colon == std::string::npos ? std::string::npos : colon - start);
    if (!dir.empty()) {
      std::string full = dir + "/" + program;
      std::error_code ec;  // a strange PATH entry must not throw
      if (::access(full.c_str(), X_OK) == 0 && !std::filesystem::is_directory(full, ec)) return full;
    }
    if (colon == std::string::npos) break;
    start = colon + 1;
  }
  return "";
}

void renderSvg(const std::string& dotText, const std::string& svgPath) {
  std::string dot = findOnPath("dot");
  if (dot.empty()) throw std::runtime_error("cannot write SVG: Graphviz 'dot' is not on PATH (install graphviz)");
  std::filesystem::path target(svgPath);
  std::string tmpDot = svgPath + ".tmp.dot";
  std::string tmpSvg = svgPath + ".tmp";
  {
    std::ofstream o(tmpDot, std::ios::binary);
    o << dotText;
    if (!o) throw std::runtime_error("cannot write " + tmpDot);
  }
  std::vector<std::string> args{dot, "-Tsvg", tmpDot, "-o", tmpSvg};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  int rc = posix_spawn(&pid, dot.c_str(), nullptr, nullptr, argv.data(), environ);
  int status = 0;
  if (rc == 0) waitpid(pid, &status, 0);
  std::error_code ec;
  std::filesystem::remove(tmpDot, ec);
  if (rc != 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::filesystem::remove(tmpSvg, ec);
    throw std::runtime_error(fmt::format("'{}' failed to render {}", dot, svgPath));
  }
  std::filesystem::rename(tmpSvg, target);
}

}  // namespace sg
