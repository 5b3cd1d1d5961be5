#include "validate/definition_values.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sg::defval {

using glm::dmat3;
using glm::dmat4;
using glm::dvec3;
using glm::dvec4;

namespace {

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
bool isVecT(DefType t) { return t == DefType::Vec2 || t == DefType::Vec3 || t == DefType::Vec4; }

}  // namespace

Val scalar(double x, DefType t) {
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

bool isMat(DefType t) { return t == DefType::Mat3 || t == DefType::Mat4; }
bool isScalar(DefType t) { return t == DefType::Int || t == DefType::Float || t == DefType::Bool; }
DefType vecType(int n) { return n == 2 ? DefType::Vec2 : n == 3 ? DefType::Vec3 : DefType::Vec4; }

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

void fail(const DefNode& n, const std::string& msg) {
  std::string where = n.loc.line ? fmt::format("{}:{}:{}: ", n.loc.file, n.loc.line, n.loc.col) : "";
  throw std::invalid_argument(where + msg);
}

int64_t integral(const DefNode& n, double x, const char* what) {
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
  auto apply = [&](double x, double y) { return op == "+" ? x + y : op == "-" ? x - y : op == "*" ? x * y : x / y; };
  auto each = [&](const Val& x, auto f) {
    Val r;
    r.t = x.t;
    int cols = x.t == DefType::Mat3 ? 3 : x.t == DefType::Mat4 ? 4 : 1;
    int rows = isMat(x.t) ? cols : defTypeComponents(x.t);
    for (int c = 0; c < cols; ++c)
      for (int k = 0; k < rows; ++k) r.m[c][k] = f(x.m[c][k], c, k);
    return r;
  };
  if (a.t == DefType::Float && b.t == DefType::Float) return scalar(apply(s(a), s(b)));
  if (a.t == DefType::Float) return each(b, [&](double y, int, int) { return apply(s(a), y); });
  if (b.t == DefType::Float) return each(a, [&](double x, int, int) { return apply(x, s(b)); });
  if (op == "*" && isMat(a.t) && isMat(b.t)) return a.t == DefType::Mat3 ? mat3v(m3(a) * m3(b)) : mat4v(a.m * b.m);
  if (op == "*" && isMat(a.t) && isVecT(b.t))
    return a.t == DefType::Mat3 ? vec(dvec4(m3(a) * dvec3(b.m[0]), 0.0), b.t) : vec(a.m * b.m[0], b.t);
  if (op == "*" && isVecT(a.t) && isMat(b.t))
    return b.t == DefType::Mat3 ? vec(dvec4(dvec3(a.m[0]) * m3(b), 0.0), a.t) : vec(a.m[0] * b.m, a.t);
  return each(a, [&](double x, int c, int k) { return apply(x, b.m[c][k]); });
}

Val compare(const std::string& op, const Val& a, const Val& b) {
  double x = s(a), y = s(b);
  bool r = op == "==" ? x == y : op == "!=" ? x != y : op == "<" ? x < y : op == ">" ? x > y : op == "<=" ? x <= y : x >= y;
  return scalar(r ? 1.0 : 0.0, DefType::Bool);
}

Val call(const DefNode& n, Val* a, size_t count) {
  const std::string& f = n.text;
  for (size_t i = 0; i < count; ++i)
    if (a[i].t == DefType::Int) a[i].t = DefType::Float;
  auto v3 = [](const Val& v) { return dvec3(v.m[0]); };
  auto perComp = [&](const Val& v, double (*g)(double)) {
    Val r = v;
    for (int c = 0; c < defTypeComponents(v.t); ++c) r.m[0][c] = g(v.m[0][c]);
    return r;
  };
  // Over the vector's own components (GLM's order: x + y + z, (x + y) + (z + w)).
  auto dot = [](const Val& x, const Val& y) {
    const int size = defTypeComponents(x.t);
    return size == 2 ? glm::dot(glm::dvec2(x.m[0]), glm::dvec2(y.m[0]))
           : size == 3 ? glm::dot(dvec3(x.m[0]), dvec3(y.m[0]))
                    : glm::dot(x.m[0], y.m[0]);
  };
  if (f == "dot") return scalar(dot(a[0], a[1]));
  if (f == "cross") return vec(dvec4(glm::cross(v3(a[0]), v3(a[1])), 0.0), DefType::Vec3);
  if (f == "length") return scalar(std::sqrt(dot(a[0], a[0])));
  if (f == "normalize") {
    double len = std::sqrt(dot(a[0], a[0]));
    Val r = a[0];  // a zero vector gives NaN, as normalize() in GLSL
    for (int c = 0; c < defTypeComponents(r.t); ++c) r.m[0][c] /= len;
    return r;
  }
  if (f == "abs") return perComp(a[0], [](double x) { return std::abs(x); });
  if (f == "sqrt") return perComp(a[0], [](double x) { return std::sqrt(x); });
  if (f == "sign") return perComp(a[0], [](double x) { return x > 0 ? 1.0 : x < 0 ? -1.0 : 0.0; });
  if (f == "float") return a[0];
  if (f == "min" || f == "max" || f == "clamp") {
    Val r = a[0];
    for (int c = 0; c < defTypeComponents(r.t); ++c) {
      auto arg = [&](size_t i) { return isScalar(a[i].t) ? s(a[i]) : a[i].m[0][c]; };
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
    if (count == 1 && isScalar(a[0].t)) return three ? mat3v(dmat3(s(a[0]))) : mat4v(dmat4(s(a[0])));
    if (count == 1) {
      if (three) return mat3v(m3(a[0]));
      if (a[0].t == DefType::Mat3) return mat4v(dmat4(m3(a[0])));
      return a[0];
    }
    Val r;
    r.t = three ? DefType::Mat3 : DefType::Mat4;
    const int rows = three ? 3 : 4;
    for (size_t c = 0; c < count; ++c)
      for (int k = 0; k < rows; ++k) r.m[static_cast<int>(c)][k] = a[c].m[0][k];
    return r;
  }
  if (f == "vec2" || f == "vec3" || f == "vec4") {
    const int N = f[3] - '0';
    dvec4 x(0.0);
    if (count == 1 && isScalar(a[0].t)) {
      for (int c = 0; c < N; ++c) x[c] = s(a[0]);
      return vec(x, vecType(N));
    }
    int k = 0;
    for (size_t i = 0; i < count; ++i)
      for (int c = 0; c < defTypeComponents(a[i].t); ++c) x[k++] = a[i].m[0][c];
    return vec(x, vecType(N));
  }
  fail(n, fmt::format("unknown function '{}'", f));
}

Val element(const DefNode& n, const Val& b, int64_t i) {
  int size = isMat(b.t) ? (b.t == DefType::Mat3 ? 3 : 4) : defTypeComponents(b.t);
  if (i < 0 || i >= size) fail(n, fmt::format("index {} is out of range of a {}", i, defTypeName(b.t)));
  if (isMat(b.t)) {
    dvec4 col = b.m[static_cast<int>(i)];
    if (b.t == DefType::Mat3) col.w = 0;
    return vec(col, vecType(size));
  }
  return scalar(b.m[0][static_cast<int>(i)]);
}

int swizzleComponent(char c) { return c == 'x' || c == 'r' ? 0 : c == 'y' || c == 'g' ? 1 : c == 'z' || c == 'b' ? 2 : 3; }

Val swizzle(const std::string& letters, const Val& b) {
  dvec4 x(0.0);
  for (size_t k = 0; k < letters.size(); ++k) x[static_cast<int>(k)] = b.m[0][swizzleComponent(letters[k])];
  if (letters.size() == 1) return scalar(x.x);
  return vec(x, vecType(static_cast<int>(letters.size())));
}

Source findSource(const RuleSet& rules, const rt::Mesh& mesh, const UniformValues& uniforms, int sem, int64_t index) {
  const SemanticDecl& d = rules.semantics[static_cast<size_t>(sem)];
  const size_t n = static_cast<size_t>(defTypeComponents(declType(d.type)));
  Source src;
  src.name = index >= 0 ? fmt::format("{}[{}]", d.name, index) : d.name;
  auto u = uniforms.find(d.name);
  if (u != uniforms.end() && !(index >= 0 && !d.count.empty())) {  // families are per-vertex
    size_t off = index >= 0 ? static_cast<size_t>(index) * n : 0;
    if (off + n > u->second.size()) {
      src.error = fmt::format("index {} is out of range of '{}' ({} elements)", index, d.name, u->second.size() / n);
      src.outOfRange = true;
      return src;
    }
    src.uniform = &u->second;
    src.offset = off;
  } else if (auto m = mesh.streams.find(src.name); m != mesh.streams.end()) {
    if (m->second.size() != mesh.vertexCount) {
      src.error = fmt::format("stream {} of mesh '{}' has {} values for {} vertices", src.name, mesh.name,
                              m->second.size(), mesh.vertexCount);
      return src;
    }
    src.stream = &m->second;
  }
  return src;
}

Val streamValue(const glm::vec4& x, DefType t) {
  if (t == DefType::Int || t == DefType::Float) return scalar(x.x, t);
  Val v = vec(dvec4(x), t);
  for (int c = defTypeComponents(t); c < 4; ++c) v.m[0][c] = 0;  // a vec3 stream's w is not part of it
  return v;
}

}  // namespace sg::defval
