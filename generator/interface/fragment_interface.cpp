#include "interface/fragment_interface.h"

#include <fmt/format.h>

#include <algorithm>
#include <string_view>

#include "common/glsl_compile.h"
#include "common/yaml_util.h"
#include "interface/suggest.h"
#include "rules/rules.h"

namespace sg {
namespace {

// Where `name` is declared as an input: glslang's reflection carries no source location.
// A linear scan over tokens (comments and preprocessor lines skipped): the statement
// that contains the word `in` and whose last identifier is `name`. No regex: a long
// line must cost linear time and constant stack.
SourceLoc findDeclaration(const std::string& src, const std::string& file, const std::string& name) {
  auto isIdStart = [](char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; };
  auto isId = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  int line = 1;
  size_t lineStart = 0;
  bool sawIn = false;
  SourceLoc last{file, 0, 0};
  std::string lastName;
  bool atLineStart = true;
  for (size_t i = 0; i < src.size();) {
    char c = src[i];
    if (c == '\n') {
      ++line;
      lineStart = ++i;
      atLineStart = true;
      continue;
    }
    if (c == '/' && i + 1 < src.size() && src[i + 1] == '/') {
      while (i < src.size() && src[i] != '\n') ++i;
      continue;
    }
    if (c == '/' && i + 1 < src.size() && src[i + 1] == '*') {
      size_t end = src.find("*/", i + 2);
      end = end == std::string::npos ? src.size() : end + 2;
      for (; i < end; ++i)
        if (src[i] == '\n') {
          ++line;
          lineStart = i + 1;
        }
      continue;
    }
    if (c == '#' && atLineStart) {  // preprocessor line (continuations are rare here)
      while (i < src.size() && src[i] != '\n') ++i;
      continue;
    }
    if (std::isspace(static_cast<unsigned char>(c))) {
      ++i;
      continue;
    }
    atLineStart = false;
    if (isIdStart(c)) {
      size_t b = i;
      while (i < src.size() && isId(src[i])) ++i;
      std::string_view word(src.data() + b, i - b);
      if (word == "in") sawIn = true;
      lastName.assign(word);
      last = SourceLoc{file, line, static_cast<int>(b - lineStart) + 1};
      continue;
    }
    // `in T name;`, or the block name of `in Block { ... } instance;`
    if ((c == ';' || c == '{') && sawIn && lastName == name) return last;
    if (c == ';' || c == '{' || c == '}') {
      sawIn = false;
      lastName.clear();
    }
    ++i;
  }
  return SourceLoc{file, 0, 0};
}

// The declared semantic the input's name spells in this project's own style: '.' as '_'
// (world_eye_dir), or camelCase / PascalCase words (worldEyeDir, WorldEyeDir).
const SemanticDecl* semanticNamed(const RuleSet& rules, const std::string& inputName) {
  for (const auto& d : rules.semantics) {
    std::string snake = d.name;
    std::replace(snake.begin(), snake.end(), '.', '_');
    if (snake == inputName) return &d;
    std::string camel;
    bool up = false;
    for (char c : d.name) {
      if (c == '.' || c == '_') {
        up = true;
        continue;
      }
      camel += up ? static_cast<char>(std::toupper(static_cast<unsigned char>(c))) : c;
      up = false;
    }
    if (camel == inputName) return &d;
    camel[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(camel[0])));
    if (camel == inputName) return &d;
  }
  return nullptr;
}

// glslang gives lines only; its messages start with the offending token in quotes
// ("'foo' : undeclared identifier"): point the column at that token on the line.
void addColumn(Diagnostic& d, const std::string& source) {
  if (d.loc.line <= 0 || d.loc.col > 0 || d.message.size() < 3 || d.message[0] != '\'') return;
  size_t close = d.message.find('\'', 1);
  if (close == std::string::npos || close == 1) return;
  std::string token = d.message.substr(1, close - 1);
  size_t start = 0;
  for (int l = 1; l < d.loc.line; ++l) {
    start = source.find('\n', start);
    if (start == std::string::npos) return;
    ++start;
  }
  size_t end = source.find('\n', start);
  std::string_view line(source.data() + start, (end == std::string::npos ? source.size() : end) - start);
  size_t at = line.find(token);
  if (at != std::string_view::npos) d.loc.col = static_cast<int>(at) + 1;
}

}  // namespace

const char* reservedNameUse(const std::string& name) {
  if (name.rfind("a_", 0) == 0) return "starts with 'a_', the prefix of the generated vertex attributes";
  if (name.rfind("u_", 0) == 0) return "starts with 'u_', the prefix of the generated uniforms";
  if (name == kUniformBlockName) return "is the name of the generated uniform block";
  return nullptr;
}

FragmentInterface reflectFragmentFile(const std::string& path, TargetEnv env) {
  return reflectFragmentSource(readInputFile(path), path, env);
}

FragmentInterface reflectFragmentSource(const std::string& source, const std::string& fileName, TargetEnv env) {
  FragmentInterface fi;
  fi.file = fileName;
  fi.source = source;
  GlslShader shader(GlslUnit{Stage::Fragment, source, fileName, {}}, env);
  if (!shader.ok()) {
    std::vector<Diagnostic> diags = shader.diagnostics();
    for (auto& d : diags) addColumn(d, source);
    throwDiagnostics(std::move(diags), fileName, "the fragment shader does not compile");
  }
  for (const StageVariable& r : shader.inputs()) {
    if (r.name.rfind("gl_", 0) == 0) continue;  // gl_FragCoord etc. are not vertex outputs
    FragmentInput in;
    in.name = r.name;
    if (r.block)  // located at `in Block {`
      throw InputError(findDeclaration(source, fileName, r.blockName),
                       fmt::format("fragment input block '{}' ('{}'): interface blocks are not supported as inputs (the "
                                   "generated vertex shader writes, and validation captures, plain outputs); declare "
                                   "each member as a plain 'in' variable with layout(location = N) (matrices and "
                                   "arrays are supported)",
                                   r.blockName, r.name));
    in.loc = findDeclaration(source, fileName, r.name);
    if (!r.type)
      throw InputError(in.loc, fmt::format("fragment input '{}' has type '{}'; supported: scalars, vectors, mat3, mat4 "
                                           "and 1-D arrays of them",
                                           r.name, r.typeText));
    in.type = *r.type;
    in.arraySize = r.arraySize;
    if (r.location < 0)
      throw InputError(in.loc, fmt::format("fragment input '{}' has no layout(location = N)", r.name));
    // One input per location: the emitter writes whole locations, and a list of semantics
    // packs several values into one input instead (docs/rules-format.md, "Varyings").
    if (r.component >= 0)
      throw InputError(in.loc, fmt::format("fragment input '{}' uses layout(component = {}): inputs sharing a location "
                                           "are not supported; give it a location of its own, or declare one vector "
                                           "and map it to a list of semantics (--map NAME=sem,sem)",
                                           r.name, r.component));
    in.location = r.location;
    in.flat = r.flat;
    fi.inputs.push_back(std::move(in));
  }
  std::sort(fi.inputs.begin(), fi.inputs.end(),
            [](const FragmentInput& a, const FragmentInput& b) { return a.location < b.location; });
  for (size_t i = 1; i < fi.inputs.size(); ++i) {
    const FragmentInput& a = fi.inputs[i - 1];
    const FragmentInput& b = fi.inputs[i];
    int aEnd = a.location + locationCount(a.type, a.arraySize);
    if (b.location == a.location)
      throw InputError(b.loc, fmt::format("fragment inputs '{}' and '{}' share location {}", a.name, b.name, b.location));
    if (b.location < aEnd)  // a mat3 takes three locations, an array one per element (per column)
      throw InputError(b.loc, fmt::format("fragment input '{}' at location {} overlaps '{}' ({}{} takes locations {}..{})",
                                          b.name, b.location, a.name, glslName(a.type),
                                          a.arraySize ? fmt::format("[{}]", a.arraySize) : "", a.location, aEnd - 1));
  }
  return fi;
}

int locationCount(Type type, int arraySize) {
  int columns = type == Type::Mat3 ? 3 : type == Type::Mat4 ? 4 : 1;
  return columns * std::max(1, arraySize);
}

namespace {

std::string typeText(Type t, int arraySize) {
  return arraySize ? fmt::format("{}[{}]", glslName(t), arraySize) : std::string(glslName(t));
}

// "did you mean ...?" for an input no mapping names, with what the conventions say.
std::string unmappedMessage(const FragmentInput& in, const RuleSet& rules, const ConventionMatch& conv) {
  std::string msg = fmt::format("fragment input '{}' does not name a semantic; map it in the rules' 'varyings:' or "
                                "with --map {}=<semantic>",
                                in.name, in.name);
  std::vector<std::string> close = closestSemantics(rules, in.name, in.type);
  if (!close.empty()) {
    std::string list;
    for (size_t i = 0; i < close.size(); ++i) {
      const SemanticDecl* d = rules.findSemantic(close[i]);
      list += fmt::format("{}{} ({})", i == 0 ? "" : i + 1 == close.size() ? " or " : ", ", close[i], glslName(d->type));
    }
    msg += fmt::format("; did you mean {}?", list);
  }
  for (const auto& n : conv.notes) msg += "; " + n;
  return msg;
}

// One input's mapping and its checks. Throws InputError.
Varying bindOne(const FragmentInput& in, const RuleSet& rules, const std::vector<VaryingOverride>& overrides,
                const std::vector<std::string>& conventions) {
  if (const char* why = reservedNameUse(in.name))
    throw InputError(in.loc, fmt::format("fragment input '{}' {}; rename it", in.name, why));
  Varying v;
  v.name = in.name;
  v.type = in.type;
  v.arraySize = in.arraySize;
  v.location = in.location;
  v.flat = in.flat;
  v.loc = in.loc;
  SourceLoc mapLoc = in.loc;
  std::string how;
  auto ov = std::find_if(overrides.begin(), overrides.end(), [&](const VaryingOverride& o) { return o.name == in.name; });
  if (ov != overrides.end()) {
    v.semantics = ov->semantics;
    how = "the --map option";
    v.via = "--map";
  } else if (const VaryingMapping* m = rules.findVarying(in.name)) {
    v.semantics = m->semantics;
    mapLoc = m->loc;
    how = fmt::format("the mapping at {}:{}", m->loc.file, m->loc.line);
    v.via = fmt::format("varyings: at {}:{}", m->loc.file, m->loc.line);
  } else if (const SemanticDecl* d = in.arraySize ? nullptr : semanticNamed(rules, in.name)) {
    v.semantics = {d->name};
    how = "its name";
    v.via = "its name";
  } else {
    ConventionMatch conv = matchConvention(rules, in.name, in.type, in.arraySize, conventions);
    if (conv.semantics.empty()) throw InputError(in.loc, unmappedMessage(in, rules, conv));
    v.semantics = conv.semantics;
    mapLoc = conv.loc;
    how = fmt::format("naming convention '{}' at {}:{}", conv.convention, conv.loc.file, conv.loc.line);
    v.via = fmt::format("naming convention '{}'", conv.convention);
  }
  int comps = 0;
  for (const auto& s : v.semantics) {
    const SemanticDecl* d = rules.findSemantic(s);
    if (!d) throw InputError(mapLoc, fmt::format("fragment input '{}' maps to unknown semantic '{}' (via {})", in.name, s, how));
    if (isMatrix(d->type) || d->arraySize || !d->arrayParam.empty())
      throw InputError(mapLoc, fmt::format("semantic '{}' ({}) cannot be passed as a varying", s, glslName(d->type)));
    if (scalarKind(d->type) != scalarKind(in.type))
      throw InputError(in.loc, fmt::format("fragment input '{}' is {} but semantic '{}' is {}", in.name,
                                           typeText(in.type, in.arraySize), s, glslName(d->type)));
    if (in.arraySize && componentCount(d->type) != componentCount(in.type))
      throw InputError(in.loc, fmt::format("fragment input '{}' is {}: each element takes one {} semantic, but '{}' is {}",
                                           in.name, typeText(in.type, in.arraySize), glslName(in.type), s,
                                           glslName(d->type)));
    comps += componentCount(d->type);
  }
  if (in.arraySize) {
    if (static_cast<int>(v.semantics.size()) != in.arraySize)
      throw InputError(in.loc, fmt::format("fragment input '{}' is {}: map it to {} semantics, one per element (got {}, "
                                           "via {})",
                                           in.name, typeText(in.type, in.arraySize), in.arraySize, v.semantics.size(), how));
  } else if (comps != componentCount(in.type)) {
    if (v.semantics.size() == 1)
      throw InputError(in.loc, fmt::format("fragment input '{}' is {} but semantic '{}' is {}", in.name,
                                           glslName(in.type), v.semantics[0],
                                           glslName(rules.findSemantic(v.semantics[0])->type)));
    throw InputError(in.loc, fmt::format("fragment input '{}' is {} ({} components{}) but its packed semantics have {} "
                                         "components (via {})",
                                         in.name, glslName(in.type), componentCount(in.type),
                                         isMatrix(in.type) ? ", filled column by column" : "", comps, how));
  }
  if (scalarKind(in.type) != ScalarKind::Float && !in.flat)
    throw InputError(in.loc, fmt::format("integer fragment input '{}' must be 'flat'", in.name));
  return v;
}

}  // namespace

VaryingBinding bindVaryingsCollect(const FragmentInterface& frag, const RuleSet& rules,
                                   const std::vector<VaryingOverride>& overrides,
                                   const std::vector<std::string>& conventions) {
  checkConventionNames(rules, conventions);
  for (const auto& o : overrides) {
    bool found = std::any_of(frag.inputs.begin(), frag.inputs.end(), [&](const FragmentInput& in) { return in.name == o.name; });
    if (!found) {
      std::string names;
      for (const auto& in : frag.inputs) names += (names.empty() ? "" : ", ") + in.name;
      throw InputError(SourceLoc{frag.file, 0, 0},
                       fmt::format("--map {}=...: the fragment shader has no input '{}' (its inputs: {})", o.name,
                                   o.name, names.empty() ? "none" : names));
    }
  }
  VaryingBinding out;
  Varying pos;
  pos.name = "gl_Position";
  pos.type = Type::Vec4;
  pos.semantics = {"clip.position"};
  pos.loc = SourceLoc{frag.file, 0, 0};
  out.varyings.push_back(pos);
  for (const auto& in : frag.inputs) {
    try {
      out.varyings.push_back(bindOne(in, rules, overrides, conventions));
    } catch (const InputError& e) {
      out.errors.push_back(e.diagnostic());
    }
  }
  return out;
}

std::vector<Varying> bindVaryings(const FragmentInterface& frag, const RuleSet& rules,
                                  const std::vector<VaryingOverride>& overrides,
                                  const std::vector<std::string>& conventions) {
  VaryingBinding b = bindVaryingsCollect(frag, rules, overrides, conventions);
  if (!b.errors.empty()) {
    InputError e(b.errors[0]);
    e.related.assign(b.errors.begin() + 1, b.errors.end());
    throw e;
  }
  return std::move(b.varyings);
}

}  // namespace sg
