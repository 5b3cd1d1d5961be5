#include "interface/fragment_interface.h"

#include <fmt/format.h>

#include <algorithm>
#include <regex>

#include "common/glsl_compile.h"
#include "common/yaml_util.h"
#include "rules/rules.h"

namespace sg {
namespace {

// Where `name` is declared as an input: glslang's reflection carries no source location.
SourceLoc findDeclaration(const std::string& source, const std::string& file, const std::string& name) {
  std::regex decl("\\bin\\b[^;{}]*\\b" + name + "\\s*;");
  int line = 1;
  size_t start = 0;
  while (start <= source.size()) {
    size_t end = source.find('\n', start);
    std::string l = source.substr(start, end == std::string::npos ? std::string::npos : end - start);
    std::smatch m;
    if (std::regex_search(l, m, decl)) {
      size_t col = l.find(name, static_cast<size_t>(m.position(0)));
      return SourceLoc{file, line, static_cast<int>(col) + 1};
    }
    if (end == std::string::npos) break;
    start = end + 1;
    ++line;
  }
  return SourceLoc{file, 0, 0};
}

// The declared semantic whose name, with '.' written as '_', is the input's name
// (world_eye_dir -> world.eye_dir; '_' inside a semantic name stays '_').
const SemanticDecl* semanticNamed(const RuleSet& rules, const std::string& inputName) {
  for (const auto& d : rules.semantics) {
    std::string s = d.name;
    std::replace(s.begin(), s.end(), '.', '_');
    if (s == inputName) return &d;
  }
  return nullptr;
}

}  // namespace

FragmentInterface reflectFragmentFile(const std::string& path, TargetEnv env) {
  return reflectFragmentSource(readInputFile(path), path, env);
}

FragmentInterface reflectFragmentSource(const std::string& source, const std::string& fileName, TargetEnv env) {
  FragmentInterface fi;
  fi.file = fileName;
  fi.source = source;
  GlslShader shader(GlslUnit{Stage::Fragment, source, fileName, {}}, env);
  if (!shader.ok()) throwDiagnostics(shader.diagnostics(), fileName, "the fragment shader does not compile");
  for (const StageVariable& r : shader.inputs()) {
    if (r.name.rfind("gl_", 0) == 0) continue;  // gl_FragCoord etc. are not vertex outputs
    FragmentInput in;
    in.name = r.name;
    in.loc = findDeclaration(source, fileName, r.name);
    if (r.block)
      throw InputError(in.loc, fmt::format("fragment input '{}' is in an interface block; declare plain 'in' variables", r.name));
    if (!r.type || isMatrix(*r.type))
      throw InputError(in.loc, fmt::format("fragment input '{}' has type '{}'; only scalars and vectors are supported",
                                           r.name, r.typeText));
    in.type = *r.type;
    if (r.location < 0)
      throw InputError(in.loc, fmt::format("fragment input '{}' has no layout(location = N)", r.name));
    in.location = r.location;
    in.flat = r.flat;
    fi.inputs.push_back(std::move(in));
  }
  std::sort(fi.inputs.begin(), fi.inputs.end(),
            [](const FragmentInput& a, const FragmentInput& b) { return a.location < b.location; });
  for (size_t i = 1; i < fi.inputs.size(); ++i)
    if (fi.inputs[i].location == fi.inputs[i - 1].location)
      throw InputError(fi.inputs[i].loc, fmt::format("fragment inputs '{}' and '{}' share location {}",
                                                     fi.inputs[i - 1].name, fi.inputs[i].name, fi.inputs[i].location));
  return fi;
}

std::vector<Varying> bindVaryings(const FragmentInterface& frag, const RuleSet& rules,
                                  const std::vector<VaryingOverride>& overrides) {
  std::vector<Varying> out;
  Varying pos;
  pos.name = "gl_Position";
  pos.type = Type::Vec4;
  pos.semantics = {"clip.position"};
  pos.loc = SourceLoc{frag.file, 0, 0};
  out.push_back(pos);

  for (const auto& in : frag.inputs) {
    Varying v;
    v.name = in.name;
    v.type = in.type;
    v.location = in.location;
    v.flat = in.flat;
    v.loc = in.loc;
    SourceLoc mapLoc = in.loc;
    std::string how;
    auto ov = std::find_if(overrides.begin(), overrides.end(), [&](const VaryingOverride& o) { return o.name == in.name; });
    if (ov != overrides.end()) {
      v.semantics = ov->semantics;
      how = "the --map option";
    } else if (const VaryingMapping* m = rules.findVarying(in.name)) {
      v.semantics = m->semantics;
      mapLoc = m->loc;
      how = fmt::format("the mapping at {}:{}", m->loc.file, m->loc.line);
    } else if (const SemanticDecl* d = semanticNamed(rules, in.name)) {
      v.semantics = {d->name};
      how = "its name";
    } else {
      throw InputError(in.loc, fmt::format("fragment input '{}' does not name a semantic; map it in the rules' "
                                           "'varyings:' or with --map {}=<semantic>",
                                           in.name, in.name));
    }
    int comps = 0;
    for (const auto& s : v.semantics) {
      const SemanticDecl* d = rules.findSemantic(s);
      if (!d) throw InputError(mapLoc, fmt::format("fragment input '{}' maps to unknown semantic '{}' (via {})", in.name, s, how));
      if (isMatrix(d->type) || d->arraySize || !d->arrayParam.empty())
        throw InputError(mapLoc, fmt::format("semantic '{}' ({}) cannot be passed as a varying", s, glslName(d->type)));
      if (scalarKind(d->type) != scalarKind(in.type))
        throw InputError(in.loc, fmt::format("fragment input '{}' is {} but semantic '{}' is {}", in.name,
                                             glslName(in.type), s, glslName(d->type)));
      comps += componentCount(d->type);
    }
    if (comps != componentCount(in.type)) {
      if (v.semantics.size() == 1)
        throw InputError(in.loc, fmt::format("fragment input '{}' is {} but semantic '{}' is {}", in.name,
                                             glslName(in.type), v.semantics[0],
                                             glslName(rules.findSemantic(v.semantics[0])->type)));
      throw InputError(in.loc, fmt::format("fragment input '{}' is {} ({} components) but its packed semantics have {} "
                                           "components (via {})",
                                           in.name, glslName(in.type), componentCount(in.type), comps, how));
    }
    if (scalarKind(in.type) != ScalarKind::Float && !in.flat)
      throw InputError(in.loc, fmt::format("integer fragment input '{}' must be 'flat'", in.name));
    out.push_back(std::move(v));
  }
  return out;
}

}  // namespace sg
