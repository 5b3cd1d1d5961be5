#include "analysis/probe.h"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>

#include "common/input_file.h"
#include "rig/rig.h"
#include "rules/snippet.h"
#include "search/problem.h"

namespace sg {
namespace {

// GLSL identifier for a semantic instance: "morph.position[3]" -> "morph_position_3".
std::string mangle(const std::string& fact) {
  std::string s;
  for (char c : fact) {
    if (c == '.' || c == '[') s += '_';
    else if (c != ']') s += c;
  }
  return s;
}

bool isIntegerType(Type t) { return scalarKind(t) != ScalarKind::Float; }

// Semantics no rule produces: what some rig would have to provide.
std::set<std::string> leafSemantics(const RuleSet& rules) {
  std::set<std::string> produced;
  for (const auto& r : rules.rules) produced.insert(r.produces);
  std::set<std::string> leaves;
  for (const auto& d : rules.semantics)
    if (!produced.count(d.name)) leaves.insert(d.name);
  return leaves;
}

ProbeRig makeDefault(const RuleSet& rules, const std::string& name, std::map<std::string, int64_t> params,
                     bool provideLeaves) {
  ProbeRig pr;
  pr.name = name;
  pr.params = std::move(params);
  pr.params.emplace("uniform_scale", 1);  // probe the rules that need it too
  // Sparse morph rules size their loops by it (docs/buffers.md): a list as long as the targets.
  pr.params.emplace("max_active_targets", pr.params.count("morph_targets") ? pr.params.at("morph_targets") : 0);
  pr.isDefault = true;
  evalFamilies(pr, rules, false);
  if (provideLeaves)
    for (const auto& s : leafSemantics(rules)) {
      auto f = pr.families.find(s);
      if (f == pr.families.end()) pr.provided.insert(s);
      else
        for (int64_t i = 0; i < f->second; ++i) pr.provided.insert(indexedName(s, i));
    }
  return pr;
}

}  // namespace

ProbeRig probeRigFromRig(const Rig& rig, const RuleSet& rules) {
  ProbeRig pr;
  static_cast<RigShape&>(pr) = shapeOfRig(rig, rules);
  for (const auto& u : rig.uniforms) pr.uniforms.insert(u.semantic);
  for (const auto& a : rig.attributes) {
    int targets = a.perMorphTarget ? rig.morphTargets() : 1;
    for (int t = 0; t < targets; ++t)
      for (const auto& part : a.provides) {
        if (part.field >= 0) continue;  // unpacked into a local first: read like a uniform of its type
        std::string fact = a.perMorphTarget ? indexedName(part.semantic, t) : part.semantic;
        std::string input = a.perMorphTarget ? fmt::format("a_{}{}", a.name, t) : "a_" + a.name;
        pr.streams[fact] = ProbeRig::Stream{input, a.shaderType, part.swizzle};
      }
  }
  return pr;
}

std::vector<ProbeRig> defaultProbeRigs(const RuleSet& rules) {
  std::vector<ProbeRig> out;
  out.push_back(makeDefault(rules, "default rig (morph_targets=2, influences=4, bones=4)",
                            {{"morph_targets", 2}, {"influences", 4}, {"bones", 4}}, true));
  out.push_back(makeDefault(rules, "default rigid rig (morph_targets=0, influences=1, bones=4)",
                            {{"morph_targets", 0}, {"influences", 1}, {"bones", 4}}, true));
  out.push_back(makeDefault(rules, "default unskinned rig (morph_targets=0, influences=0, bones=0)",
                            {{"morph_targets", 0}, {"influences", 0}, {"bones", 0}}, true));
  out.push_back(makeDefault(rules, "default bare rig (no parameters, provides nothing)",
                            {{"morph_targets", 0}, {"influences", 0}, {"bones", 0}}, false));
  return out;
}

ExprEnv probeEnv(const ProbeRig& rig) { return shapeEnv(rig); }

SnippetProbe buildSnippetProbe(const RuleSet& rules, int r, const ProbeRig& rig, bool forAccesses) {
  const Rule& rule = rules.rules[static_cast<size_t>(r)];
  const std::string outName = "t_" + mangle(rule.produces);
  // Streams read the attribute (and swizzle) as the emitted shader does; the rest are uniforms.
  RuleInstance inst = instantiateRule(rules, r, rig, outName, [&](const std::string& full) {
    if (auto st = rig.streams.find(full); st != rig.streams.end())
      return st->second.swizzle.empty() ? st->second.input : st->second.input + "." + st->second.swizzle;
    return "p_" + mangle(full);
  });
  const SemanticDecl* product = rules.findSemantic(rule.produces);
  std::vector<ExpandedLine>& lines = inst.code;

  SnippetProbe probe;
  probe.productType = std::string(glslName(product->type));
  probe.unit.stage = Stage::Vertex;
  probe.unit.fileName = fmt::format("<probe of rule '{}'>", rule.name);
  std::string ruleFile = rule.loc.file;
  probe.unit.sourceFiles = {ruleFile};
  std::string& s = probe.unit.text;
  s += "#version 450\n";
  s += fmt::format("// Probe of rule '{}' instantiated for {}.\n", rule.name, rig.name);
  std::map<std::string, Type> inputs;  // vertex inputs read (attribute streams; per-vertex values forAccesses)
  std::string members;                  // uniform block members
  std::string constants;                // counts at their bound (forAccesses)
  std::string buffers;                  // storage buffers and their accessors, as the emitter reads them
  int binding = 1;
  for (const auto& fact : inst.needs) {
    const SemanticDecl* d = rules.findSemantic(splitIndexed(fact).first);
    if (!d->bufferOf.empty()) {
      const std::string n = "p_" + mangle(fact), t(glslName(d->type));
      buffers += fmt::format(
          "layout(set = 0, binding = {}, std430) readonly buffer ProbeBuffer{} {{\n  {} {}_data[];\n}};\n"
          "{} {}(int i) {{ return {}_data[uint(gl_VertexIndex) + uint(i)]; }}\n",
          binding, binding, t, n, t, n, n);
      probe.buffers.push_back(fact);
      ++binding;
      continue;
    }
    if (auto st = rig.streams.find(fact); st != rig.streams.end()) {
      inputs.emplace(st->second.input, st->second.type);
      continue;
    }
    if (forAccesses && !d->bound.empty()) {
      // At most as many iterations as a family has instances: a rig may state a larger bound
      // (max_active_targets up to 65535), and unrolling that many would take minutes for
      // iterations no list can fill.
      const int64_t most = std::clamp<int64_t>(d->bound.eval(probeEnv(rig)), 0, kMostFamilyInstances);
      constants += fmt::format("const {} p_{} = {}{};\n", glslName(d->type), mangle(fact), most,
                               scalarKind(d->type) == ScalarKind::UInt ? "u" : "");
      continue;
    }
    std::string array;
    if (auto it = rig.arrays.find(d->name); it != rig.arrays.end()) array = fmt::format("[{}]", it->second);
    if (forAccesses && array.empty() && !rig.uniforms.count(fact)) {
      inputs.emplace("p_" + mangle(fact), d->type);
      continue;
    }
    members += fmt::format("  {} p_{}{};\n", glslName(d->type), mangle(fact), array);
  }
  int location = 0;
  for (const auto& [name, type] : inputs) {
    s += fmt::format("layout(location = {}) in {} {};\n", location, glslName(type), name);
    location += isMatrix(type) ? 4 : 1;
  }
  if (!members.empty()) s += "layout(set = 0, binding = 0, std140) uniform ProbeInputs {\n" + members + "};\n";
  s += constants;
  s += buffers;
  s += fmt::format("layout(location = 0) {}out {} sg_probe_out;\n", isIntegerType(product->type) ? "flat " : "",
                   glslName(product->type));
  s += "void main() {\n";
  s += fmt::format("  {} {};\n", glslName(product->type), outName);
  int line = 1 + static_cast<int>(std::count(s.begin(), s.end(), '\n'));  // line number of the next line
  int expect = -1;
  for (const auto& l : lines) {
    if (l.loc.line != expect) {
      s += fmt::format("#line {} 1\n", l.loc.line);
      ++line;
    }
    s += "  " + l.text + "\n";
    ++line;
    probe.snippetLines.push_back(l.loc);
    expect = l.loc.line + 1;
  }
  probe.end = rule.glsl.empty() ? rule.loc : rule.glsl.back().loc;
  if (!rule.glsl.empty() && probe.end.col > 0) probe.end.col += static_cast<int>(rule.glsl.back().text.size());
  s += fmt::format("#line {} 0\n", line + 1);
  s += fmt::format("  sg_probe_out = {};\n", outName);
  s += "}\n";
  return probe;
}

CompileResult compileSnippetProbe(const SnippetProbe& probe, const Rule& rule) {
  CompileResult r = compileGlsl(probe.unit, TargetEnv::Vulkan1_0);
  for (auto& d : r.diagnostics) {
    // glslang's "'' :  syntax error..." names no token.
    if (d.message.rfind("'' :", 0) == 0) d.message = d.message.substr(d.message.find_first_not_of(" ", 4));
  }
  for (auto& d : r.diagnostics)
    if (d.loc.file == probe.unit.fileName) {
      bool syntax = d.message.find("syntax error") != std::string::npos;
      d.message = syntax ? fmt::format("at the end of the snippet of rule '{}': {} (a missing ';' or bracket?)",
                                       rule.name, d.message)
                         : fmt::format("the snippet of rule '{}' does not fit its product '{}' ({}): {}", rule.name,
                                       rule.produces, probe.productType, d.message);
      d.loc = probe.end.line ? probe.end : rule.loc;
    }
  refineSnippetColumns(r.diagnostics, probe.snippetLines);
  return r;
}

void refineSnippetColumns(std::vector<Diagnostic>& diags, const std::vector<SourceLoc>& snippetLines) {
  std::map<std::string, std::vector<std::string>> fileLines;
  auto rawLine = [&](const std::string& file, int line) -> std::string {
    auto it = fileLines.find(file);
    if (it == fileLines.end()) {
      std::vector<std::string> ls;
      std::string text;
      tryReadInputFile(file, text);  // bounded; unreadable = no lines
      for (size_t start = 0; start < text.size();) {
        size_t nl = text.find('\n', start);
        std::string l = text.substr(start, nl == std::string::npos ? std::string::npos : nl - start);
        if (!l.empty() && l.back() == '\r') l.pop_back();
        ls.push_back(std::move(l));
        if (nl == std::string::npos) break;
        start = nl + 1;
      }
      it = fileLines.emplace(file, std::move(ls)).first;
    }
    return line >= 1 && line <= static_cast<int>(it->second.size()) ? it->second[static_cast<size_t>(line - 1)] : "";
  };
  for (auto& d : diags) {
    if (d.loc.line <= 0 || d.loc.col > 0) continue;
    const SourceLoc* start = nullptr;
    for (const auto& s : snippetLines)
      if (s.file == d.loc.file && s.line == d.loc.line) {
        start = &s;
        break;
      }
    if (!start) continue;
    d.loc.col = std::max(1, start->col);
    // glslang quotes the offending token first: "'nrmalize' : no matching overloaded function found".
    size_t q1 = d.message.find('\'');
    size_t q2 = q1 == std::string::npos ? std::string::npos : d.message.find('\'', q1 + 1);
    if (q2 == std::string::npos || q2 == q1 + 1) continue;
    std::string token = d.message.substr(q1 + 1, q2 - q1 - 1);
    if (token == "assign") token = "=";  // glslang names the assignment operator
    if (token.find_first_not_of(' ') == std::string::npos) continue;
    std::string raw = rawLine(d.loc.file, d.loc.line);
    size_t from = static_cast<size_t>(std::max(0, start->col - 1));
    size_t at = raw.find(token, std::min(from, raw.size()));
    if (at != std::string::npos) d.loc.col = static_cast<int>(at) + 1;
  }
}

InputError refineSnippetError(const InputError& e, const std::vector<SourceLoc>& snippetLines) {
  std::vector<Diagnostic> all{e.diagnostic()};
  for (const auto& d : e.related)  // glslang's closing "compilation terminated" adds nothing
    if (d.message.find("compilation terminated") == std::string::npos) all.push_back(d);
  refineSnippetColumns(all, snippetLines);
  InputError out(all.front());
  out.related.assign(all.begin() + 1, all.end());
  return out;
}

}  // namespace sg
