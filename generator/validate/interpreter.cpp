// Tree-walking evaluation of semantic definitions, one vertex at a time, with a per-vertex
// cache of every semantic already evaluated (outputs share their intermediates).
#include "validate/interpreter.h"

#include <fmt/format.h>

#include <glm/glm.hpp>

#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <utility>

namespace sg {
namespace {

using glm::dmat3;
using glm::dmat4;
using glm::dvec3;
using glm::dvec4;

// Every value lives in a dmat4: scalars in [0][0], vectors in column 0, mat3 upper-left.
struct Val {
  DefType t = DefType::Float;
  dmat4 m = dmat4(0.0);
};

Val scalar(double x, DefType t = DefType::Float) {
  Val v;
  v.t = t;
  v.m[0][0] = x;
  return v;
}
Val vec(const dvec4& x, DefType t) {
  Val v;
  v.t = t;
  v.m[0] = x;
  return v;
}
Val mat3v(const dmat3& x) {
  Val v;
  v.t = DefType::Mat3;
  v.m = dmat4(x);
  v.m[3][3] = 0.0;
  return v;
}
Val mat4v(const dmat4& x) {
  Val v;
  v.t = DefType::Mat4;
  v.m = x;
  return v;
}
dmat3 m3(const Val& v) { return dmat3(v.m); }
double s(const Val& v) { return v.m[0][0]; }
int vecN(DefType t) { return t == DefType::Vec2 ? 2 : t == DefType::Vec3 ? 3 : 4; }
bool isVecT(DefType t) { return t == DefType::Vec2 || t == DefType::Vec3 || t == DefType::Vec4; }
bool isMatT(DefType t) { return t == DefType::Mat3 || t == DefType::Mat4; }
bool isScalarT(DefType t) { return t == DefType::Int || t == DefType::Float || t == DefType::Bool; }
DefType vecType(int n) { return n == 2 ? DefType::Vec2 : n == 3 ? DefType::Vec3 : DefType::Vec4; }

// Flat components of a value (what outputs and uniforms hold).
void flatten(const Val& v, double* out) {
  if (v.t == DefType::Mat3) {
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) out[c * 3 + r] = v.m[c][r];
  } else if (v.t == DefType::Mat4) {
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) out[c * 4 + r] = v.m[c][r];
  } else {
    for (int c = 0; c < defTypeComponents(v.t); ++c) out[c] = v.m[0][c];
  }
}

Val unflatten(DefType t, const double* in) {
  Val v;
  v.t = t;
  if (t == DefType::Mat3) {
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) v.m[c][r] = in[c * 3 + r];
  } else if (t == DefType::Mat4) {
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) v.m[c][r] = in[c * 4 + r];
  } else {
    for (int c = 0; c < defTypeComponents(t); ++c) v.m[0][c] = in[c];
  }
  return v;
}

std::string showVal(const Val& v) {
  double f[16];
  flatten(v, f);
  int n = defTypeComponents(v.t);
  if (n == 1) return fmt::format("{:.9g}", f[0]);
  std::string s = "(";
  for (int i = 0; i < n; ++i) s += fmt::format("{}{:.9g}", i ? ", " : "", f[i]);
  return s + ")";
}

constexpr size_t kNoVertex = std::numeric_limits<size_t>::max();

}  // namespace

struct Interpreter::State {
  const RuleSet& rules;
  const RigShape& shape;
  const rt::Mesh& mesh;
  const UniformValues& uniforms;
  size_t vertex = 0;
  uint64_t stamp = 1;  // cache generation: one per vertex
  std::vector<Val> cache;
  std::vector<uint64_t> cachedAt;
  std::vector<std::pair<std::string, Val>> locals;
  std::vector<std::string>* trace = nullptr;
  std::set<std::string> traced;
  int evaluating = -1;  // semantic whose definition is being evaluated (messages)

  State(const RuleSet& r, const RigShape& sh, const rt::Mesh& m, const UniformValues& u)
      : rules(r), shape(sh), mesh(m), uniforms(u), cache(r.semantics.size()), cachedAt(r.semantics.size(), 0) {}

  [[noreturn]] void fail(const DefNode& n, const std::string& msg) const {
    std::string where = n.loc.line ? fmt::format("{}:{}:{}: ", n.loc.file, n.loc.line, n.loc.col) : "";
    throw std::invalid_argument(where + msg);
  }

  int semanticIndex(const std::string& name) const {
    for (size_t i = 0; i < rules.semantics.size(); ++i)
      if (rules.semantics[i].name == name) return static_cast<int>(i);
    throw UndefinedSemantic(fmt::format("unknown semantic '{}'", name));
  }

  void record(const std::string& name, const Val& v) {
    if (trace && traced.insert(name).second) trace->push_back(name + " = " + showVal(v));
  }

  // Where a provided semantic instance lives, resolved once per (semantic, index).
  struct Source {
    const std::vector<double>* uniform = nullptr;  // with offset
    size_t offset = 0;
    const std::vector<glm::vec4>* stream = nullptr;
    std::string name;  // "morph.position[2]"
  };
  std::map<std::pair<int, int64_t>, Source> sources;

  const Source& sourceOf(int sem, int64_t index, const DefNode* at) {
    auto key = std::make_pair(sem, index);
    if (auto it = sources.find(key); it != sources.end()) return it->second;
    const SemanticDecl& d = rules.semantics[static_cast<size_t>(sem)];
    const size_t n = static_cast<size_t>(defTypeComponents(declType(d.type)));
    Source src;
    src.name = index >= 0 ? fmt::format("{}[{}]", d.name, index) : d.name;
    auto u = uniforms.find(d.name);
    if (u != uniforms.end() && !(index >= 0 && !d.count.empty())) {
      size_t off = index >= 0 ? static_cast<size_t>(index) * n : 0;
      if (off + n > u->second.size()) {
        std::string msg = fmt::format("index {} is out of range of '{}' ({} elements)", index, d.name, u->second.size() / n);
        if (at) fail(*at, msg);
        throw std::invalid_argument(msg);
      }
      src.uniform = &u->second;
      src.offset = off;
    } else if (auto m = mesh.streams.find(src.name); m != mesh.streams.end()) {
      if (m->second.size() != mesh.vertexCount)
        throw std::invalid_argument(fmt::format("stream {} of mesh '{}' has {} values for {} vertices", src.name, mesh.name,
                                                m->second.size(), mesh.vertexCount));
      src.stream = &m->second;
    }
    return sources.emplace(key, std::move(src)).first->second;
  }

  // Provided value of a semantic (element `index` of a family or array, -1 for none), or
  // false if neither the mesh nor the pose has it.
  bool provided(int sem, int64_t index, Val& out, const DefNode* at) {
    const Source& src = sourceOf(sem, index, at);
    DefType t = declType(rules.semantics[static_cast<size_t>(sem)].type);
    if (src.uniform) {
      out = unflatten(t, src.uniform->data() + src.offset);
    } else if (src.stream) {
      if (vertex == kNoVertex) {
        const std::string& of = evaluating >= 0 ? rules.semantics[static_cast<size_t>(evaluating)].name : src.name;
        throw std::invalid_argument(fmt::format("'{}' is evaluated as a uniform but reads per-vertex '{}'", of, src.name));
      }
      const glm::vec4& x = (*src.stream)[vertex];
      out = t == DefType::Int || t == DefType::Float ? scalar(x.x, t) : vec(dvec4(x), t);
    } else {
      return false;
    }
    if (trace) record(src.name, out);
    return true;
  }

  Val semantic(int sem, const DefNode* at) {
    if (cachedAt[static_cast<size_t>(sem)] == stamp) return cache[static_cast<size_t>(sem)];
    Val v;
    const SemanticDecl& d = rules.semantics[static_cast<size_t>(sem)];
    if (!provided(sem, -1, v, at)) {
      if (!d.definition)
        throw UndefinedSemantic(fmt::format("'{}' has no definition and the rig does not provide it", d.name));
      auto savedLocals = std::move(locals);
      locals.clear();
      int savedEval = evaluating;
      evaluating = sem;
      v = eval(*d.definition);
      if (v.t == DefType::Int && declType(d.type) == DefType::Float) v.t = DefType::Float;
      evaluating = savedEval;
      locals = std::move(savedLocals);
    }
    cache[static_cast<size_t>(sem)] = v;
    cachedAt[static_cast<size_t>(sem)] = stamp;
    return v;
  }

  int64_t integral(const DefNode& n, const Val& v, const char* what) {
    double x = s(v);
    if (!(x == std::floor(x)) || std::abs(x) > 1e15) fail(n, fmt::format("{} {} is not an integer", what, x));
    return static_cast<int64_t>(x);
  }

  Val arith(const DefNode& n, const std::string& op, Val a, Val b) {
    if (a.t == DefType::Int && b.t == DefType::Int) {
      double x = s(a), y = s(b), r = 0;
      if (op == "+") r = x + y;
      else if (op == "-") r = x - y;
      else if (op == "*") r = x * y;
      else {
        if (y == 0) fail(n, fmt::format("integer division by zero in '{}'", op));
        r = op == "/" ? std::trunc(x / y) : std::fmod(x, y);
      }
      return scalar(r, DefType::Int);
    }
    if (a.t == DefType::Int) a.t = DefType::Float;
    if (b.t == DefType::Int) b.t = DefType::Float;
    auto apply = [&](double x, double y) {
      return op == "+" ? x + y : op == "-" ? x - y : op == "*" ? x * y : x / y;
    };
    auto each = [&](const Val& x, auto f) {
      Val r;
      r.t = x.t;
      int cols = x.t == DefType::Mat3 ? 3 : x.t == DefType::Mat4 ? 4 : 1;
      int rows = isMatT(x.t) ? cols : defTypeComponents(x.t);
      for (int c = 0; c < cols; ++c)
        for (int k = 0; k < rows; ++k) r.m[c][k] = f(x.m[c][k], c, k);
      return r;
    };
    if (a.t == DefType::Float && b.t == DefType::Float) return scalar(apply(s(a), s(b)));
    if (a.t == DefType::Float) return each(b, [&](double y, int, int) { return apply(s(a), y); });
    if (b.t == DefType::Float) return each(a, [&](double x, int, int) { return apply(x, s(b)); });
    if (op == "*" && isMatT(a.t) && isMatT(b.t))
      return a.t == DefType::Mat3 ? mat3v(m3(a) * m3(b)) : mat4v(a.m * b.m);
    if (op == "*" && isMatT(a.t) && isVecT(b.t))
      return a.t == DefType::Mat3 ? vec(dvec4(m3(a) * dvec3(b.m[0]), 0.0), b.t) : vec(a.m * b.m[0], b.t);
    if (op == "*" && isVecT(a.t) && isMatT(b.t))
      return b.t == DefType::Mat3 ? vec(dvec4(dvec3(a.m[0]) * m3(b), 0.0), a.t) : vec(a.m[0] * b.m, a.t);
    return each(a, [&](double x, int c, int k) { return apply(x, b.m[c][k]); });
  }

  double compare(const std::string& op, double x, double y) {
    bool r = op == "==" ? x == y : op == "!=" ? x != y : op == "<" ? x < y : op == ">" ? x > y : op == "<=" ? x <= y : x >= y;
    return r ? 1.0 : 0.0;
  }

  Val call(const DefNode& n) {
    const std::string& f = n.text;
    if (f == "has") {
      const std::string& name = n.args[0]->text;
      bool has = shape.provided.count(name) || shape.provided.count(indexedName(name, 0));
      return scalar(has ? 1.0 : 0.0, DefType::Bool);
    }
    // At most 4 arguments once checked (mat4 of 4 columns, vec4 of 4 scalars): no allocation.
    if (n.args.size() > 4) fail(n, fmt::format("'{}' has {} arguments", f, n.args.size()));
    struct Args {
      Val v[4];
      size_t count = 0;
      size_t size() const { return count; }
      Val& operator[](size_t i) { return v[i]; }
      Val* begin() { return v; }
      Val* end() { return v + count; }
    } a;
    for (const auto& x : n.args) a.v[a.count++] = eval(*x);
    for (auto& x : a)
      if (x.t == DefType::Int) x.t = DefType::Float;
    auto v3 = [](const Val& v) { return dvec3(v.m[0]); };
    auto perComp = [&](const Val& v, double (*g)(double)) {
      Val r = v;
      for (int c = 0; c < defTypeComponents(v.t); ++c) r.m[0][c] = g(v.m[0][c]);
      return r;
    };
    if (f == "dot") return scalar(glm::dot(a[0].m[0], a[1].m[0]));
    if (f == "cross") return vec(dvec4(glm::cross(v3(a[0]), v3(a[1])), 0.0), DefType::Vec3);
    if (f == "length") return scalar(glm::length(a[0].m[0]));
    if (f == "normalize") {
      double len = glm::length(a[0].m[0]);
      return vec(a[0].m[0] / len, a[0].t);  // a zero vector gives NaN, as normalize() in GLSL
    }
    if (f == "abs") return perComp(a[0], [](double x) { return std::abs(x); });
    if (f == "sqrt") return perComp(a[0], [](double x) { return std::sqrt(x); });
    if (f == "sign") return perComp(a[0], [](double x) { return x > 0 ? 1.0 : x < 0 ? -1.0 : 0.0; });
    if (f == "float") return a[0];
    if (f == "min" || f == "max" || f == "clamp") {
      Val r = a[0];
      for (int c = 0; c < defTypeComponents(r.t); ++c) {
        auto arg = [&](size_t i) { return isScalarT(a[i].t) ? s(a[i]) : a[i].m[0][c]; };
        double x = r.m[0][c];
        if (f == "min") x = std::min(x, arg(1));
        else if (f == "max") x = std::max(x, arg(1));
        else x = std::min(std::max(x, arg(1)), arg(2));
        r.m[0][c] = x;
      }
      return r;
    }
    if (f == "inverse") return a[0].t == DefType::Mat3 ? mat3v(glm::inverse(m3(a[0]))) : mat4v(glm::inverse(a[0].m));
    if (f == "transpose") return a[0].t == DefType::Mat3 ? mat3v(glm::transpose(m3(a[0]))) : mat4v(glm::transpose(a[0].m));
    if (f == "determinant") return scalar(a[0].t == DefType::Mat3 ? glm::determinant(m3(a[0])) : glm::determinant(a[0].m));
    if (f == "mat3" || f == "mat4") {
      const bool three = f == "mat3";
      if (a.size() == 1 && isScalarT(a[0].t)) return three ? mat3v(dmat3(s(a[0]))) : mat4v(dmat4(s(a[0])));
      if (a.size() == 1) {
        if (three) return mat3v(m3(a[0]));
        if (a[0].t == DefType::Mat3) return mat4v(dmat4(m3(a[0])));
        return a[0];
      }
      Val r;
      r.t = three ? DefType::Mat3 : DefType::Mat4;
      for (size_t c = 0; c < a.size(); ++c) r.m[static_cast<int>(c)] = a[c].m[0];
      return r;
    }
    if (f == "vec2" || f == "vec3" || f == "vec4") {
      const int N = f[3] - '0';
      if (a.size() == 1 && isScalarT(a[0].t)) {
        dvec4 x(0.0);
        for (int c = 0; c < N; ++c) x[c] = s(a[0]);
        return vec(x, vecType(N));
      }
      dvec4 x(0.0);
      int k = 0;
      for (const auto& v : a)
        for (int c = 0; c < defTypeComponents(v.t); ++c) x[k++] = v.m[0][c];
      return vec(x, vecType(N));
    }
    fail(n, fmt::format("unknown function '{}'", f));
  }

  Val eval(const DefNode& n) {
    switch (n.kind) {
      case DefNode::Num: return scalar(n.value, n.integer ? DefType::Int : DefType::Float);
      case DefNode::Name: {
        if (n.ref == DefNode::Local) {
          for (auto it = locals.rbegin(); it != locals.rend(); ++it)
            if (it->first == n.text) return it->second;
          fail(n, fmt::format("unbound local '{}'", n.text));
        }
        if (n.ref == DefNode::Param) {
          auto p = shape.params.find(n.text);
          if (p == shape.params.end()) fail(n, fmt::format("the rig has no parameter '{}'", n.text));
          return scalar(static_cast<double>(p->second), DefType::Int);
        }
        return semantic(n.semantic, &n);
      }
      case DefNode::Call: return call(n);
      case DefNode::Unary: {
        Val a = eval(*n.args[0]);
        if (n.text == "!") return scalar(s(a) == 0 ? 1.0 : 0.0, DefType::Bool);
        Val r = a;
        r.m = -a.m;
        return r;
      }
      case DefNode::Binary: {
        const std::string& op = n.text;
        if (op == "&&" || op == "||") {
          bool x = s(eval(*n.args[0])) != 0;
          if (op == "&&" && !x) return scalar(0, DefType::Bool);
          if (op == "||" && x) return scalar(1, DefType::Bool);
          return scalar(s(eval(*n.args[1])) != 0 ? 1 : 0, DefType::Bool);
        }
        Val a = eval(*n.args[0]), b = eval(*n.args[1]);
        if (op == "==" || op == "!=" || op == "<" || op == ">" || op == "<=" || op == ">=")
          return scalar(compare(op, s(a), s(b)), DefType::Bool);
        return arith(n, op, a, b);
      }
      case DefNode::Ternary: {
        Val r = s(eval(*n.args[0])) != 0 ? eval(*n.args[1]) : eval(*n.args[2]);
        if (r.t == DefType::Int && n.type == DefType::Float) r.t = DefType::Float;
        return r;
      }
      case DefNode::Let: {
        locals.emplace_back(n.text, eval(*n.args[0]));
        Val r = eval(*n.args[1]);
        locals.pop_back();
        return r;
      }
      case DefNode::Sum: {
        int64_t count = integral(n, eval(*n.args[1]), "the count of sum()");
        Val acc;
        acc.t = n.type;
        for (int64_t i = 0; i < count; ++i) {
          locals.emplace_back(n.args[0]->text, scalar(static_cast<double>(i), DefType::Int));
          Val term = eval(*n.args[2]);
          locals.pop_back();
          acc = i == 0 ? term : arith(n, "+", acc, term);
        }
        if (acc.t == DefType::Int && n.type == DefType::Float) acc.t = DefType::Float;
        return acc;
      }
      case DefNode::Index: {
        const DefNode& base = *n.args[0];
        int64_t i = integral(*n.args[1], eval(*n.args[1]), "index");
        if (base.kind == DefNode::Name && base.ref == DefNode::Semantic) {
          const SemanticDecl& d = rules.semantics[static_cast<size_t>(base.semantic)];
          if (!d.count.empty() || !d.arrayParam.empty()) {
            if (i < 0) fail(n, fmt::format("negative index {} into '{}'", i, d.name));
            Val v;
            if (!provided(base.semantic, i, v, &n))
              throw UndefinedSemantic(fmt::format("'{}[{}]' is not provided by the rig", d.name, i));
            return v;
          }
        }
        Val b = eval(base);
        int size = isMatT(b.t) ? (b.t == DefType::Mat3 ? 3 : 4) : defTypeComponents(b.t);
        if (i < 0 || i >= size) fail(n, fmt::format("index {} is out of range of a {}", i, defTypeName(b.t)));
        if (isMatT(b.t)) {
          dvec4 col = b.m[static_cast<int>(i)];
          if (b.t == DefType::Mat3) col.w = 0;
          return vec(col, vecType(size));
        }
        return scalar(b.m[0][static_cast<int>(i)]);
      }
      case DefNode::Swizzle: {
        Val b = eval(*n.args[0]);
        dvec4 x(0.0);
        for (size_t k = 0; k < n.text.size(); ++k) {
          char c = n.text[k];
          int i = c == 'x' || c == 'r' ? 0 : c == 'y' || c == 'g' ? 1 : c == 'z' || c == 'b' ? 2 : 3;
          x[static_cast<int>(k)] = b.m[0][i];
        }
        if (n.text.size() == 1) return scalar(x.x);
        return vec(x, vecType(static_cast<int>(n.text.size())));
      }
    }
    fail(n, "unknown node");
  }
};

Interpreter::Interpreter(const RuleSet& rules, const RigShape& shape, const rt::Mesh& mesh, const UniformValues& uniforms)
    : s_(std::make_unique<State>(rules, shape, mesh, uniforms)) {}

Interpreter::~Interpreter() = default;

int Interpreter::components(const std::string& semantic) const {
  return defTypeComponents(declType(s_->rules.semantics[static_cast<size_t>(s_->semanticIndex(semantic))].type));
}

std::string Interpreter::uncheckedReason(const std::string& semantic) {
  try {
    int sem = s_->semanticIndex(semantic);
    s_->vertex = s_->mesh.vertexCount ? 0 : kNoVertex;
    ++s_->stamp;
    s_->semantic(sem, nullptr);
  } catch (const UndefinedSemantic& e) {
    return e.what();
  }
  return "";
}

std::vector<std::vector<double>> Interpreter::evaluate(const std::vector<std::string>& semantics) {
  std::vector<int> idx;
  std::vector<int> comps;
  std::vector<std::vector<double>> out;
  for (const auto& name : semantics) {
    idx.push_back(s_->semanticIndex(name));
    comps.push_back(components(name));
    out.emplace_back(s_->mesh.vertexCount * static_cast<size_t>(comps.back()));
  }
  for (size_t v = 0; v < s_->mesh.vertexCount; ++v) {
    s_->vertex = v;
    ++s_->stamp;
    for (size_t k = 0; k < idx.size(); ++k) flatten(s_->semantic(idx[k], nullptr), out[k].data() + v * static_cast<size_t>(comps[k]));
  }
  return out;
}

std::vector<double> Interpreter::evaluateUniform(const std::string& semantic) {
  int sem = s_->semanticIndex(semantic);
  s_->vertex = kNoVertex;
  ++s_->stamp;
  std::vector<double> out(static_cast<size_t>(components(semantic)));
  flatten(s_->semantic(sem, nullptr), out.data());
  return out;
}

std::vector<std::string> Interpreter::inputsAt(const std::string& semantic, size_t vertex) {
  std::vector<std::string> out;
  s_->trace = &out;
  s_->traced.clear();
  s_->vertex = vertex;
  ++s_->stamp;
  try {
    s_->semantic(s_->semanticIndex(semantic), nullptr);
  } catch (...) {
    s_->trace = nullptr;
    throw;
  }
  s_->trace = nullptr;
  return out;
}

}  // namespace sg
