#include "rules/definition.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <map>
#include <optional>
#include <set>

#include "rules/instantiate.h"
#include "rules/rules.h"

namespace sg {

const char* defTypeName(DefType t) {
  switch (t) {
    case DefType::Bool: return "bool";
    case DefType::Int: return "int";
    case DefType::Float: return "float";
    case DefType::Vec2: return "vec2";
    case DefType::Vec3: return "vec3";
    case DefType::Vec4: return "vec4";
    case DefType::Mat3: return "mat3";
    case DefType::Mat4: return "mat4";
  }
  return "?";
}

int defTypeComponents(DefType t) {
  switch (t) {
    case DefType::Vec2: return 2;
    case DefType::Vec3: return 3;
    case DefType::Vec4: return 4;
    case DefType::Mat3: return 9;
    case DefType::Mat4: return 16;
    default: return 1;
  }
}

DefType declType(Type t) {
  switch (t) {
    case Type::Float: return DefType::Float;
    case Type::Vec2: case Type::UVec2: return DefType::Vec2;
    case Type::Vec3: return DefType::Vec3;
    case Type::Vec4: case Type::IVec4: case Type::UVec4: return DefType::Vec4;
    case Type::Int: case Type::UInt: return DefType::Int;
    case Type::Mat3: return DefType::Mat3;
    case Type::Mat4: return DefType::Mat4;
  }
  return DefType::Float;
}

namespace {

bool isVec(DefType t) { return t == DefType::Vec2 || t == DefType::Vec3 || t == DefType::Vec4; }
bool isMat(DefType t) { return t == DefType::Mat3 || t == DefType::Mat4; }
bool isScalar(DefType t) { return t == DefType::Int || t == DefType::Float; }
bool isNumeric(DefType t) { return t != DefType::Bool; }
DefType vecOf(int n) { return n == 2 ? DefType::Vec2 : n == 3 ? DefType::Vec3 : DefType::Vec4; }
int matN(DefType t) { return t == DefType::Mat3 ? 3 : 4; }

class DefinitionParser {
 public:
  DefinitionParser(const std::string& s, std::vector<std::pair<size_t, SourceLoc>> segments) : s_(s), segments_(std::move(segments)) {}

  DefNodeP parseAll() {
    if (s_.size() > kMaxDefinitionChars)
      fail(0, fmt::format("definition is {} characters long, more than the limit of {}", s_.size(), kMaxDefinitionChars));
    DefNodeP n = parseExpr();
    skip();
    if (pos_ != s_.size()) fail(pos_, fmt::format("unexpected '{}' in definition", s_.substr(pos_, 1)));
    return n;
  }

 private:
  SourceLoc at(size_t p) const {
    size_t k = 0;
    while (k + 1 < segments_.size() && segments_[k + 1].first <= p) ++k;
    SourceLoc l = segments_[k].second;
    if (l.col > 0) l.col += static_cast<int>(p - segments_[k].first);
    return l;
  }
  [[noreturn]] void fail(size_t p, const std::string& msg) const { throw InputError(at(p), msg); }
  void skip() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
  }
  size_t next() {
    skip();
    return pos_;
  }
  bool peek(const char* op) {
    skip();
    return s_.compare(pos_, std::char_traits<char>::length(op), op) == 0;
  }
  bool eat(const char* op) {
    if (!peek(op)) return false;
    pos_ += std::char_traits<char>::length(op);
    return true;
  }
  void expect(const char* op, const char* what) {
    if (!eat(op)) fail(next(), fmt::format("expected '{}' {}", op, what));
  }
  DefNodeP make(DefNode::Kind k, std::string text, size_t p, std::vector<DefNodeP> args = {}) {
    auto n = std::make_shared<DefNode>();
    n->kind = k;
    n->text = std::move(text);
    n->loc = at(p);
    n->args = std::move(args);
    for (const auto& a : n->args) n->depth = std::max(n->depth, a->depth + 1);
    if (n->depth > kMaxDefinitionDepth) fail(p, fmt::format("definition is nested deeper than {} levels", kMaxDefinitionDepth));
    return n;
  }
  struct Nesting {  // bounds the recursion of the parser itself
    DefinitionParser& p;
    Nesting(DefinitionParser& p, size_t at) : p(p) {
      if (++p.nesting_ > kMaxDefinitionDepth)
        p.fail(at, fmt::format("definition is nested deeper than {} levels", kMaxDefinitionDepth));
    }
    ~Nesting() { --p.nesting_; }
  };

  static bool identStart(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
  static bool identChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }
  std::string ident() {  // one identifier, no dots
    std::string id;
    while (pos_ < s_.size() && identChar(s_[pos_])) id += s_[pos_++];
    return id;
  }

  DefNodeP parseExpr() {
    size_t p = next();
    Nesting guard(*this, p);
    if (s_.compare(pos_, 3, "let") == 0 && pos_ + 3 < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_ + 3]))) {
      pos_ += 3;
      skip();
      size_t np = pos_;
      if (pos_ >= s_.size() || !identStart(s_[pos_])) fail(pos_, "expected a name after 'let'");
      std::string name = ident();
      if (pos_ < s_.size() && s_[pos_] == '.') fail(np, fmt::format("a local name cannot contain '.': '{}'", name));
      expect("=", "after the name in 'let'");
      DefNodeP value = parseTernary();
      expect(";", "after the value in 'let'");
      DefNodeP body = parseExpr();
      return make(DefNode::Let, name, np, {value, body});
    }
    return parseTernary();
  }
  DefNodeP parseTernary() {
    DefNodeP c = parseOr();
    size_t p = next();
    if (!eat("?")) return c;
    DefNodeP a = parseExpr();
    expect(":", "in 'c ? a : b'");
    DefNodeP b = parseExpr();
    return make(DefNode::Ternary, "?", p, {c, a, b});
  }
  DefNodeP parseOr() {
    DefNodeP l = parseAnd();
    for (size_t p = next(); eat("||"); p = next()) l = make(DefNode::Binary, "||", p, {l, parseAnd()});
    return l;
  }
  DefNodeP parseAnd() {
    DefNodeP l = parseCmp();
    for (size_t p = next(); eat("&&"); p = next()) l = make(DefNode::Binary, "&&", p, {l, parseCmp()});
    return l;
  }
  DefNodeP parseCmp() {
    DefNodeP l = parseAdd();
    for (;;) {
      size_t p = next();
      const char* hit = nullptr;
      for (const char* op : {"==", "!=", "<=", ">=", "<", ">"})
        if (eat(op)) {
          hit = op;
          break;
        }
      if (!hit) return l;
      l = make(DefNode::Binary, hit, p, {l, parseAdd()});
    }
  }
  DefNodeP parseAdd() {
    DefNodeP l = parseMul();
    for (;;) {
      size_t p = next();
      if (eat("+")) l = make(DefNode::Binary, "+", p, {l, parseMul()});
      else if (eat("-")) l = make(DefNode::Binary, "-", p, {l, parseMul()});
      else return l;
    }
  }
  DefNodeP parseMul() {
    DefNodeP l = parseUnary();
    for (;;) {
      size_t p = next();
      if (eat("*")) l = make(DefNode::Binary, "*", p, {l, parseUnary()});
      else if (eat("/")) l = make(DefNode::Binary, "/", p, {l, parseUnary()});
      else if (eat("%")) l = make(DefNode::Binary, "%", p, {l, parseUnary()});
      else return l;
    }
  }
  DefNodeP parseUnary() {
    size_t p = next();
    Nesting guard(*this, p);
    if (!peek("!=") && eat("!")) return make(DefNode::Unary, "!", p, {parseUnary()});
    if (eat("-")) return make(DefNode::Unary, "-", p, {parseUnary()});
    if (eat("+")) return parseUnary();
    return parsePostfix(parsePrimary());
  }
  DefNodeP parsePostfix(DefNodeP n) {
    for (;;) {
      size_t p = next();
      if (eat("[")) {
        DefNodeP i = parseExpr();
        expect("]", "to close the index");
        n = make(DefNode::Index, "[]", p, {n, i});
      } else if (pos_ < s_.size() && s_[pos_] == '.' && pos_ + 1 < s_.size() && identStart(s_[pos_ + 1])) {
        ++pos_;
        n = make(DefNode::Swizzle, ident(), p + 1, {n});
      } else {
        return n;
      }
    }
  }
  DefNodeP parsePrimary() {
    size_t p = next();
    if (pos_ >= s_.size()) fail(pos_, "definition ends too early");
    char c = s_[pos_];
    if (c == '(') {
      ++pos_;
      DefNodeP n = parseExpr();
      expect(")", "to close '('");
      return n;
    }
    if (std::isdigit(static_cast<unsigned char>(c)) || (c == '.' && pos_ + 1 < s_.size() && std::isdigit(static_cast<unsigned char>(s_[pos_ + 1])))) {
      size_t end = pos_;
      bool integer = true;
      while (end < s_.size() && std::isdigit(static_cast<unsigned char>(s_[end]))) ++end;
      if (end < s_.size() && s_[end] == '.') {
        integer = false;
        ++end;
        while (end < s_.size() && std::isdigit(static_cast<unsigned char>(s_[end]))) ++end;
      }
      if (end < s_.size() && (s_[end] == 'e' || s_[end] == 'E')) {
        size_t e = end + 1;
        if (e < s_.size() && (s_[e] == '+' || s_[e] == '-')) ++e;
        if (e < s_.size() && std::isdigit(static_cast<unsigned char>(s_[e]))) {
          integer = false;
          end = e;
          while (end < s_.size() && std::isdigit(static_cast<unsigned char>(s_[end]))) ++end;
        }
      }
      std::string num = s_.substr(pos_, end - pos_);
      double v = std::strtod(num.c_str(), nullptr);
      if (!std::isfinite(v) || (integer && v > 1e15)) fail(p, fmt::format("number '{}' is out of range", num));
      pos_ = end;
      auto n = make(DefNode::Num, num, p);
      n->value = v;
      n->integer = integer;
      return n;
    }
    if (identStart(c)) {
      std::string id = ident();
      if (peek("(")) {
        eat("(");
        std::vector<DefNodeP> args;
        if (!eat(")")) {
          do args.push_back(parseExpr());
          while (eat(","));
          expect(")", fmt::format("to close the arguments of '{}'", id).c_str());
        }
        return make(DefNode::Call, id, p, std::move(args));
      }
      // A dotted name (a semantic, perhaps followed by a swizzle: split when checked).
      while (pos_ + 1 < s_.size() && s_[pos_] == '.' && identStart(s_[pos_ + 1])) {
        ++pos_;
        id += "." + ident();
      }
      return make(DefNode::Name, id, p);
    }
    fail(p, fmt::format("unexpected '{}' in definition", std::string(1, c)));
  }

  const std::string& s_;
  std::vector<std::pair<size_t, SourceLoc>> segments_;
  size_t pos_ = 0;
  int nesting_ = 0;
};

bool swizzleLetters(const std::string& s) {
  if (s.empty() || s.size() > 4) return false;
  bool xyzw = s.find_first_not_of("xyzw") == std::string::npos;
  bool rgba = s.find_first_not_of("rgba") == std::string::npos;
  return xyzw || rgba;
}

class Checker {
 public:
  explicit Checker(RuleSet& set) : set_(set) {}

  void check(int semantic) {
    SemanticDecl& d = set_.semantics[static_cast<size_t>(semantic)];
    locals_.clear();
    DefType t = type(*d.definition);
    DefType want = declType(d.type);
    if (t != want && !(t == DefType::Int && want == DefType::Float))
      throw InputError(d.definition->loc, fmt::format("the definition of '{}' is a {}, but '{}' is declared {}", d.name,
                                                      defTypeName(t), d.name, glslName(d.type)));
  }

 private:
  [[noreturn]] static void fail(const DefNode& n, const std::string& msg) { throw InputError(n.loc, msg); }

  const SemanticDecl* semanticOf(const DefNode& n) const {
    return n.semantic >= 0 ? &set_.semantics[static_cast<size_t>(n.semantic)] : nullptr;
  }
  static bool indexed(const SemanticDecl& d) { return !d.count.empty() || !d.arrayParam.empty(); }

  // Resolves a Name node; turns "sem.xyz" into Swizzle(Name sem). Returns the node to type.
  void resolve(DefNode& n) {
    if (locals_.count(n.text)) {
      n.ref = DefNode::Local;
      return;
    }
    auto find = [&](const std::string& name) -> int {
      for (size_t i = 0; i < set_.semantics.size(); ++i)
        if (set_.semantics[i].name == name) return static_cast<int>(i);
      return -1;
    };
    if (int s = find(n.text); s >= 0) {
      n.ref = DefNode::Semantic;
      n.semantic = s;
      return;
    }
    auto dot = n.text.rfind('.');
    if (dot == std::string::npos) {
      n.ref = DefNode::Param;  // a rig parameter (checked against the rig when evaluated)
      return;
    }
    std::string base = n.text.substr(0, dot), sw = n.text.substr(dot + 1);
    if (locals_.count(base) && swizzleLetters(sw)) {  // a local's swizzle: "N.z"
      auto inner = std::make_shared<DefNode>(n);
      inner->text = base;
      inner->ref = DefNode::Local;
      n.kind = DefNode::Swizzle;
      n.text = sw;
      n.args = {inner};
      n.loc.col = n.loc.col > 0 ? n.loc.col + static_cast<int>(dot) + 1 : 0;
      return;
    }
    if (int s = find(base); s >= 0 && swizzleLetters(sw)) {
      auto inner = std::make_shared<DefNode>(n);
      inner->text = base;
      inner->ref = DefNode::Semantic;
      inner->semantic = s;
      n.kind = DefNode::Swizzle;
      n.text = sw;
      n.args = {inner};
      n.loc.col = n.loc.col > 0 ? n.loc.col + static_cast<int>(dot) + 1 : 0;
      return;
    }
    fail(n, fmt::format("unknown semantic '{}'{}", n.text, didYouMeanSemantic(set_, n.text)));
  }

  DefType arith(const DefNode& n, const std::string& op, DefType a, DefType b) {
    auto bad = [&]() -> DefType {
      fail(n, fmt::format("cannot apply '{}' to {} and {}", op, defTypeName(a), defTypeName(b)));
    };
    if (!isNumeric(a) || !isNumeric(b)) bad();
    if (a == DefType::Int && b == DefType::Int) return DefType::Int;
    if (op == "%") bad();
    if (a == DefType::Int) a = DefType::Float;
    if (b == DefType::Int) b = DefType::Float;
    if (a == DefType::Float) return b;
    if (b == DefType::Float) return a;
    if (a == b) return a;  // componentwise, or the matrix product for matN * matN
    if (op == "*" && isMat(a) && isVec(b) && matN(a) == defTypeComponents(b)) return b;
    if (op == "*" && isVec(a) && isMat(b) && matN(b) == defTypeComponents(a)) return a;
    return bad();
  }

  DefType unify(const DefNode& n, DefType a, DefType b, const char* what) {
    if (a == b) return a;
    if (isScalar(a) && isScalar(b)) return DefType::Float;
    fail(n, fmt::format("{} have different types: {} and {}", what, defTypeName(a), defTypeName(b)));
  }

  void want(const DefNode& n, bool ok, const std::string& msg) {
    if (!ok) fail(n, msg);
  }

  DefType call(DefNode& n) {
    const std::string& f = n.text;
    auto& a = n.args;
    auto argc = [&](size_t lo, size_t hi) {
      if (a.size() < lo || a.size() > hi)
        fail(n, lo == hi ? fmt::format("'{}' takes {} argument(s), not {}", f, lo, a.size())
                         : fmt::format("'{}' takes {} to {} arguments, not {}", f, lo, hi, a.size()));
    };
    if (f == "has") {
      argc(1, 1);
      want(n, a[0]->kind == DefNode::Name, "has() takes a semantic name");
      if (locals_.count(a[0]->text) || !set_.findSemantic(a[0]->text))
        fail(*a[0], fmt::format("unknown semantic '{}'{}", a[0]->text, didYouMeanSemantic(set_, a[0]->text)));
      a[0]->ref = DefNode::Semantic;
      for (size_t i = 0; i < set_.semantics.size(); ++i)
        if (set_.semantics[i].name == a[0]->text) a[0]->semantic = static_cast<int>(i);
      a[0]->type = DefType::Bool;
      return DefType::Bool;
    }
    if (f == "sum") {
      argc(3, 3);
      want(*a[0], a[0]->kind == DefNode::Name && a[0]->text.find('.') == std::string::npos,
           "sum(i, count, body): the first argument is the name of the index");
      want(n, type(*a[1]) == DefType::Int, "sum(i, count, body): the count must be an integer");
      const std::string& var = a[0]->text;
      auto saved = locals_.find(var) != locals_.end() ? std::optional<DefType>(locals_[var]) : std::nullopt;
      locals_[var] = DefType::Int;
      a[0]->ref = DefNode::Local;
      a[0]->type = DefType::Int;
      DefType t = type(*a[2]);
      if (saved) locals_[var] = *saved;
      else locals_.erase(var);
      want(n, isNumeric(t), "sum() adds numbers, vectors or matrices");
      n.kind = DefNode::Sum;
      return t;
    }
    std::vector<DefType> t;
    for (auto& x : a) t.push_back(type(*x));
    auto floatish = [&](DefType x) { return x == DefType::Int ? DefType::Float : x; };
    if (f == "dot") {
      argc(2, 2);
      want(n, isVec(t[0]) && t[0] == t[1], fmt::format("dot() takes two vectors of one size, not {} and {}", defTypeName(t[0]), defTypeName(t[1])));
      return DefType::Float;
    }
    if (f == "cross") {
      argc(2, 2);
      want(n, t[0] == DefType::Vec3 && t[1] == DefType::Vec3, "cross() takes two vec3");
      return DefType::Vec3;
    }
    if (f == "normalize" || f == "length") {
      argc(1, 1);
      want(n, isVec(t[0]), fmt::format("{}() takes a vector, not {}", f, defTypeName(t[0])));
      return f == "length" ? DefType::Float : t[0];
    }
    if (f == "abs" || f == "sign" || f == "sqrt" || f == "float") {
      argc(1, 1);
      want(n, isScalar(t[0]) || (isVec(t[0]) && f != "float"), fmt::format("{}() does not take a {}", f, defTypeName(t[0])));
      return floatish(t[0]);
    }
    if (f == "min" || f == "max" || f == "clamp") {
      argc(f == "clamp" ? 3 : 2, f == "clamp" ? 3 : 2);
      DefType r = floatish(t[0]);
      want(n, isScalar(t[0]) || isVec(t[0]), fmt::format("{}() does not take a {}", f, defTypeName(t[0])));
      for (size_t i = 1; i < t.size(); ++i)
        want(n, floatish(t[i]) == r || isScalar(t[i]), fmt::format("{}() arguments: {} and {}", f, defTypeName(t[0]), defTypeName(t[i])));
      return r;
    }
    if (f == "inverse" || f == "transpose" || f == "determinant") {
      argc(1, 1);
      want(n, isMat(t[0]), fmt::format("{}() takes a matrix, not {}", f, defTypeName(t[0])));
      return f == "determinant" ? DefType::Float : t[0];
    }
    if (f == "mat3" || f == "mat4") {
      const int N = f == "mat3" ? 3 : 4;
      if (a.size() == 1 && (isMat(t[0]) || isScalar(t[0]))) return N == 3 ? DefType::Mat3 : DefType::Mat4;
      want(n, a.size() == static_cast<size_t>(N) &&
                  std::all_of(t.begin(), t.end(), [&](DefType x) { return x == vecOf(N); }),
           fmt::format("{}() takes a matrix, a scalar (the diagonal) or {} vec{} columns", f, N, N));
      return N == 3 ? DefType::Mat3 : DefType::Mat4;
    }
    if (f == "vec2" || f == "vec3" || f == "vec4") {
      const int N = f[3] - '0';
      if (a.size() == 1 && isScalar(t[0])) return vecOf(N);
      int comps = 0;
      for (DefType x : t) {
        want(n, isScalar(x) || isVec(x), fmt::format("{}() takes scalars and vectors, not {}", f, defTypeName(x)));
        comps += defTypeComponents(x);
      }
      want(n, comps == N, fmt::format("{}() needs {} components, the arguments have {}", f, N, comps));
      return vecOf(N);
    }
    fail(n, fmt::format("unknown function '{}' (dot, cross, normalize, length, abs, sign, sqrt, min, max, clamp, "
                        "inverse, transpose, determinant, float, mat3, mat4, vec2, vec3, vec4, has, sum)",
                        f));
  }

  DefType type(DefNode& n) {
    n.type = typeOf(n);
    return n.type;
  }

  DefType typeOf(DefNode& n) {
    switch (n.kind) {
      case DefNode::Num: return n.integer ? DefType::Int : DefType::Float;
      case DefNode::Name: {
        resolve(n);
        if (n.kind == DefNode::Swizzle) return typeOf(n);
        if (n.ref == DefNode::Local) return locals_[n.text];
        if (n.ref == DefNode::Param) return DefType::Int;
        const SemanticDecl& d = *semanticOf(n);
        if (indexed(d))
          fail(n, fmt::format("'{}' is {}: index it ('{}[i]')", d.name,
                              d.count.empty() ? "a uniform array" : "an indexed family", d.name));
        return declType(d.type);
      }
      case DefNode::Call: return call(n);
      case DefNode::Unary: {
        DefType a = type(*n.args[0]);
        if (n.text == "!") want(n, a == DefType::Bool, fmt::format("'!' takes a bool, not {}", defTypeName(a)));
        else want(n, isNumeric(a), "'-' takes a number, vector or matrix");
        return a;
      }
      case DefNode::Binary: {
        DefType a = type(*n.args[0]), b = type(*n.args[1]);
        const std::string& op = n.text;
        if (op == "&&" || op == "||") {
          want(n, a == DefType::Bool && b == DefType::Bool, fmt::format("'{}' takes two bools", op));
          return DefType::Bool;
        }
        if (op == "==" || op == "!=" || op == "<" || op == ">" || op == "<=" || op == ">=") {
          bool ok = (isScalar(a) && isScalar(b)) || ((op == "==" || op == "!=") && a == DefType::Bool && b == DefType::Bool);
          want(n, ok, fmt::format("'{}' compares scalars, not {} and {}", op, defTypeName(a), defTypeName(b)));
          return DefType::Bool;
        }
        return arith(n, op, a, b);
      }
      case DefNode::Ternary: {
        DefType c = type(*n.args[0]);
        want(*n.args[0], c == DefType::Bool, fmt::format("the condition of '?:' must be a bool, not {}", defTypeName(c)));
        return unify(n, type(*n.args[1]), type(*n.args[2]), "the branches of '?:'");
      }
      case DefNode::Let: {
        DefType v = type(*n.args[0]);
        auto saved = locals_.count(n.text) ? std::optional<DefType>(locals_[n.text]) : std::nullopt;
        locals_[n.text] = v;
        DefType t = type(*n.args[1]);
        if (saved) locals_[n.text] = *saved;
        else locals_.erase(n.text);
        return t;
      }
      case DefNode::Index: {
        DefNode& base = *n.args[0];
        DefType it = type(*n.args[1]);
        if (base.kind == DefNode::Name) {
          resolve(base);
          if (base.kind == DefNode::Name && base.ref == DefNode::Semantic) {
            const SemanticDecl& d = *semanticOf(base);
            if (indexed(d)) {
              bool family = !d.count.empty();
              want(*n.args[1], it == DefType::Int || (!family && it == DefType::Float),
                   family ? "an indexed family is indexed by an integer (a rig parameter, a sum index, a literal)"
                          : "a uniform array is indexed by a number");
              base.type = declType(d.type);
              return declType(d.type);
            }
          }
        }
        DefType b = type(base);
        want(*n.args[1], it == DefType::Int || it == DefType::Float, fmt::format("an index must be a number, not {}", defTypeName(it)));
        if (isVec(b)) return DefType::Float;
        if (isMat(b)) return vecOf(matN(b));
        fail(n, fmt::format("a {} cannot be indexed", defTypeName(b)));
      }
      case DefNode::Swizzle: {
        DefType b = type(*n.args[0]);
        want(n, isVec(b), fmt::format("'.{}' on a {}: swizzles apply to vectors", n.text, defTypeName(b)));
        want(n, swizzleLetters(n.text), fmt::format("'{}' is not a swizzle (xyzw or rgba)", n.text));
        for (char c : n.text) {
          int i = c == 'x' || c == 'r' ? 0 : c == 'y' || c == 'g' ? 1 : c == 'z' || c == 'b' ? 2 : 3;
          want(n, i < defTypeComponents(b), fmt::format("'.{}' reaches past the end of a {}", n.text, defTypeName(b)));
        }
        return n.text.size() == 1 ? DefType::Float : vecOf(static_cast<int>(n.text.size()));
      }
      case DefNode::Sum: return call(n);  // already rewritten: re-check
    }
    return DefType::Float;
  }

  RuleSet& set_;
  std::map<std::string, DefType> locals_;
};

void collectReads(const DefNode& n, std::vector<int>& out) {
  if (n.kind == DefNode::Call && n.text == "has") return;
  if ((n.kind == DefNode::Name) && n.ref == DefNode::Semantic) out.push_back(n.semantic);
  for (const auto& a : n.args) collectReads(*a, out);
}

}  // namespace

DefNodeP parseDefinition(const std::string& text, const SourceLoc& loc) { return DefinitionParser(text, {{0, loc}}).parseAll(); }

DefNodeP parseDefinition(const std::string& text, const std::vector<std::pair<size_t, SourceLoc>>& segments) {
  return DefinitionParser(text, segments).parseAll();
}

std::vector<int> definitionReads(const DefNode& root) {
  std::vector<int> out;
  collectReads(root, out);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

void checkDefinitions(RuleSet& set) {
  Checker checker(set);
  for (size_t i = 0; i < set.semantics.size(); ++i) {
    SemanticDecl& d = set.semantics[i];
    if (!d.definition) continue;
    if (!d.count.empty() || !d.arrayParam.empty())
      throw InputError(d.definition->loc, fmt::format("'{}' is {}; only single semantics have definitions", d.name,
                                                      d.count.empty() ? "a uniform array" : "an indexed family"));
    checker.check(static_cast<int>(i));
  }
  // Cycles: depth-first search, 0 = unseen, 1 = on the stack, 2 = done.
  std::vector<int> state(set.semantics.size(), 0);
  std::vector<int> stack;
  std::function<void(int)> visit = [&](int s) {
    state[static_cast<size_t>(s)] = 1;
    stack.push_back(s);
    const SemanticDecl& d = set.semantics[static_cast<size_t>(s)];
    if (d.definition)
      for (int r : definitionReads(*d.definition)) {
        if (state[static_cast<size_t>(r)] == 1) {
          std::string path;
          auto from = std::find(stack.begin(), stack.end(), r);
          for (auto it = from; it != stack.end(); ++it) path += set.semantics[static_cast<size_t>(*it)].name + " -> ";
          path += set.semantics[static_cast<size_t>(r)].name;
          const SemanticDecl& first = set.semantics[static_cast<size_t>(r)];
          throw InputError(first.definition->loc, fmt::format("definitions form a cycle: {}", path));
        }
        if (state[static_cast<size_t>(r)] == 0) visit(r);
      }
    stack.pop_back();
    state[static_cast<size_t>(s)] = 2;
  };
  for (size_t i = 0; i < set.semantics.size(); ++i)
    if (state[i] == 0) visit(static_cast<int>(i));
}

}  // namespace sg
