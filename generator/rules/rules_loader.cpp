// Loads rules YAML (format: docs/rules-format.md) with located diagnostics.
#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <set>
#include <sstream>

#include "common/yaml_util.h"
#include "rules/instantiate.h"
#include "rules/loader_parts.h"
#include "rules/rules.h"

namespace sg {
namespace {

std::vector<std::string> splitLines(const std::string& text) {
  std::vector<std::string> lines;
  std::string cur;
  for (char c : text) {
    if (c == '\n') {
      if (!cur.empty() && cur.back() == '\r') cur.pop_back();
      lines.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  lines.push_back(cur);
  return lines;
}

bool validSemanticName(const std::string& s) {
  if (s.empty() || !std::isalpha(static_cast<unsigned char>(s[0]))) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.')) return false;
  return s.back() != '.';
}

bool validRuleName(const std::string& s) {
  if (s.empty()) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) return false;
  return true;
}

SourceLoc exprLoc(const YAML::Node& n, const std::string& file) {
  SourceLoc l = locOf(n, file);
  // Quoted scalars start one column after the mark.
  if (n.Tag() == "!" && l.col > 0) l.col += 1;
  return l;
}

SemanticRef parseRef(const YamlCtx& y, const YAML::Node& n) {
  std::string s = y.scalar(n, "a semantic reference");
  SemanticRef r;
  r.loc = locOf(n, y.file);
  auto lb = s.find('[');
  if (lb != std::string::npos) {
    if (s.back() != ']') y.fail(n, fmt::format("malformed semantic reference '{}' (missing ']')", s));
    r.index = s.substr(lb + 1, s.size() - lb - 2);
    if (r.index.empty()) y.fail(n, fmt::format("empty index in '{}'", s));
    s = s.substr(0, lb);
  }
  if (!validSemanticName(s)) y.fail(n, fmt::format("'{}' is not a valid semantic name", s));
  r.name = s;
  return r;
}

double finiteNumber(const YamlCtx& y, const YAML::Node& n, const char* what) {
  std::string s = y.scalar(n, what);
  char* end = nullptr;
  double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size() || !std::isfinite(v)) y.fail(n, fmt::format("{} must be a finite number, got '{}'", what, s));
  return v;
}

// The `definition:`, `kind:` and `range:` keys of a semantic (rules/definition.h).
void loadSemanticDefinition(SemanticDecl& d, const YamlCtx& y, const YAML::Node& body, const std::vector<std::string>& raw) {
  if (body["definition"]) {
    d.definitionText = y.scalar(body["definition"], "'definition'");
    SourceLoc at = exprLoc(body["definition"], y.file);
    SourceLoc mark = locOf(body["definition"], y.file);
    // A block scalar ('>' or '|'): map each source line's text to its place in the value.
    std::vector<std::pair<size_t, SourceLoc>> segments{{0, at}};
    if (mark.line > 0 && mark.line <= static_cast<int>(raw.size()) && mark.col > 0 &&
        raw[mark.line - 1].size() >= static_cast<size_t>(mark.col) &&
        (raw[mark.line - 1][mark.col - 1] == '>' || raw[mark.line - 1][mark.col - 1] == '|')) {
      segments.clear();
      size_t off = 0;
      for (size_t l = static_cast<size_t>(at.line); l < raw.size() && off < d.definitionText.size(); ++l) {
        size_t first = raw[l].find_first_not_of(' ');
        if (first == std::string::npos) continue;
        std::string content = raw[l].substr(first);
        if (d.definitionText.compare(off, content.size(), content) != 0) break;
        segments.push_back({off, SourceLoc{y.file, static_cast<int>(l) + 1, static_cast<int>(first) + 1}});
        off += content.size() + 1;
      }
      if (segments.empty()) segments.push_back({0, SourceLoc{y.file, at.line + 1, 0}});
    }
    d.definition = parseDefinition(d.definitionText, segments);
  }
  if (body["kind"]) {
    d.kind = y.scalar(body["kind"], "'kind'");
    d.kindLoc = locOf(body["kind"], y.file);
    static const std::set<std::string> kinds = {"rigid", "affine", "projection", "unit", "point", "weight", "int"};
    if (!kinds.count(d.kind))
      y.fail(body["kind"], fmt::format("unknown kind '{}' (rigid, affine, projection, unit, point, weight, int)", d.kind));
  }
  if (body["range"]) {
    YAML::Node r = body["range"];
    y.expectSeq(r, "'range' ([low, high])");
    if (r.size() != 2) y.fail(r, "'range' is [low, high]");
    d.rangeLo = finiteNumber(y, r[0], "the low end of 'range'");
    d.rangeHi = finiteNumber(y, r[1], "the high end of 'range'");
    if (!(d.rangeLo <= d.rangeHi)) y.fail(r, "'range' is [low, high] with low <= high");
  }
}

void loadSemantics(RuleSet& set, const YamlCtx& y, const YAML::Node& sems, const std::vector<std::string>& raw) {
  y.expectMap(sems, "'semantics'");
  for (auto it = sems.begin(); it != sems.end(); ++it) {
    if (set.semantics.size() >= kMaxSemantics) y.fail(it->first, fmt::format("more than {} semantics", kMaxSemantics));
    SemanticDecl d;
    d.name = y.scalar(it->first, "a semantic name");
    d.loc = locOf(it->first, y.file);
    if (!validSemanticName(d.name)) y.fail(it->first, fmt::format("'{}' is not a valid semantic name", d.name));
    if (const SemanticDecl* prev = set.findSemantic(d.name)) {
      if (prev->loc.file == d.loc.file && prev->loc.line == d.loc.line) continue;  // same file included twice
      y.fail(it->first, fmt::format("semantic '{}' is declared twice (first at {}:{})", d.name, prev->loc.file,
                                    prev->loc.line));
    }
    YAML::Node body = it->second;  // a copy: it->second lives in a temporary proxy
    std::string typeName;
    if (body.IsScalar()) {
      typeName = body.Scalar();
    } else {
      y.expectMap(body, "a semantic declaration");
      y.checkKeys(body, {"type", "count", "array", "doc", "definition", "kind", "range", "buffer_of", "bound"});
      if (!body["type"]) y.fail(body, fmt::format("semantic '{}' has no 'type'", d.name));
      typeName = y.scalar(body["type"], "'type'");
      if (body["count"]) d.count = Expr::parse(y.scalar(body["count"], "'count'"), exprLoc(body["count"], y.file));
      if (body["array"]) d.arrayParam = y.scalar(body["array"], "'array'");
      if (body["bound"]) d.bound = Expr::parse(y.scalar(body["bound"], "'bound'"), exprLoc(body["bound"], y.file));
      if (body["doc"]) d.doc = y.scalar(body["doc"], "'doc'");
      if (YAML::Node b = body["buffer_of"]) {
        if (b.IsScalar()) d.bufferOf.push_back(b.Scalar());
        else {
          y.expectSeq(b, "'buffer_of'");
          for (const auto& e : b) d.bufferOf.push_back(y.scalar(e, "a semantic in 'buffer_of'"));
        }
        if (d.bufferOf.empty()) y.fail(b, fmt::format("semantic '{}': 'buffer_of' lists no semantic", d.name));
      }
      loadSemanticDefinition(d, y, body, raw);
    }
    auto t = parseType(typeName);
    if (!t) y.fail(body.IsMap() ? body["type"] : body, fmt::format("unknown type '{}' for semantic '{}'", typeName, d.name));
    d.type = *t;
    if (!d.bound.empty() && (scalarKind(d.type) == ScalarKind::Float || componentCount(d.type) != 1 || !d.arrayParam.empty()))
      y.fail(body["bound"], fmt::format("semantic '{}': 'bound' is for a count (a uint or int scalar), not a {}{}", d.name,
                                        glslName(d.type), d.arrayParam.empty() ? "" : " array"));
    set.semantics.push_back(std::move(d));
  }
}

void loadVaryings(RuleSet& set, const YamlCtx& y, const YAML::Node& vars) {
  y.expectMap(vars, "'varyings'");
  for (auto it = vars.begin(); it != vars.end(); ++it) {
    VaryingMapping v;
    v.name = y.scalar(it->first, "a varying name");
    v.loc = locOf(it->first, y.file);
    if (set.findVarying(v.name)) y.fail(it->first, fmt::format("varying '{}' is mapped twice", v.name));
    if (it->second.IsScalar()) {
      v.semantics.push_back(it->second.Scalar());
    } else {
      y.expectSeq(it->second, "a varying mapping");
      YAML::Node list = it->second;  // a copy: it->second lives in a temporary proxy
      for (const auto& s : list) v.semantics.push_back(y.scalar(s, "a semantic name"));
      if (v.semantics.empty()) y.fail(it->second, fmt::format("varying '{}' maps to no semantic", v.name));
    }
    set.varyings.push_back(std::move(v));
  }
}

std::vector<TemplateLine> snippetLines(const YamlCtx& y, const YAML::Node& n, const std::vector<std::string>& raw) {
  std::string text = y.scalar(n, "'glsl'");
  SourceLoc at = locOf(n, y.file);
  std::vector<std::string> lines = splitLines(text);
  while (!lines.empty() && lines.back().empty()) lines.pop_back();
  std::vector<TemplateLine> out;
  // Block scalars ('|') start on the line after the indicator; others on the mark.
  bool block = at.line > 0 && at.line <= static_cast<int>(raw.size()) && at.col > 0 &&
               raw[at.line - 1].size() >= static_cast<size_t>(at.col) &&
               (raw[at.line - 1][at.col - 1] == '|' || raw[at.line - 1][at.col - 1] == '>');
  for (size_t i = 0; i < lines.size(); ++i) {
    TemplateLine tl;
    tl.text = lines[i];
    tl.loc = at;
    if (block) {
      tl.loc.line = at.line + 1 + static_cast<int>(i);
      const std::string& r = tl.loc.line <= static_cast<int>(raw.size()) ? raw[tl.loc.line - 1] : std::string();
      size_t pos = (!tl.text.empty() && r.size() >= tl.text.size() && r.compare(r.size() - tl.text.size(), tl.text.size(), tl.text) == 0)
                       ? r.size() - tl.text.size()
                       : r.find_first_not_of(' ');
      tl.loc.col = static_cast<int>(pos == std::string::npos ? 0 : pos) + 1;
    } else if (n.Tag() == "!") {
      tl.loc.col += 1;  // quoted
    }
    // Control bytes have no place in GLSL, and \x01/\x02 mark fact references inside
    // the generator (search/problem.h): refuse them where they are written.
    for (size_t c = 0; c < tl.text.size(); ++c) {
      auto u = static_cast<unsigned char>(tl.text[c]);
      if ((u < 0x20 && u != '\t') || u == 0x7f) {
        SourceLoc bad = tl.loc;
        if (block && bad.col > 0) bad.col += static_cast<int>(c);
        throw InputError(bad, fmt::format("control character 0x{:02x} in a GLSL snippet", u));
      }
    }
    // A directive is not local to its snippet: pasted into main(), '#define' or '#if' would
    // apply to every later snippet and the template.
    size_t hash = tl.text.find_first_not_of(" \t");
    if (hash != std::string::npos && tl.text[hash] == '#') {
      size_t end = tl.text.find_first_not_of("abcdefghijklmnopqrstuvwxyz", tl.text.find_first_not_of(" \t", hash + 1));
      std::string word = tl.text.substr(hash, std::min(end, tl.text.size()) - hash);
      SourceLoc bad = tl.loc;
      if (block && bad.col > 0) bad.col += static_cast<int>(hash);
      throw InputError(bad, fmt::format("preprocessor directive '{}' in a GLSL snippet: snippets are pasted into one "
                                        "function, so it would apply to every later snippet; use '@if' / '@for' "
                                        "(docs/rules-format.md) or a constant",
                                        word));
    }
    out.push_back(std::move(tl));
  }
  return out;
}

bool validSnippetName(const std::string& s) {
  if (s.empty() || std::isdigit(static_cast<unsigned char>(s[0]))) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return false;
  return true;
}

// `@use NAME(ARG, ...)` parsed: the name, where it is, and the arguments' text (split at
// top-level commas; brackets and ${...} nest).
struct UseDirective {
  std::string name;
  SourceLoc nameLoc;
  std::vector<std::string> args;
};
std::optional<UseDirective> parseUse(const TemplateLine& line) {
  const std::string& t = line.text;
  size_t at = t.find_first_not_of(" \t");
  if (at == std::string::npos || t.compare(at, 4, "@use") != 0 ||
      (at + 4 < t.size() && t[at + 4] != ' ' && t[at + 4] != '\t'))
    return std::nullopt;
  auto locAt = [&](size_t col) { return SourceLoc{line.loc.file, line.loc.line, line.loc.col + static_cast<int>(col)}; };
  auto bad = [&](size_t col) -> InputError {
    return InputError(locAt(col), "malformed @use: write '@use NAME(ARG, ...)' (one shared snippet per line)");
  };
  UseDirective u;
  size_t p = t.find_first_not_of(" \t", at + 4);
  if (p == std::string::npos) throw bad(at);
  size_t e = p;
  while (e < t.size() && (std::isalnum(static_cast<unsigned char>(t[e])) || t[e] == '_')) ++e;
  u.name = t.substr(p, e - p);
  u.nameLoc = locAt(p);
  if (u.name.empty()) throw bad(p);
  e = t.find_first_not_of(" \t", e);
  if (e == std::string::npos || t[e] != '(') throw bad(e == std::string::npos ? t.size() : e);
  int depth = 0;
  std::string cur;
  size_t i = e + 1;
  for (; i < t.size(); ++i) {
    char c = t[i];
    if (depth == 0 && (c == ',' || c == ')')) {
      size_t b = cur.find_first_not_of(" \t"), f = cur.find_last_not_of(" \t");
      std::string arg = b == std::string::npos ? "" : cur.substr(b, f - b + 1);
      if (arg.empty() && !(c == ')' && u.args.empty())) throw InputError(locAt(i), "@use: an empty argument");
      if (!arg.empty()) u.args.push_back(arg);
      cur.clear();
      if (c == ')') break;
      continue;
    }
    if (c == '(' || c == '[' || c == '{') ++depth;
    if (c == ')' || c == ']' || c == '}') --depth;
    cur += c;
  }
  if (i >= t.size() || t.find_first_not_of(" \t", i + 1) != std::string::npos) throw bad(std::min(i, t.size()));
  return u;
}

// `${param}` replaced by its argument (other ${...} left for the snippet expansion).
std::string substituteParams(const std::string& text, const SharedSnippet& s, const std::vector<std::string>& args) {
  std::string out;
  size_t i = 0;
  while (i < text.size()) {
    size_t b = text.find("${", i);
    size_t e = b == std::string::npos ? std::string::npos : text.find('}', b);
    if (e == std::string::npos) break;
    out += text.substr(i, b - i);
    std::string inner = text.substr(b + 2, e - b - 2);
    auto p = std::find(s.params.begin(), s.params.end(), inner);
    out += p == s.params.end() ? text.substr(b, e - b + 1) : args[static_cast<size_t>(p - s.params.begin())];
    i = e + 1;
  }
  return out + text.substr(std::min(i, text.size()));
}

// Every `@use` line replaced by the shared snippet's lines (which keep their own place in
// the rules files, so GLSL errors point at the one text); nested uses expand in turn.
// `stack`: the snippets being expanded (a use of one of them is a cycle).
std::vector<TemplateLine> expandUses(const RuleSet& set, const std::vector<TemplateLine>& lines,
                                     std::vector<std::string>& stack) {
  std::vector<TemplateLine> out;
  for (const auto& line : lines) {
    std::optional<UseDirective> u = parseUse(line);
    if (!u) {
      out.push_back(line);
      continue;
    }
    const SharedSnippet* s = set.findSnippet(u->name);
    if (!s) {
      std::vector<std::string> names;
      for (const auto& x : set.snippets) names.push_back(x.name);
      throw InputError(u->nameLoc, fmt::format("@use of unknown snippet '{}'{}", u->name, didYouMean(u->name, names)));
    }
    if (std::find(stack.begin(), stack.end(), s->name) != stack.end()) {
      std::string cycle;
      for (auto it = std::find(stack.begin(), stack.end(), s->name); it != stack.end(); ++it) cycle += *it + " -> ";
      throw InputError(u->nameLoc, fmt::format("snippet cycle: {}{}", cycle, s->name));
    }
    if (u->args.size() != s->params.size()) {
      std::string params;
      for (const auto& p : s->params) params += (params.empty() ? "" : ", ") + p;
      throw InputError(u->nameLoc, fmt::format("snippet '{}' takes {} argument{} ({}), given {} (defined at {}:{})", s->name,
                                               s->params.size(), s->params.size() == 1 ? "" : "s", params,
                                               u->args.size(), s->loc.file, s->loc.line));
    }
    std::vector<TemplateLine> body = s->glsl;
    for (auto& b : body) b.text = substituteParams(b.text, *s, u->args);
    stack.push_back(s->name);
    for (auto& b : expandUses(set, body, stack)) out.push_back(std::move(b));
    stack.pop_back();
  }
  return out;
}

void loadSharedSnippets(RuleSet& set, const YamlCtx& y, const YAML::Node& section, const std::vector<std::string>& raw) {
  y.expectMap(section, "'snippets'");
  const size_t first = set.snippets.size();
  for (auto it = section.begin(); it != section.end(); ++it) {
    SharedSnippet s;
    s.name = y.scalar(it->first, "a snippet name");
    s.loc = locOf(it->first, y.file);
    if (!validSnippetName(s.name))
      y.fail(it->first, fmt::format("'{}' is not a valid snippet name (letters, digits and '_')", s.name));
    if (const SharedSnippet* prev = set.findSnippet(s.name)) {
      if (prev->loc.file == s.loc.file && prev->loc.line == s.loc.line) continue;  // same file included twice
      y.fail(it->first, fmt::format("snippet '{}' is defined twice (first at {}:{})", s.name, prev->loc.file, prev->loc.line));
    }
    YAML::Node body = it->second;  // a copy: it->second lives in a temporary proxy
    y.expectMap(body, "a shared snippet");
    y.checkKeys(body, {"params", "glsl", "doc"});
    if (YAML::Node ps = body["params"]) {
      y.expectSeq(ps, "'params'");
      for (const auto& p : ps) {
        std::string name = y.scalar(p, "a parameter name");
        if (!validSnippetName(name)) y.fail(p, fmt::format("'{}' is not a valid parameter name (letters, digits and '_')", name));
        if (name == "out") y.fail(p, "'out' is the using rule's product, not a parameter");
        if (std::find(s.params.begin(), s.params.end(), name) != s.params.end())
          y.fail(p, fmt::format("parameter '{}' is listed twice", name));
        s.params.push_back(name);
      }
    }
    if (!body["glsl"]) y.fail(body, fmt::format("snippet '{}' has no 'glsl'", s.name));
    s.glsl = snippetLines(y, body["glsl"], raw);
    if (body["doc"]) s.doc = y.scalar(body["doc"], "'doc'");
    set.snippets.push_back(std::move(s));
  }
  // Every use inside this file's snippets resolves, with the right arity and no cycle,
  // even if no rule uses them.
  for (size_t i = first; i < set.snippets.size(); ++i) {
    std::vector<std::string> stack{set.snippets[i].name};
    expandUses(set, set.snippets[i].glsl, stack);
  }
}

void loadRule(RuleSet& set, const YamlCtx& y, const YAML::Node& r, const std::vector<std::string>& raw) {
  y.expectMap(r, "a rule");
  y.checkKeys(r, {"name", "produces", "needs", "when", "cost", "glsl", "doc", "override"});
  Rule rule;
  if (!r["name"]) y.fail(r, "rule has no 'name'");
  rule.name = y.scalar(r["name"], "'name'");
  rule.loc = locOf(r["name"], y.file);
  if (!validRuleName(rule.name)) y.fail(r["name"], fmt::format("'{}' is not a valid rule name", rule.name));
  bool overrides = r["override"] && y.boolean(r["override"], "'override'");
  std::optional<size_t> existing;
  for (size_t i = 0; i < set.rules.size(); ++i)
    if (set.rules[i].name == rule.name) {
      const Rule& other = set.rules[i];
      if (other.loc.file == rule.loc.file && other.loc.line == rule.loc.line) return;  // same file included twice
      existing = i;
    }
  if (overrides && !existing) failNothingToOverride(set, y, r["name"], rule.name);
  if (!r["produces"]) y.fail(r, fmt::format("rule '{}' has no 'produces'", rule.name));
  rule.produces = y.scalar(r["produces"], "'produces'");
  rule.producesLoc = locOf(r["produces"], y.file);
  if (!validSemanticName(rule.produces))
    y.fail(r["produces"], fmt::format("'{}' is not a valid semantic name", rule.produces));
  if (auto needs = r["needs"]) {
    if (needs.IsScalar()) {
      rule.needs.push_back(parseRef(y, needs));
    } else {
      y.expectSeq(needs, "'needs'");
      for (const auto& n : needs) rule.needs.push_back(parseRef(y, n));
    }
  }
  if (r["when"]) rule.when = Expr::parse(y.scalar(r["when"], "'when'"), exprLoc(r["when"], y.file));
  if (!r["cost"]) y.fail(r, fmt::format("rule '{}' has no 'cost' (a number, an expression, or 'auto')", rule.name));
  std::string cost = y.scalar(r["cost"], "'cost'");
  if (cost == "auto") rule.costAuto = true;
  else rule.cost = Expr::parse(cost, exprLoc(r["cost"], y.file));
  if (!r["glsl"]) y.fail(r, fmt::format("rule '{}' has no 'glsl' snippet", rule.name));
  std::vector<std::string> stack;
  rule.glsl = expandUses(set, snippetLines(y, r["glsl"], raw), stack);
  if (r["doc"]) rule.doc = y.scalar(r["doc"], "'doc'");
  if (existing) replaceRule(set, y, r["name"], *existing, std::move(rule), overrides);
  else set.rules.push_back(std::move(rule));
}

void loadFile(RuleSet& set, const std::string& path, std::vector<std::string>& stack);

// The same file under another spelling (relative from two places, or absolute) is the
// same file: loading it twice would declare everything twice.
bool alreadyLoaded(const RuleSet& set, const std::string& path) {
  if (std::find(set.files.begin(), set.files.end(), path) != set.files.end()) return true;
  std::error_code ec;
  auto canon = std::filesystem::weakly_canonical(path, ec);
  if (ec) return false;
  for (const auto& f : set.files) {
    std::error_code ec2;
    if (std::filesystem::weakly_canonical(f, ec2) == canon && !ec2) return true;
  }
  return false;
}

void loadParsed(RuleSet& set, const std::string& text, const std::string& path, std::vector<std::string>& stack) {
  YamlCtx y{path};
  YAML::Node root = parseYaml(text, path);
  if (!root.IsDefined() || root.IsNull()) throw InputError(SourceLoc{path, 1, 1}, "empty rules file");
  y.expectMap(root, "a rules file");
  y.checkKeys(root, {"include", "semantics", "snippets", "varyings", "conventions", "disable", "rules", "doc"});
  set.files.push_back(path);
  std::vector<std::string> raw = splitLines(text);
  if (auto inc = root["include"]) {
    y.expectSeq(inc, "'include'");
    for (const auto& i : inc) {
      std::string rel = y.scalar(i, "an include path");
      std::filesystem::path p = std::filesystem::path(path).parent_path() / rel;
      std::string incPath = p.lexically_normal().string();
      if (std::find(stack.begin(), stack.end(), incPath) != stack.end())
        y.fail(i, fmt::format("include cycle: '{}' includes itself", incPath));
      if (alreadyLoaded(set, incPath)) continue;
      std::error_code ec;
      if (!std::filesystem::exists(p, ec)) y.fail(i, fmt::format("included file '{}' does not exist", incPath));
      if (stack.size() >= kMaxIncludeDepth) y.fail(i, fmt::format("includes nest deeper than {} files", kMaxIncludeDepth));
      try {
        loadFile(set, incPath, stack);
      } catch (const InputError& e) {
        // An unreadable include (a directory, a FIFO...) is reported at the include line.
        if (e.diagnostic().loc.file != incPath || e.diagnostic().loc.line != 0) throw;
        y.fail(i, fmt::format("cannot include '{}': {}", incPath, e.diagnostic().message));
      }
    }
  }
  if (auto s = root["semantics"]) loadSemantics(set, y, s, raw);
  if (auto sn = root["snippets"]) loadSharedSnippets(set, y, sn, raw);
  if (auto v = root["varyings"]) loadVaryings(set, y, v);
  if (auto c = root["conventions"]) loadConventions(set, y, c);
  if (auto d = root["disable"]) applyDisable(set, y, d);
  if (auto rs = root["rules"]) {
    y.expectSeq(rs, "'rules'");
    for (const auto& r : rs) {
      if (set.rules.size() >= kMaxRules) y.fail(r, fmt::format("more than {} rules", kMaxRules));
      loadRule(set, y, r, raw);
    }
  }
}

void loadFile(RuleSet& set, const std::string& path, std::vector<std::string>& stack) {
  stack.push_back(path);
  loadParsed(set, readInputFile(path), path, stack);
  stack.pop_back();
}

}  // namespace

const SemanticDecl* RuleSet::findSemantic(const std::string& name) const {
  for (const auto& s : semantics)
    if (s.name == name) return &s;
  return nullptr;
}

const Rule* RuleSet::findRule(const std::string& name) const {
  for (const auto& r : rules)
    if (r.name == name) return &r;
  return nullptr;
}

const SharedSnippet* RuleSet::findSnippet(const std::string& name) const {
  for (const auto& s : snippets)
    if (s.name == name) return &s;
  return nullptr;
}

const VaryingMapping* RuleSet::findVarying(const std::string& name) const {
  for (const auto& v : varyings)
    if (v.name == name) return &v;
  return nullptr;
}

void loadRulesInto(RuleSet& set, const std::string& path) {
  std::string norm = std::filesystem::path(path).lexically_normal().string();
  if (alreadyLoaded(set, norm)) return;
  std::vector<std::string> stack;
  loadFile(set, norm, stack);
}

void loadRulesText(RuleSet& set, const std::string& text, const std::string& fileName) {
  std::vector<std::string> stack{fileName};
  loadParsed(set, text, fileName, stack);
}

RuleSet loadRules(const std::vector<std::string>& paths) {
  RuleSet set;
  for (const auto& p : paths) loadRulesInto(set, p);
  checkDefinitions(set);
  return set;
}

}  // namespace sg
