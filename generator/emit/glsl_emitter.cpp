#include "emit/glsl_emitter.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <set>
#include <stdexcept>

#include "interface/fragment_interface.h"

namespace sg {

std::string semanticIdentifier(const std::string& fact) {
  std::string s;
  for (char c : fact) {
    if (c == '.' || c == '[') s += '_';
    else if (c != ']') s += c;
  }
  return s;
}

std::string commentSafe(const std::string& text) {
  std::string s;
  for (char c : text) {
    auto u = static_cast<unsigned char>(c);
    // A newline would end the comment and inject code; a trailing '\\' would splice the
    // next line into the comment (GLSL line continuation).
    s += (u < 0x20 || u == 0x7f || c == '\\') ? '?' : c;
  }
  return s;
}

namespace {

// A local's name from what it holds ("world.normal" -> world_normal): no "__" (reserved
// in GLSL) and no trailing '_' (the snippets' own temporaries end with one).
std::string localBase(const std::string& semantic) {
  std::string s;
  for (char c : semanticIdentifier(semantic))
    if (c != '_' || (!s.empty() && s.back() != '_')) s += c;
  while (!s.empty() && s.back() == '_') s.pop_back();
  // A name without '_' could be a GLSL keyword or built-in function (no keyword has one
  // but atomic_uint), and gl_ is reserved.
  if (s.find('_') == std::string::npos || s.rfind("gl_", 0) == 0 || s == "atomic_uint") s = "value_" + s;
  return s;
}

// The local holding an attribute read in parts, named for the semantics it provides:
// {vertex.normal: xyz, vertex.occlusion: w} -> vertex_normal_occlusion; per target t, _t.
std::string attributeLocalBase(const RigAttribute& a, int target) {
  std::string s, family;
  for (const auto& p : a.provides) {
    const size_t dot = p.semantic.rfind('.');
    const std::string prefix = dot == std::string::npos ? "" : p.semantic.substr(0, dot);
    if (s.empty()) {
      s = p.semantic;
      family = prefix;
    } else {
      s += "_" + (prefix == family && dot != std::string::npos ? p.semantic.substr(dot + 1) : p.semantic);
    }
  }
  if (target >= 0) s += fmt::format("_{}", target);
  return localBase(s);
}

// One rule's snippet lines re-indented as a person would write them: two spaces inside
// main, two more per open brace, and a line that continues a statement keeps its offset
// (at least two spaces) from the statement's first line as the rules file wrote it. The
// lines of a shared snippet (`@use`) keep their own YAML indentation, which says nothing
// about where the using rule puts them; braces and statement ends do.
std::vector<std::string> reindent(const std::vector<std::string>& lines) {
  std::vector<std::string> out;
  int depth = 0, stmtIndent = 2, stmtOwn = 0;
  bool continues = false;
  for (const auto& line : lines) {
    const size_t b = line.find_first_not_of(" \t");
    if (b == std::string::npos) {
      out.emplace_back();
      continue;
    }
    std::string text = line.substr(b);
    text.erase(text.find_last_not_of(" \t") + 1);
    std::string code = text.substr(0, text.find("//"));  // without a trailing comment
    while (!code.empty() && (code.back() == ' ' || code.back() == '\t')) code.pop_back();
    const int own = static_cast<int>(b);
    int indent = 0;
    if (continues) {
      indent = stmtIndent + std::max(2, own - stmtOwn);
    } else {
      indent = 2 + 2 * std::max(0, depth - (text[0] == '}' ? 1 : 0));
      stmtIndent = indent;
      stmtOwn = own;
    }
    for (char c : code) depth = std::max(0, depth + (c == '{') - (c == '}'));
    if (!code.empty() && code[0] != '#') continues = code.back() != ';' && code.back() != '{' && code.back() != '}';
    out.push_back(std::string(static_cast<size_t>(indent), ' ') + text);
  }
  return out;
}

std::string baseName(const std::string& path) { return commentSafe(std::filesystem::path(path).filename().string()); }

// The fact id inside an internal reference "\x01<id>\x02" (rules/snippet.h): snippets
// cannot contain these bytes (the rules loader refuses control bytes), so a malformed
// one is a bug here, not an input error.
int refFact(const std::string& s, size_t begin, size_t facts) {
  size_t i = begin + 1;
  long long v = 0;
  while (i < s.size() && s[i] >= '0' && s[i] <= '9' && v < 1'000'000'000) v = v * 10 + (s[i++] - '0');
  if (i == begin + 1 || i >= s.size() || s[i] != kFactRefEnd || v < 0 || static_cast<size_t>(v) >= facts)
    throw std::logic_error("internal error: malformed fact reference in a snippet");
  return static_cast<int>(v);
}

class Emitter {
 public:
  Emitter(const Rig& rig, const Problem& p, const Plan& plan, const std::vector<Varying>& varyings,
          const TemplateSet& t, const EmitOptions& opts)
      : rig_(rig), p_(p), plan_(plan), varyings_(varyings), t_(t), opts_(opts) {}

  EmittedGlsl run(const std::string& fragmentName) {
    collectUsedFacts();
    declareInputs();
    declareUniforms();
    declareBuffers();
    std::string outputs = declareOutputs();
    nameLocals();
    std::string inputs;
    for (const auto& in : out_.inputs)
      inputs += t_.fill("input", {{"location", std::to_string(in.location)},
                                  {"type", std::string(glslName(in.type))},
                                  {"name", in.name}}) + "\n";
    std::string uniforms;
    if (!out_.uniforms.empty()) {
      std::string members;
      for (const auto& u : out_.uniforms) {
        const RigUniform& ru = rig_.uniforms[u.uniform];
        if (!members.empty()) members += "\n";
        members += t_.fill("uniform_member", {{"type", std::string(glslName(ru.type))},
                                              {"name", u.name},
                                              {"array", ru.arraySize ? fmt::format("[{}]", ru.arraySize) : ""}});
      }
      uniforms = t_.fill("uniform_block", {{"members", members}}) + "\n";
    }
    uniforms += bufferDeclarations();
    std::string stores;
    for (const auto& o : out_.outputs) {
      if (o.arraySize) {  // one semantic per element
        for (size_t i = 0; i < o.semantics.size(); ++i) {
          if (!stores.empty()) stores += "\n";
          stores += t_.fill("store", {{"name", fmt::format("{}[{}]", o.name, i)},
                                      {"value", factExpr(p_.findFact(o.semantics[i]))}});
        }
        continue;
      }
      std::string value;
      if (o.semantics.size() == 1) {
        value = factExpr(p_.findFact(o.semantics[0]));
      } else {  // packed vector, or a matrix filled column by column
        std::string args;
        for (const auto& s : o.semantics) args += (args.empty() ? "" : ", ") + factExpr(p_.findFact(s));
        value = t_.fill("pack", {{"type", std::string(glslName(o.type))}, {"args", args}});
      }
      if (!stores.empty()) stores += "\n";
      stores += t_.fill("store", {{"name", o.name}, {"value", value}});
    }
    // Fill with a marker for the body first: its #line directives need absolute line numbers.
    const std::string marker = "\x03BODY\x03";
    std::map<std::string, std::string> v{
        {"version", opts_.version},
        {"extensions", ""},
        {"rig", commentSafe(rig_.name)},
        {"fragment", baseName(fragmentName)},
        {"cost", std::to_string(plan_.cost)},
        {"heuristic", opts_.heuristic},
        {"search", opts_.search},
        {"sources", sourcesList()},
        {"inputs", inputs},
        {"uniforms", uniforms},
        {"outputs", outputs},
        {"body", marker},
        {"stores", stores}};
    std::string text = t_.fill("shader", v);
    size_t at = text.find(marker);
    int bodyLine = 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
    text.replace(at, marker.size(), body(bodyLine));
    if (text.empty() || text.back() != '\n') text += '\n';
    out_.text = std::move(text);
    return std::move(out_);
  }

 private:
  void collectUsedFacts() {
    used_.assign(p_.facts.size(), false);
    for (int a : plan_.actions) {
      used_[p_.actions[a].add] = true;
      for (const auto& line : p_.actions[a].code) markRefs(line.text);
    }
    for (const auto& v : varyings_)
      for (const auto& s : v.semantics) used_[p_.findFact(s)] = true;
  }

  void markRefs(const std::string& s) {
    for (size_t i = s.find(kFactRefBegin); i != std::string::npos; i = s.find(kFactRefBegin, i + 1))
      used_[refFact(s, i, p_.facts.size())] = true;
  }

  void declareInputs() {
    // Dense locations in rig order, only for attributes the plan reads.
    std::set<std::pair<int, int>> needed;  // (attribute, target)
    for (size_t f = 0; f < p_.facts.size(); ++f)
      if (used_[f] && p_.facts[f].source == Fact::Source::Attribute)
        needed.insert({p_.facts[f].rigIndex, p_.facts[f].target});
    int loc = 0;
    for (const auto& [attr, target] : needed) {
      const RigAttribute& a = rig_.attributes[attr];
      EmittedInput in;
      in.name = target >= 0 ? fmt::format("a_{}{}", a.name, target) : "a_" + a.name;
      in.location = loc++;
      in.attribute = attr;
      in.target = target;
      in.type = a.shaderType;
      out_.inputs.push_back(in);
    }
  }

  // Every local gets a name of its own (docs/design.md "Generated names"): the semantic it
  // holds, made unique against the interface (inputs, uniforms, buffers, outputs), the
  // template's names, every identifier the plan's snippets write and earlier locals, by a
  // suffix _2, _3, ... So no local hides an input or another local.
  void nameLocals() {
    std::set<std::string> taken{"main", std::string(kUniformBlockName)};
    for (const auto& in : out_.inputs) taken.insert(in.name);
    for (const auto& u : out_.uniforms) taken.insert(u.name);
    for (const auto& b : out_.buffers) {
      taken.insert({b.name, b.name + "_data", fmt::format("ShadergenBuffer{}", b.binding)});
    }
    for (const auto& o : out_.outputs) taken.insert(o.name);
    for (int a : plan_.actions)
      for (const auto& line : p_.actions[a].code) {
        const std::string& t = line.text;
        for (size_t i = 0; i < t.size();) {
          if (t[i] == kFactRefBegin) {  // a fact reference, named here
            const size_t e = t.find(kFactRefEnd, i);
            i = e == std::string::npos ? t.size() : e + 1;
          } else if (std::isalpha(static_cast<unsigned char>(t[i])) || t[i] == '_') {
            size_t e = i;
            while (e < t.size() && (std::isalnum(static_cast<unsigned char>(t[e])) || t[e] == '_')) ++e;
            taken.insert(t.substr(i, e - i));
            i = e;
          } else {
            ++i;
          }
        }
      }
    auto unique = [&](const std::string& base) {
      std::string name = base;
      for (int n = 2; taken.count(name); ++n) name = fmt::format("{}_{}", base, n);
      taken.insert(name);
      return name;
    };
    inputLocal_.assign(out_.inputs.size(), "");
    for (size_t i = 0; i < out_.inputs.size(); ++i)
      if (readInParts(out_.inputs[i]))
        inputLocal_[i] = unique(attributeLocalBase(rig_.attributes[out_.inputs[i].attribute], out_.inputs[i].target));
    local_.assign(p_.facts.size(), "");
    for (int a : plan_.actions) local_[p_.actions[a].add] = unique(localBase(p_.facts[p_.actions[a].add].name));
  }

  // An attribute read in parts (a_normal.xyz and a_normal.w) is loaded once into a local:
  // each part of an input variable would be a load of its own, and spirv-opt does not
  // rebuild vec4(a.xyz, a.w) into a.
  bool readInParts(const EmittedInput& in) const {
    for (size_t f = 0; f < p_.facts.size(); ++f)
      if (used_[f] && p_.facts[f].source == Fact::Source::Attribute && p_.facts[f].rigIndex == in.attribute &&
          p_.facts[f].target == in.target && !p_.facts[f].swizzle.empty())
        return true;
    return false;
  }

  void declareUniforms() {
    std::set<int> needed;
    for (size_t f = 0; f < p_.facts.size(); ++f)
      if (used_[f] && p_.facts[f].source == Fact::Source::Uniform) needed.insert(p_.facts[f].rigIndex);
    for (int u : needed) out_.uniforms.push_back(EmittedUniform{"u_" + rig_.uniforms[u].name, u});
  }

  void declareBuffers() {
    int binding = 1;
    for (size_t f = 0; f < p_.facts.size(); ++f) {
      if (!used_[f] || p_.facts[f].source != Fact::Source::Buffer) continue;
      const BufferSource& b = p_.buffers[p_.facts[f].rigIndex];
      EmittedBuffer e;
      e.name = "b_" + semanticIdentifier(p_.facts[f].name);
      e.semantic = p_.facts[f].name;
      e.binding = binding++;
      e.buffer = p_.facts[f].rigIndex;
      e.element = b.element;
      e.strideBytes = static_cast<uint32_t>(b.strideBytes);
      e.perVertex = b.kind == BufferSource::Kind::PerVertex;
      e.count = b.count;
      if (e.perVertex) {
        for (const auto& part : b.parts)
          e.packs.emplace_back(part.family + "[i]", std::string("xyzw").substr(static_cast<size_t>(part.firstComponent),
                                                                                static_cast<size_t>(part.components)));
      } else {
        e.packs.emplace_back(rig_.uniforms[b.uniform].semantic + "[i]", "mat4");
      }
      out_.buffers.push_back(e);
    }
  }

  // Each buffer: its block, and an accessor returning the semantic's type, so that
  // snippets read ${semantic}(i) whatever the layout.
  std::string bufferDeclarations() const {
    std::string s;
    for (const auto& e : out_.buffers) {
      const BufferSource& b = p_.buffers[e.buffer];
      const Fact& f = p_.facts[b.fact];
      std::string index = b.kind == BufferSource::Kind::PerVertex
                              ? fmt::format("uint(gl_VertexIndex) * {}u + uint(i)", b.count)
                              : std::string("uint(i)");
      int n = componentCount(f.type);
      std::string value;
      if (e.element == Type::Float) {  // tightly packed floats
        index = fmt::format("({}) * {}u", index, b.components);
        std::string parts;
        for (int c = 0; c < n; ++c) parts += fmt::format("{}{}_data[k + {}u]", c ? ", " : "", e.name, c);
        value = n == 1 ? parts : fmt::format("{}({})", glslName(f.type), parts);
      } else {
        std::string swizzle = f.type == e.element ? "" : "." + std::string("xyzw").substr(0, static_cast<size_t>(n));
        value = fmt::format("{}_data[k]{}", e.name, swizzle);
      }
      s += fmt::format(
          "layout(set = 0, binding = {}, std430) readonly buffer ShadergenBuffer{} {{\n  {} {}_data[];\n}};\n"
          "{} {}(int i) {{ uint k = {}; return {}; }}\n",
          e.binding, e.binding, glslName(e.element), e.name, glslName(f.type), e.name, index, value);
    }
    return s;
  }

  std::string declareOutputs() {
    uint32_t offset = 0;
    for (const auto& v : varyings_) {
      EmittedOutput o;
      o.name = v.name;
      o.location = v.location;
      o.type = v.type;
      o.arraySize = v.arraySize;
      o.semantics = v.semantics;
      o.captureOffset = offset;
      // Transform feedback captures matrices column after column and arrays element after
      // element, 4 bytes a component with no padding.
      offset += 4u * static_cast<uint32_t>(componentCount(v.type) * std::max(1, v.arraySize));
      out_.outputs.push_back(o);
    }
    out_.captureStride = offset;
    std::string text;
    if (opts_.capture)
      text += t_.fill("position_block", {{"stride", std::to_string(offset)}}) + "\n";
    for (const auto& o : out_.outputs) {
      if (o.location < 0) continue;
      std::string xfb = opts_.capture ? t_.fill("xfb", {{"offset", std::to_string(o.captureOffset)},
                                                         {"stride", std::to_string(offset)}})
                                      : "";
      const Varying* v = nullptr;
      for (const auto& x : varyings_)
        if (x.name == o.name) v = &x;
      text += t_.fill("output", {{"location", std::to_string(o.location)},
                                 {"xfb", xfb},
                                 {"qualifier", v && v->flat ? "flat " : ""},
                                 {"type", std::string(glslName(o.type))},
                                 {"name", o.arraySize ? fmt::format("{}[{}]", o.name, o.arraySize) : o.name}}) + "\n";
    }
    return text;
  }

  std::string factExpr(int f) const {
    const Fact& fact = p_.facts[f];
    switch (fact.source) {
      case Fact::Source::Computed:
        return local_[f];
      case Fact::Source::Uniform:
        return "u_" + rig_.uniforms[fact.rigIndex].name;
      case Fact::Source::Buffer:
        return "b_" + semanticIdentifier(fact.name);
      case Fact::Source::Attribute: {
        for (size_t i = 0; i < out_.inputs.size(); ++i) {
          const EmittedInput& in = out_.inputs[i];
          if (in.attribute != fact.rigIndex || in.target != fact.target) continue;
          const std::string& name = inputLocal_[i].empty() ? in.name : inputLocal_[i];
          return fact.swizzle.empty() ? name : name + "." + fact.swizzle;
        }
        return "?";
      }
    }
    return "?";
  }

  std::string resolve(const std::string& s) const {
    std::string out;
    size_t i = 0;
    while (i < s.size()) {
      size_t b = s.find(kFactRefBegin, i);
      if (b == std::string::npos) {
        out += s.substr(i);
        break;
      }
      size_t e = s.find(kFactRefEnd, b);
      out += s.substr(i, b - i);
      out += factExpr(refFact(s, b, p_.facts.size()));
      i = e + 1;
    }
    return out;
  }

  int sourceIndex(const std::string& file) {
    auto it = std::find(out_.sourceFiles.begin(), out_.sourceFiles.end(), file);
    if (it != out_.sourceFiles.end()) return static_cast<int>(it - out_.sourceFiles.begin()) + 1;
    out_.sourceFiles.push_back(file);
    return static_cast<int>(out_.sourceFiles.size());
  }

  std::string sourcesList() {
    // Register files in plan order so numbering is stable for the same inputs.
    for (int a : plan_.actions)
      for (const auto& l : p_.actions[a].code) sourceIndex(l.loc.file);
    std::string s = t_.fill("source", {{"index", "0"}, {"file", "this file"}});
    for (size_t i = 0; i < out_.sourceFiles.size(); ++i)
      s += "\n" + t_.fill("source", {{"index", std::to_string(i + 1)}, {"file", baseName(out_.sourceFiles[i])}});
    return s;
  }

  std::string body(int firstLine) {
    std::vector<std::string> lines;
    auto push = [&](const std::string& chunk) {
      size_t start = 0;
      for (;;) {
        size_t nl = chunk.find('\n', start);
        lines.push_back(chunk.substr(start, nl == std::string::npos ? std::string::npos : nl - start));
        if (nl == std::string::npos) break;
        start = nl + 1;
      }
    };
    // The attributes read in parts (readInParts), each loaded once.
    if (std::any_of(inputLocal_.begin(), inputLocal_.end(), [](const std::string& n) { return !n.empty(); }))
      push("  // Attributes read in parts, each loaded once.");
    for (size_t i = 0; i < out_.inputs.size(); ++i)
      if (!inputLocal_[i].empty())
        push(fmt::format("  {} {} = {};", glslName(out_.inputs[i].type), inputLocal_[i], out_.inputs[i].name));
    for (int a : plan_.actions) {
      const Action& act = p_.actions[a];
      const Fact& f = p_.facts[act.add];
      push(t_.fill("rule", {{"rule", act.name},
                            {"semantic", f.name},
                            {"cost", std::to_string(act.cost)},
                            {"type", std::string(glslName(f.type))},
                            {"name", local_[act.add]}}));
      std::vector<std::string> code;
      for (const auto& cl : act.code) code.push_back(resolve(cl.text));
      code = reindent(code);
      int expectLine = -1, expectSrc = -1;
      for (size_t k = 0; k < act.code.size(); ++k) {
        const CodeLine& cl = act.code[k];
        int src = sourceIndex(cl.loc.file);
        if (cl.loc.line != expectLine || src != expectSrc)
          push(t_.fill("line", {{"line", std::to_string(cl.loc.line)}, {"source", std::to_string(src)}}));
        push(code[k]);
        expectLine = cl.loc.line + 1;
        expectSrc = src;
      }
      if (!act.code.empty()) {
        // Back to this file's own numbering: the line after the directive.
        int next = firstLine + static_cast<int>(lines.size()) + 1;
        push(t_.fill("line", {{"line", std::to_string(next)}, {"source", "0"}}));
      }
    }
    std::string out;
    for (size_t i = 0; i < lines.size(); ++i) out += (i ? "\n" : "") + lines[i];
    return out;
  }

  const Rig& rig_;
  const Problem& p_;
  const Plan& plan_;
  const std::vector<Varying>& varyings_;
  const TemplateSet& t_;
  EmitOptions opts_;
  std::vector<bool> used_;
  std::vector<std::string> local_;       // per fact: the local a computed fact is held in
  std::vector<std::string> inputLocal_;  // per input: the local it is loaded into ("" = read directly)
  EmittedGlsl out_;
};

}  // namespace

EmittedGlsl emitGlsl(const Rig& rig, const Problem& p, const Plan& plan, const std::vector<Varying>& varyings,
                     const TemplateSet& templates, const std::string& fragmentName, const EmitOptions& opts) {
  return Emitter(rig, p, plan, varyings, templates, opts).run(fragmentName);
}

}  // namespace sg
