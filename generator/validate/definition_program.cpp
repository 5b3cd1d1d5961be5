// The definition compiler and its batch evaluator. Arithmetic follows the tree walker's
// (GLM's order of operations for products, dot and cross), so both give the same doubles;
// tests/validate/test_definitions.cpp holds them to it.
#include "validate/definition_program.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <map>
#include <optional>
#include <thread>

#include "validate/definition_values.h"

namespace sg {

using namespace defval;

namespace {

constexpr size_t B = DefinitionProgram::kBatch;
constexpr size_t kMaxInstructions = 1 << 20;
constexpr int64_t kMaxUnroll = 1 << 16;

enum class Op : uint8_t {
  // d = a op b, component by component (a scalar operand is broadcast through its map)
  Add, Sub, Mul, Div, Min, Max, Lt, Le, Gt, Ge, Eq, Ne, And, Or,
  // d = op a
  Neg, Abs, Sqrt, Sign, Not, Copy,
  MulAdd,  // d = a * b + c (two roundings, as the Mul and Add it replaces)
  Select,  // d = a != 0 ? b : c
  Load,    // d = stream[vertex]
  Gather,  // d = element a of a uniform array or family (checked)
  Call,    // d = an operation evaluated vertex by vertex through defval (checked)
  Trap,    // a check that fails wherever the guard holds
  Output,  // out[extra][vertex] = a
};

// An operand: `base` is a register (varying: one component per vertex of the batch) or an
// offset into the constants; component c of the operand is component map[c] there.
struct Arg {
  uint32_t base = 0;
  bool varying = false;
  uint8_t map[16] = {};
};

struct Instr {
  Op op = Op::Copy;
  uint8_t n = 0;       // components written
  uint8_t dstOff = 0;  // first component of dst written
  bool guarded = false;
  uint8_t k = 0;       // Load: components read from the stream
  uint32_t dst = 0;    // register
  uint32_t extra = 0;  // Load: stream; Gather: table; Call: call site; Output: output index
  Arg a, b, c;
  Arg guard;  // checks fail only where it is non-zero (when guarded)
};

// Elements of a uniform array (one pose's values) or of a per-vertex family (streams).
struct Table {
  const double* uniform = nullptr;
  std::vector<const std::vector<glm::vec4>*> streams;
  size_t elements = 0;
  DefType t = DefType::Float;
};

struct CallSite {
  enum Kind { Function, Element, Arith } kind = Function;
  const DefNode* node = nullptr;
  DefType args[3] = {};
  int count = 0;
  std::string op;  // Arith
};

// Components of a stream value read as type t (the tree walker's streamValue, flattened).
int streamComponents(DefType t) { return t == DefType::Mat3 ? 3 : std::min(defTypeComponents(t), 4); }

}  // namespace

struct DefinitionProgram::Impl {
  std::vector<Instr> code;
  std::vector<double> constants;  // the first doubles of every workspace
  size_t workspace = 0;           // doubles per thread
  std::vector<const std::vector<glm::vec4>*> streams;
  std::vector<Table> tables;
  std::vector<CallSite> calls;
  std::vector<int> outComponents;
  size_t vertices = 0;
  Stats stats;

  bool runBatch(double* ws, size_t batch, std::vector<std::vector<double>>& out) const;
};

namespace {

struct NotCompilable {};

// A value while compiling: a constant (evaluated now), or components of a register.
struct Value {
  DefType t = DefType::Float;
  bool constant = true;
  Val val;
  uint32_t reg = 0;
  uint8_t map[16] = {};
  int n() const { return defTypeComponents(t); }
};

double apply(Op op, double x, double y) {
  switch (op) {
    case Op::Add: return x + y;
    case Op::Sub: return x - y;
    case Op::Mul: return x * y;
    case Op::Div: return x / y;
    case Op::Min: return std::min(x, y);
    case Op::Max: return std::max(x, y);
    case Op::Lt: return x < y ? 1.0 : 0.0;
    case Op::Le: return x <= y ? 1.0 : 0.0;
    case Op::Gt: return x > y ? 1.0 : 0.0;
    case Op::Ge: return x >= y ? 1.0 : 0.0;
    case Op::Eq: return x == y ? 1.0 : 0.0;
    case Op::Ne: return x != y ? 1.0 : 0.0;
    case Op::And: return x != 0 && y != 0 ? 1.0 : 0.0;
    case Op::Or: return x != 0 || y != 0 ? 1.0 : 0.0;
    default: return 0;
  }
}

double apply(Op op, double x) {
  switch (op) {
    case Op::Neg: return -x;
    case Op::Abs: return std::abs(x);
    case Op::Sqrt: return std::sqrt(x);
    case Op::Sign: return x > 0 ? 1.0 : x < 0 ? -1.0 : 0.0;
    case Op::Not: return x == 0 ? 1.0 : 0.0;
    default: return x;
  }
}

Op arithOp(const std::string& op) {
  return op == "+" ? Op::Add : op == "-" ? Op::Sub : op == "*" ? Op::Mul : Op::Div;  // as defval::arith
}

Op compareOp(const std::string& op) {
  return op == "==" ? Op::Eq : op == "!=" ? Op::Ne : op == "<" ? Op::Lt : op == ">" ? Op::Gt : op == "<=" ? Op::Le : Op::Ge;
}

bool isVecType(DefType t) { return t == DefType::Vec2 || t == DefType::Vec3 || t == DefType::Vec4; }
int matN(DefType t) { return t == DefType::Mat3 ? 3 : 4; }

class Compiler {
 public:
  Compiler(const RuleSet& rules, const RigShape& shape, const rt::Mesh& mesh, const UniformValues& uniforms,
           DefinitionProgram::Impl& p)
      : rules_(rules), shape_(shape), mesh_(mesh), uniforms_(uniforms), p_(p) {}

  void compile(const std::vector<int>& semantics) {
    for (size_t k = 0; k < semantics.size(); ++k) {
      Value v = semantic(semantics[k]);
      p_.outComponents.push_back(defTypeComponents(declType(rules_.semantics[static_cast<size_t>(semantics[k])].type)));
      Instr in;
      in.op = Op::Output;
      in.n = static_cast<uint8_t>(p_.outComponents.back());
      in.a = arg(v, in.n);
      in.extra = static_cast<uint32_t>(k);
      emit(in);
    }
    allocate();
  }

 private:
  // --- Values ---------------------------------------------------------------------------
  static Value konst(const Val& v) {
    Value r;
    r.t = v.t;
    r.val = v;
    return r;
  }
  static Value zero(DefType t) {
    Val v;
    v.t = t;
    return konst(v);
  }
  Value fresh(DefType t) {
    Value r;
    r.t = t;
    r.constant = false;
    r.reg = static_cast<uint32_t>(regSize_.size());
    regSize_.push_back(defTypeComponents(t));
    for (int c = 0; c < 16; ++c) r.map[c] = static_cast<uint8_t>(c);
    return r;
  }
  static Value retyped(Value v, DefType t) {
    v.t = t;
    if (v.constant) v.val.t = t;
    return v;
  }
  static Value floatish(const Value& v) { return v.t == DefType::Int ? retyped(v, DefType::Float) : v; }

  // Component sel[c] of v as component c of a value of type t: no instruction.
  static Value view(const Value& v, DefType t, const int* sel) {
    const int n = defTypeComponents(t);
    if (v.constant) {
      double f[16], g[16] = {};
      flatten(v.val, f);
      for (int c = 0; c < n; ++c) g[c] = f[sel[c]];
      return konst(unflatten(t, g));
    }
    Value r = v;
    r.t = t;
    for (int c = 0; c < n; ++c) r.map[c] = v.map[sel[c]];
    return r;
  }
  static Value component(const Value& v, int k) { return view(v, DefType::Float, &k); }
  static Value column(const Value& m, int k) {
    const int N = matN(m.t);
    int sel[4];
    for (int r = 0; r < N; ++r) sel[r] = k * N + r;
    return view(m, vecType(N), sel);
  }

  // The operand for an instruction reading n components (a one-component value broadcast),
  // or the components sel[c] of v when sel is given.
  Arg arg(const Value& v, int n, const int* sel = nullptr) {
    Arg a;
    int idx[16];
    for (int c = 0; c < n; ++c) idx[c] = sel ? sel[c] : (v.n() == 1 ? 0 : c);
    if (v.constant) {
      double f[16];
      flatten(v.val, f);
      a.base = static_cast<uint32_t>(p_.constants.size());
      p_.constants.insert(p_.constants.end(), f, f + v.n());
      for (int c = 0; c < n; ++c) a.map[c] = static_cast<uint8_t>(idx[c]);
    } else {
      a.base = v.reg;
      a.varying = true;
      for (int c = 0; c < n; ++c) a.map[c] = v.map[idx[c]];
    }
    return a;
  }

  void emit(Instr in) {
    if (guard_ && (in.op == Op::Trap || in.op == Op::Gather || in.op == Op::Call)) {
      in.guarded = true;
      in.guard = arg(*guard_, 1);
    }
    p_.code.push_back(in);
    if (p_.code.size() > kMaxInstructions) throw NotCompilable{};
  }

  // --- Checks -----------------------------------------------------------------------------
  // A check that fails on every vertex where the current guard holds; the value is a
  // placeholder (the batch is handed back).
  Value trap(DefType t) {
    Instr in;
    in.op = Op::Trap;
    emit(in);
    ++checked_;
    return zero(t);
  }
  template <class F>
  Value fold(DefType t, F f) {
    try {
      return konst(f());
    } catch (const std::invalid_argument&) {
      return trap(t);
    }
  }

  // A value valid where the guard holds and `c` (!c when negate) does.
  Value guardWith(const Value& c, bool negate) {
    Value g = negate ? unary(Op::Not, DefType::Bool, c) : c;
    return guard_ ? binary(Op::And, DefType::Bool, *guard_, g) : g;
  }
  template <class F>
  Value guarded(const Value& g, F f) {
    std::optional<Value> saved = guard_;
    guard_ = g;
    Value r = f();
    guard_ = saved;
    return r;
  }

  // --- Elementwise instructions ---------------------------------------------------------
  Value binary(Op op, DefType t, const Value& a, const Value& b, const int* selA = nullptr, const int* selB = nullptr) {
    const int n = defTypeComponents(t);
    if (a.constant && b.constant) {
      double x[16], y[16], r[16] = {};
      flatten(a.val, x);
      flatten(b.val, y);
      for (int c = 0; c < n; ++c)
        r[c] = apply(op, x[selA ? selA[c] : a.n() == 1 ? 0 : c], y[selB ? selB[c] : b.n() == 1 ? 0 : c]);
      return konst(unflatten(t, r));
    }
    Value d = fresh(t);
    Instr in;
    in.op = op;
    in.n = static_cast<uint8_t>(n);
    in.dst = d.reg;
    in.a = arg(a, n, selA);
    in.b = arg(b, n, selB);
    emit(in);
    return d;
  }
  Value unary(Op op, DefType t, const Value& a) {
    const int n = defTypeComponents(t);
    if (a.constant) {
      double x[16], r[16] = {};
      flatten(a.val, x);
      for (int c = 0; c < n; ++c) r[c] = apply(op, x[a.n() == 1 ? 0 : c]);
      return konst(unflatten(t, r));
    }
    Value d = fresh(t);
    Instr in;
    in.op = op;
    in.n = static_cast<uint8_t>(n);
    in.dst = d.reg;
    in.a = arg(a, n);
    emit(in);
    return d;
  }
  Value select(DefType t, const Value& c, const Value& a, const Value& b) {
    Value d = fresh(t);
    Instr in;
    in.op = Op::Select;
    in.n = static_cast<uint8_t>(d.n());
    in.dst = d.reg;
    in.a = arg(c, 1);
    in.b = arg(a, in.n);
    in.c = arg(b, in.n);
    emit(in);
    return d;
  }

  // A value of type t whose component c is component parts[c].second of parts[c].first:
  // a view when they all come from one register, else copies.
  Value gather(DefType t, const std::vector<std::pair<Value, int>>& parts) {
    const int n = defTypeComponents(t);
    bool allConstant = true, oneRegister = true;
    for (const auto& [v, c] : parts) {
      allConstant = allConstant && v.constant;
      oneRegister = oneRegister && !v.constant && v.reg == parts[0].first.reg;
    }
    if (allConstant) {
      double g[16] = {};
      for (int c = 0; c < n; ++c) {
        double f[16];
        flatten(parts[static_cast<size_t>(c)].first.val, f);
        g[c] = f[parts[static_cast<size_t>(c)].second];
      }
      return konst(unflatten(t, g));
    }
    if (oneRegister) {
      Value r = parts[0].first;
      r.t = t;
      for (int c = 0; c < n; ++c) r.map[c] = parts[static_cast<size_t>(c)].first.map[parts[static_cast<size_t>(c)].second];
      return r;
    }
    Value d = fresh(t);
    for (int c = 0; c < n;) {  // one copy per run of components from the same value
      const Value& v = parts[static_cast<size_t>(c)].first;
      int end = c + 1;
      auto same = [&](const Value& w) { return v.constant ? w.constant : (!w.constant && w.reg == v.reg); };
      while (end < n && same(parts[static_cast<size_t>(end)].first)) ++end;
      Instr in;
      in.op = Op::Copy;
      in.n = static_cast<uint8_t>(end - c);
      in.dstOff = static_cast<uint8_t>(c);
      in.dst = d.reg;
      if (v.constant) {
        in.a.base = static_cast<uint32_t>(p_.constants.size());
        for (int k = c; k < end; ++k) {
          double f[16];
          flatten(parts[static_cast<size_t>(k)].first.val, f);
          p_.constants.push_back(f[parts[static_cast<size_t>(k)].second]);
          in.a.map[k - c] = static_cast<uint8_t>(k - c);
        }
      } else {
        in.a.base = v.reg;
        in.a.varying = true;
        for (int k = c; k < end; ++k)
          in.a.map[k - c] = parts[static_cast<size_t>(k)].first.map[parts[static_cast<size_t>(k)].second];
      }
      emit(in);
      c = end;
    }
    return d;
  }

  // An operation evaluated vertex by vertex through defval (rare: no kernel of its own).
  Value perVertex(CallSite site, const std::vector<Value>& args, DefType t) {
    Value d = fresh(t);
    Instr in;
    in.op = Op::Call;
    in.n = static_cast<uint8_t>(d.n());
    in.dst = d.reg;
    Arg* slots[3] = {&in.a, &in.b, &in.c};
    for (size_t i = 0; i < args.size(); ++i) {
      *slots[i] = arg(args[i], args[i].n());
      site.args[i] = args[i].t;
    }
    site.count = static_cast<int>(args.size());
    in.extra = static_cast<uint32_t>(p_.calls.size());
    p_.calls.push_back(site);
    emit(in);
    ++checked_;
    ++p_.stats.perVertexCalls;
    return d;
  }

  // --- Products, in GLM's order of operations -------------------------------------------
  // Sum of terms[0] + terms[1] + ..., left to right, or ((0 + 1) + (2 + 3)) when paired.
  Value sum(DefType t, const std::vector<Value>& terms, bool paired) {
    if (paired && terms.size() == 4)
      return binary(Op::Add, t, binary(Op::Add, t, terms[0], terms[1]), binary(Op::Add, t, terms[2], terms[3]));
    Value acc = terms[0];
    for (size_t k = 1; k < terms.size(); ++k) acc = binary(Op::Add, t, acc, terms[k]);
    return acc;
  }
  Value matVec(const Value& m, const Value& v) {  // column k times v[k]
    const int N = matN(m.t);
    std::vector<Value> terms;
    for (int k = 0; k < N; ++k) terms.push_back(binary(Op::Mul, v.t, column(m, k), component(v, k)));
    return sum(v.t, terms, N == 4);
  }
  Value vecMat(const Value& v, const Value& m) {  // result[i] = sum over k of m[i][k] * v[k]
    const int N = matN(m.t);
    std::vector<Value> terms;
    for (int k = 0; k < N; ++k) {
      int sel[4];
      for (int i = 0; i < N; ++i) sel[i] = i * N + k;
      terms.push_back(binary(Op::Mul, v.t, m, component(v, k), sel));
    }
    return sum(v.t, terms, false);
  }
  Value matMat(const Value& a, const Value& b) {  // result[j][r] = sum over k of a[k][r] * b[j][k]
    const int N = matN(a.t);
    std::vector<Value> terms;
    for (int k = 0; k < N; ++k) {
      int selA[16], selB[16];
      for (int j = 0; j < N; ++j)
        for (int r = 0; r < N; ++r) {
          selA[j * N + r] = k * N + r;
          selB[j * N + r] = j * N + k;
        }
      terms.push_back(binary(Op::Mul, a.t, a, b, selA, selB));
    }
    return sum(a.t, terms, false);
  }
  Value dot(const Value& a, const Value& b) {  // GLM's: x + y + z, (x + y) + (z + w)
    Value p = binary(Op::Mul, a.t, a, b);
    const int n = a.n();
    Value xy = binary(Op::Add, DefType::Float, component(p, 0), component(p, 1));
    if (n == 2) return xy;
    if (n == 3) return binary(Op::Add, DefType::Float, xy, component(p, 2));
    return binary(Op::Add, DefType::Float, xy, binary(Op::Add, DefType::Float, component(p, 2), component(p, 3)));
  }

  // --- Arithmetic -------------------------------------------------------------------------
  Value arith(const DefNode& n, const std::string& op, Value a, Value b) {
    if (a.constant && b.constant) return fold(n.type, [&] { return defval::arith(n, op, a.val, b.val); });
    if (a.t == DefType::Int && b.t == DefType::Int) {
      if (op == "+" || op == "-" || op == "*") return binary(arithOp(op), DefType::Int, a, b);
      CallSite site;
      site.kind = CallSite::Arith;
      site.node = &n;
      site.op = op;
      return perVertex(site, {a, b}, DefType::Int);  // / and %: checked for division by zero
    }
    a = floatish(a);
    b = floatish(b);
    const Op o = arithOp(op);
    if (a.t == DefType::Float) return binary(o, b.t, a, b);
    if (b.t == DefType::Float) return binary(o, a.t, a, b);
    if (op == "*" && isMat(a.t) && isMat(b.t)) return matMat(a, b);
    if (op == "*" && isMat(a.t) && isVecType(b.t)) return matVec(a, b);
    if (op == "*" && isVecType(a.t) && isMat(b.t)) return vecMat(a, b);
    return binary(o, a.t, a, b);
  }

  Value call(const DefNode& n) {
    const std::string& f = n.text;
    if (f == "has") {
      const std::string& name = n.args[0]->text;
      bool has = shape_.provided.count(name) || shape_.provided.count(indexedName(name, 0));
      return konst(scalar(has ? 1.0 : 0.0, DefType::Bool));
    }
    if (n.args.size() > 4) return trap(n.type);
    std::vector<Value> a;
    bool constant = true;
    for (const auto& x : n.args) {
      a.push_back(compile(*x));
      constant = constant && a.back().constant;
    }
    if (constant)
      return fold(n.type, [&] {
        Val v[4];
        for (size_t i = 0; i < a.size(); ++i) v[i] = a[i].val;
        return defval::call(n, v, a.size());
      });
    for (auto& x : a) x = floatish(x);
    if (f == "dot") return dot(a[0], a[1]);
    if (f == "cross") {  // GLM: (x.y * y.z - y.y * x.z, x.z * y.x - y.z * x.x, x.x * y.y - y.x * x.y)
      const int yzx[3] = {1, 2, 0}, zxy[3] = {2, 0, 1};
      Value p = binary(Op::Mul, DefType::Vec3, a[0], a[1], yzx, zxy);
      Value q = binary(Op::Mul, DefType::Vec3, a[1], a[0], yzx, zxy);
      return binary(Op::Sub, DefType::Vec3, p, q);
    }
    if (f == "length") return unary(Op::Sqrt, DefType::Float, dot(a[0], a[0]));
    if (f == "normalize") return binary(Op::Div, a[0].t, a[0], unary(Op::Sqrt, DefType::Float, dot(a[0], a[0])));
    if (f == "abs") return unary(Op::Abs, a[0].t, a[0]);
    if (f == "sqrt") return unary(Op::Sqrt, a[0].t, a[0]);
    if (f == "sign") return unary(Op::Sign, a[0].t, a[0]);
    if (f == "float") return a[0];
    if (f == "min") return binary(Op::Min, a[0].t, a[0], a[1]);
    if (f == "max") return binary(Op::Max, a[0].t, a[0], a[1]);
    if (f == "clamp") return binary(Op::Min, a[0].t, binary(Op::Max, a[0].t, a[0], a[1]), a[2]);
    if (f == "transpose") {
      const int N = matN(a[0].t);
      int sel[16];
      for (int c = 0; c < N; ++c)
        for (int r = 0; r < N; ++r) sel[c * N + r] = r * N + c;
      return view(a[0], a[0].t, sel);
    }
    if (f == "mat3" || f == "mat4") {
      const int N = f == "mat3" ? 3 : 4;
      const DefType t = N == 3 ? DefType::Mat3 : DefType::Mat4;
      std::vector<std::pair<Value, int>> parts;
      const Value zero0 = konst(scalar(0.0)), one = konst(scalar(1.0));
      for (int c = 0; c < N; ++c)
        for (int r = 0; r < N; ++r) {
          if (a.size() == 1 && isScalar(a[0].t)) {
            parts.emplace_back(c == r ? a[0] : zero0, 0);
          } else if (a.size() == 1) {
            const int M = matN(a[0].t);
            if (c < M && r < M) parts.emplace_back(a[0], c * M + r);
            else parts.emplace_back(c == r ? one : zero0, 0);  // mat4(mat3): 1 on the diagonal
          } else {
            parts.emplace_back(a[static_cast<size_t>(c)], r);
          }
        }
      return gather(t, parts);
    }
    if (f == "vec2" || f == "vec3" || f == "vec4") {
      const int N = f[3] - '0';
      std::vector<std::pair<Value, int>> parts;
      if (a.size() == 1 && isScalar(a[0].t)) {
        for (int c = 0; c < N; ++c) parts.emplace_back(a[0], 0);
      } else {
        for (const auto& v : a)
          for (int c = 0; c < v.n(); ++c) parts.emplace_back(v, c);
      }
      return gather(vecType(N), parts);
    }
    CallSite site;  // inverse, determinant of a per-vertex matrix
    site.kind = CallSite::Function;
    site.node = &n;
    return perVertex(site, a, n.type);
  }

  // --- Semantics ----------------------------------------------------------------------------
  Value load(const std::vector<glm::vec4>* stream, DefType t) {
    auto key = std::make_pair(stream, t);
    if (auto it = loads_.find(key); it != loads_.end()) return it->second;
    Value d = fresh(t);
    Instr in;
    in.op = Op::Load;
    in.n = static_cast<uint8_t>(d.n());
    in.k = static_cast<uint8_t>(streamComponents(t));
    in.dst = d.reg;
    in.extra = static_cast<uint32_t>(p_.streams.size());
    p_.streams.push_back(stream);
    emit(in);
    return loads_.emplace(key, d).first->second;
  }

  // A provided semantic (element `index` of a family or array, -1 for none), or nothing.
  std::optional<Value> provided(int sem, int64_t index) {
    Source src = findSource(rules_, mesh_, uniforms_, sem, index);
    const DefType t = declType(rules_.semantics[static_cast<size_t>(sem)].type);
    if (!src.error.empty()) return trap(t);
    if (src.uniform) return konst(unflatten(t, src.uniform->data() + src.offset));
    if (src.stream) return load(src.stream, t);
    return std::nullopt;
  }

  Value semantic(int sem) {
    if (auto it = pure_.find(sem); it != pure_.end()) return it->second;
    const uint32_t guardKey = guard_ ? guard_->reg : UINT32_MAX;
    if (auto it = checkedMemo_.find({sem, guardKey}); it != checkedMemo_.end()) {
      ++checked_;  // what uses it depends on its checks too
      return it->second;
    }
    const SemanticDecl& d = rules_.semantics[static_cast<size_t>(sem)];
    const size_t before = checked_;
    Value v;
    if (std::optional<Value> p = provided(sem, -1)) {
      v = *p;
    } else if (!d.definition) {
      v = trap(declType(d.type));  // the tree walker throws UndefinedSemantic
    } else {
      auto saved = std::move(locals_);
      locals_.clear();
      v = compile(*d.definition);
      if (v.t == DefType::Int && declType(d.type) == DefType::Float) v = retyped(v, DefType::Float);
      locals_ = std::move(saved);
    }
    if (checked_ == before) return pure_.emplace(sem, v).first->second;
    return checkedMemo_.emplace(std::make_pair(sem, guardKey), v).first->second;
  }

  // An element of a family or uniform array at an index that depends on the vertex.
  Value indexed(int sem, const Value& index) {
    const SemanticDecl& d = rules_.semantics[static_cast<size_t>(sem)];
    Table table;
    table.t = declType(d.type);
    const size_t comps = static_cast<size_t>(defTypeComponents(table.t));
    if (auto u = uniforms_.find(d.name); u != uniforms_.end() && d.count.empty()) {
      table.uniform = u->second.data();
      table.elements = u->second.size() / comps;
    } else {
      for (int64_t i = 0; i < kMaxUnroll; ++i) {
        Source src = findSource(rules_, mesh_, uniforms_, sem, i);
        if (!src.stream || !src.error.empty()) break;
        table.streams.push_back(src.stream);
      }
      table.elements = table.streams.size();
    }
    Value dst = fresh(table.t);
    Instr in;
    in.op = Op::Gather;
    in.n = static_cast<uint8_t>(dst.n());
    in.dst = dst.reg;
    in.a = arg(index, 1);
    in.extra = static_cast<uint32_t>(p_.tables.size());
    p_.tables.push_back(std::move(table));
    emit(in);
    ++checked_;
    return dst;
  }

  Value index(const DefNode& n) {
    const DefNode& base = *n.args[0];
    const Value i = compile(*n.args[1]);
    int64_t at = 0;
    if (i.constant) {
      try {
        at = integral(*n.args[1], s(i.val), "index");
      } catch (const std::invalid_argument&) {
        return trap(n.type);
      }
    }
    if (base.kind == DefNode::Name && base.ref == DefNode::Semantic) {
      const SemanticDecl& d = rules_.semantics[static_cast<size_t>(base.semantic)];
      if (!d.count.empty() || !d.arrayParam.empty()) {
        if (!i.constant) return indexed(base.semantic, i);
        if (at < 0) return trap(n.type);
        if (std::optional<Value> v = provided(base.semantic, at)) return *v;
        return trap(n.type);  // not provided: the tree walker throws UndefinedSemantic
      }
    }
    const Value b = compile(base);
    if (!i.constant) {
      CallSite site;
      site.kind = CallSite::Element;
      site.node = &n;
      return perVertex(site, {b, i}, n.type);
    }
    if (b.constant) return fold(n.type, [&] { return element(n, b.val, at); });
    const int size = isMat(b.t) ? matN(b.t) : b.n();
    if (at < 0 || at >= size) return trap(n.type);
    return isMat(b.t) ? column(b, static_cast<int>(at)) : component(b, static_cast<int>(at));
  }

  Value compile(const DefNode& n) {
    switch (n.kind) {
      case DefNode::Num: return konst(scalar(n.value, n.integer ? DefType::Int : DefType::Float));
      case DefNode::Name: {
        if (n.ref == DefNode::Local) {
          for (auto it = locals_.rbegin(); it != locals_.rend(); ++it)
            if (it->first == n.text) return it->second;
          return trap(n.type);
        }
        if (n.ref == DefNode::Param) {
          auto p = shape_.params.find(n.text);
          if (p == shape_.params.end()) return trap(DefType::Int);
          return konst(scalar(static_cast<double>(p->second), DefType::Int));
        }
        if (n.semantic < 0) return trap(n.type);
        return semantic(n.semantic);
      }
      case DefNode::Call: return call(n);
      case DefNode::Unary: {
        Value a = compile(*n.args[0]);
        if (n.text == "!") return a.constant ? konst(scalar(s(a.val) == 0 ? 1.0 : 0.0, DefType::Bool)) : unary(Op::Not, DefType::Bool, a);
        if (a.constant) {
          Val r = a.val;
          r.m = -r.m;
          return konst(r);
        }
        return unary(Op::Neg, a.t, a);
      }
      case DefNode::Binary: {
        const std::string& op = n.text;
        if (op == "&&" || op == "||") {
          const bool isAnd = op == "&&";
          Value l = compile(*n.args[0]);
          if (l.constant) {
            const bool x = s(l.val) != 0;
            if (isAnd != x) return konst(scalar(x ? 1.0 : 0.0, DefType::Bool));  // decided by the left side
            Value r = compile(*n.args[1]);
            return binary(Op::Ne, DefType::Bool, r, konst(scalar(0.0)));
          }
          Value r = guarded(guardWith(l, !isAnd), [&] { return compile(*n.args[1]); });
          return binary(isAnd ? Op::And : Op::Or, DefType::Bool, l, r);
        }
        Value a = compile(*n.args[0]), b = compile(*n.args[1]);
        if (op == "==" || op == "!=" || op == "<" || op == ">" || op == "<=" || op == ">=") {
          if (a.constant && b.constant) return konst(compare(op, a.val, b.val));
          return binary(compareOp(op), DefType::Bool, component(a, 0), component(b, 0));
        }
        return arith(n, op, a, b);
      }
      case DefNode::Ternary: {
        Value c = compile(*n.args[0]);
        Value r;
        if (c.constant) {
          r = compile(*n.args[s(c.val) != 0 ? 1 : 2]);
        } else {
          Value x = guarded(guardWith(c, false), [&] { return compile(*n.args[1]); });
          Value y = guarded(guardWith(c, true), [&] { return compile(*n.args[2]); });
          r = select(n.type, c, x, y);
        }
        return r.t == DefType::Int && n.type == DefType::Float ? retyped(r, DefType::Float) : r;
      }
      case DefNode::Let: {
        locals_.emplace_back(n.text, compile(*n.args[0]));
        Value r = compile(*n.args[1]);
        locals_.pop_back();
        return r;
      }
      case DefNode::Sum: {
        Value count = compile(*n.args[1]);
        if (!count.constant) throw NotCompilable{};
        int64_t k = 0;
        try {
          k = integral(n, s(count.val), "the count of sum()");
        } catch (const std::invalid_argument&) {
          return trap(n.type);
        }
        if (k > kMaxUnroll) throw NotCompilable{};
        Value acc = zero(n.type);
        for (int64_t i = 0; i < k; ++i) {
          locals_.emplace_back(n.args[0]->text, konst(scalar(static_cast<double>(i), DefType::Int)));
          Value term = compile(*n.args[2]);
          locals_.pop_back();
          acc = i == 0 ? term : arith(n, "+", acc, term);
        }
        return acc.t == DefType::Int && n.type == DefType::Float ? retyped(acc, DefType::Float) : acc;
      }
      case DefNode::Index: return index(n);
      case DefNode::Swizzle: {
        Value b = compile(*n.args[0]);
        if (b.constant) return konst(swizzle(n.text, b.val));
        int sel[4];
        for (size_t k = 0; k < n.text.size(); ++k) sel[k] = swizzleComponent(n.text[k]);
        return view(b, n.text.size() == 1 ? DefType::Float : vecType(static_cast<int>(n.text.size())), sel);
      }
    }
    return trap(n.type);
  }

  // --- Registers --------------------------------------------------------------------------
  // Drops instructions whose result nothing reads (checks and outputs stay), then gives each
  // register a place in the workspace, reusing places whose register is no longer read.
  void allocate() {
    auto& code = p_.code;
    const size_t regs = regSize_.size();
    auto reads = [](const Instr& in, auto f) {
      for (const Arg* a : {&in.a, &in.b, &in.c})
        if (a->varying) f(a->base);
      if (in.guarded) f(in.guard.base);
    };
    fuseMultiplyAdds(reads);
    std::vector<char> live(regs, 0);
    std::vector<char> keep(code.size(), 0);
    for (size_t i = code.size(); i-- > 0;) {
      const Instr& in = code[i];
      const bool writes = in.op != Op::Output && in.op != Op::Trap;
      keep[i] = !writes || in.op == Op::Gather || in.op == Op::Call || live[in.dst];
      if (keep[i]) reads(in, [&](uint32_t r) { live[r] = 1; });
    }
    std::vector<Instr> kept;
    for (size_t i = 0; i < code.size(); ++i)
      if (keep[i]) kept.push_back(code[i]);
    code = std::move(kept);

    std::vector<size_t> last(regs, 0);
    for (size_t i = 0; i < code.size(); ++i) {
      reads(code[i], [&](uint32_t r) { last[r] = i; });
      if (code[i].op != Op::Output && code[i].op != Op::Trap) last[code[i].dst] = std::max(last[code[i].dst], i);
    }
    std::vector<int64_t> place(regs, -1);
    std::map<int, std::vector<size_t>> freePlaces;  // by component count
    size_t top = p_.constants.size();
    for (size_t i = 0; i < code.size(); ++i) {
      Instr& in = code[i];
      const bool writes = in.op != Op::Output && in.op != Op::Trap;
      if (writes && place[in.dst] < 0) {
        auto& pool = freePlaces[regSize_[in.dst]];
        if (pool.empty()) {
          place[in.dst] = static_cast<int64_t>(top);
          top += static_cast<size_t>(regSize_[in.dst]) * B;
        } else {
          place[in.dst] = static_cast<int64_t>(pool.back());
          pool.pop_back();
        }
      }
      auto release = [&](uint32_t r) {
        if (last[r] == i && place[r] >= 0) {
          freePlaces[regSize_[r]].push_back(static_cast<size_t>(place[r]));
          last[r] = SIZE_MAX;  // released once
        }
      };
      reads(in, release);
      if (writes) release(in.dst);
    }
    for (Instr& in : code) {
      for (Arg* a : {&in.a, &in.b, &in.c, &in.guard})
        if (a->varying) a->base = static_cast<uint32_t>(place[a->base]);
      if (in.op != Op::Output && in.op != Op::Trap) in.dst = static_cast<uint32_t>(place[in.dst]);
    }
    p_.workspace = top;
    p_.stats.instructions = code.size();
    p_.stats.constants = p_.constants.size();
    for (const Instr& in : code) p_.stats.checks += in.op == Op::Trap || in.op == Op::Gather || in.op == Op::Call;
  }

  // x + a * b where the product is read only there: one pass over the lanes instead of two.
  template <class Reads>
  void fuseMultiplyAdds(Reads reads) {
    auto& code = p_.code;
    std::vector<int> readCount(regSize_.size(), 0), writer(regSize_.size(), -1);
    for (size_t i = 0; i < code.size(); ++i) {
      reads(code[i], [&](uint32_t r) { ++readCount[r]; });
      const Instr& in = code[i];
      if (in.op != Op::Output && in.op != Op::Trap) writer[in.dst] = in.op == Op::Mul && in.dstOff == 0 && writer[in.dst] == -1 ? static_cast<int>(i) : -2;
    }
    std::vector<char> fused(code.size(), 0);
    for (Instr& in : code) {
      if (in.op != Op::Add) continue;
      for (Arg* side : {&in.b, &in.a}) {
        if (!side->varying || readCount[side->base] != 1 || writer[side->base] < 0) continue;
        const Instr& mul = code[static_cast<size_t>(writer[side->base])];
        bool whole = mul.n == in.n;
        for (int c = 0; c < in.n && whole; ++c) whole = side->map[c] == c;
        if (!whole) continue;
        const Arg other = side == &in.b ? in.a : in.b;
        fused[static_cast<size_t>(writer[side->base])] = 1;
        in.op = Op::MulAdd;
        in.a = mul.a;
        in.b = mul.b;
        in.c = other;
        break;
      }
    }
    std::vector<Instr> kept;
    for (size_t i = 0; i < code.size(); ++i)
      if (!fused[i]) kept.push_back(code[i]);
    code = std::move(kept);
  }

  const RuleSet& rules_;
  const RigShape& shape_;
  const rt::Mesh& mesh_;
  const UniformValues& uniforms_;
  DefinitionProgram::Impl& p_;
  std::vector<int> regSize_;
  std::vector<std::pair<std::string, Value>> locals_;
  std::optional<Value> guard_;
  size_t checked_ = 0;  // checks emitted or depended on so far
  std::map<int, Value> pure_;                                 // semantics with no checks
  std::map<std::pair<int, uint32_t>, Value> checkedMemo_;     // others, by guard
  std::map<std::pair<const std::vector<glm::vec4>*, DefType>, Value> loads_;
};

// --- Kernels ----------------------------------------------------------------------------

inline const double* at(const double* ws, const Arg& x, int c) { return ws + x.base + x.map[c] * (x.varying ? B : 1); }

// One component over the lanes of a batch; restrict parameters let the loops vectorize.
template <class F>
void lanes(double* __restrict d, const double* __restrict x, const double* __restrict y, F f) {
  for (size_t l = 0; l < B; ++l) d[l] = f(x[l], y[l]);
}
template <class F>
void lanesX(double* __restrict d, const double* __restrict x, double y, F f) {
  for (size_t l = 0; l < B; ++l) d[l] = f(x[l], y);
}
template <class F>
void lanesY(double* __restrict d, double x, const double* __restrict y, F f) {
  for (size_t l = 0; l < B; ++l) d[l] = f(x, y[l]);
}

template <class F>
void binaryKernel(double* ws, const Instr& in, F f) {
  for (int c = 0; c < in.n; ++c) {
    double* d = ws + in.dst + (in.dstOff + c) * B;
    const double* x = at(ws, in.a, c);
    const double* y = at(ws, in.b, c);
    if (in.a.varying && in.b.varying) lanes(d, x, y, f);
    else if (in.a.varying) lanesX(d, x, *y, f);
    else lanesY(d, *x, y, f);
  }
}

template <class F>
void unaryKernel(double* ws, const Instr& in, F f) {
  for (int c = 0; c < in.n; ++c) {
    double* d = ws + in.dst + (in.dstOff + c) * B;
    const double* x = at(ws, in.a, c);
    if (in.a.varying) lanesX(d, x, 0.0, [f](double v, double) { return f(v); });
    else lanesY(d, f(*x), x, [](double v, double) { return v; });
  }
}

template <size_t XS, size_t YS, size_t ZS>
void mulAddLanes(double* __restrict d, const double* __restrict x, const double* __restrict y, const double* __restrict z) {
  for (size_t l = 0; l < B; ++l) {
    const double p = x[l * XS] * y[l * YS];
    d[l] = p + z[l * ZS];
  }
}

void mulAddKernel(double* ws, const Instr& in) {
  using Fn = void (*)(double*, const double*, const double*, const double*);
  static constexpr Fn kinds[8] = {mulAddLanes<0, 0, 0>, mulAddLanes<0, 0, 1>, mulAddLanes<0, 1, 0>, mulAddLanes<0, 1, 1>,
                                  mulAddLanes<1, 0, 0>, mulAddLanes<1, 0, 1>, mulAddLanes<1, 1, 0>, mulAddLanes<1, 1, 1>};
  const Fn f = kinds[(in.a.varying ? 4 : 0) + (in.b.varying ? 2 : 0) + (in.c.varying ? 1 : 0)];
  for (int c = 0; c < in.n; ++c) f(ws + in.dst + (in.dstOff + c) * B, at(ws, in.a, c), at(ws, in.b, c), at(ws, in.c, c));
}

bool active(const double* ws, const Instr& in, size_t l) { return !in.guarded || at(ws, in.guard, 0)[l] != 0; }

}  // namespace

bool DefinitionProgram::Impl::runBatch(double* ws, size_t batch, std::vector<std::vector<double>>& out) const {
  const size_t first = batch * B, m = std::min(B, vertices - first);
  for (const Instr& in : code) {
    switch (in.op) {
      case Op::Add: binaryKernel(ws, in, [](double x, double y) { return x + y; }); break;
      case Op::Sub: binaryKernel(ws, in, [](double x, double y) { return x - y; }); break;
      case Op::Mul: binaryKernel(ws, in, [](double x, double y) { return x * y; }); break;
      case Op::Div: binaryKernel(ws, in, [](double x, double y) { return x / y; }); break;
      case Op::Min: binaryKernel(ws, in, [](double x, double y) { return y < x ? y : x; }); break;  // std::min
      case Op::Max: binaryKernel(ws, in, [](double x, double y) { return x < y ? y : x; }); break;  // std::max
      case Op::Lt: case Op::Le: case Op::Gt: case Op::Ge: case Op::Eq: case Op::Ne: case Op::And: case Op::Or:
        binaryKernel(ws, in, [op = in.op](double x, double y) { return apply(op, x, y); });
        break;
      case Op::Neg: unaryKernel(ws, in, [](double x) { return -x; }); break;
      case Op::Copy: unaryKernel(ws, in, [](double x) { return x; }); break;
      case Op::Abs: case Op::Sqrt: case Op::Sign: case Op::Not:
        unaryKernel(ws, in, [op = in.op](double x) { return apply(op, x); });
        break;
      case Op::MulAdd: mulAddKernel(ws, in); break;
      case Op::Select: {
        const double* cond = at(ws, in.a, 0);
        const size_t cs = in.a.varying ? 1 : 0;
        for (int c = 0; c < in.n; ++c) {
          double* d = ws + in.dst + static_cast<size_t>(c) * B;
          const double *x = at(ws, in.b, c), *y = at(ws, in.c, c);
          const size_t xs = in.b.varying ? 1 : 0, ys = in.c.varying ? 1 : 0;
          for (size_t l = 0; l < B; ++l) d[l] = cond[l * cs] != 0 ? x[l * xs] : y[l * ys];
        }
        break;
      }
      case Op::Load: {
        const glm::vec4* src = streams[in.extra]->data() + first;
        double* d = ws + in.dst;
        for (int c = in.k; c < in.n; ++c) std::fill(d + static_cast<size_t>(c) * B, d + static_cast<size_t>(c) * B + m, 0.0);
        // One pass over the stream (components beyond k are not the semantic's).
        if (in.k == 1) {
          for (size_t l = 0; l < m; ++l) d[l] = src[l].x;
        } else if (in.k == 2) {
          for (size_t l = 0; l < m; ++l) d[l] = src[l].x, d[B + l] = src[l].y;
        } else if (in.k == 3) {
          for (size_t l = 0; l < m; ++l) d[l] = src[l].x, d[B + l] = src[l].y, d[2 * B + l] = src[l].z;
        } else {
          for (size_t l = 0; l < m; ++l) d[l] = src[l].x, d[B + l] = src[l].y, d[2 * B + l] = src[l].z, d[3 * B + l] = src[l].w;
        }
        break;
      }
      case Op::Gather: {
        const Table& t = tables[in.extra];
        const double* index = at(ws, in.a, 0);
        const size_t is = in.a.varying ? 1 : 0;
        const int k = streamComponents(t.t);
        double* d = ws + in.dst;
        for (size_t l = 0; l < m; ++l) {
          const double x = index[l * is];
          size_t e = 0;
          if (x == std::floor(x) && x >= 0 && x < static_cast<double>(t.elements)) {
            e = static_cast<size_t>(x);
          } else {
            if (active(ws, in, l)) return false;  // the tree walker reports it
            if (t.elements == 0) continue;
          }
          if (t.uniform) {
            const double* v = t.uniform + e * in.n;
            for (int c = 0; c < in.n; ++c) d[static_cast<size_t>(c) * B + l] = v[c];
          } else {
            const glm::vec4& v = (*t.streams[e])[first + l];
            for (int c = 0; c < in.n; ++c) d[static_cast<size_t>(c) * B + l] = c < k ? v[c] : 0.0;
          }
        }
        break;
      }
      case Op::Call: {
        const CallSite& site = calls[in.extra];
        const Arg* args[3] = {&in.a, &in.b, &in.c};
        double* d = ws + in.dst;
        for (size_t l = 0; l < m; ++l) {
          Val v[3];
          for (int i = 0; i < site.count; ++i) {
            double f[16];
            const int n = defTypeComponents(site.args[i]);
            for (int c = 0; c < n; ++c) f[c] = at(ws, *args[i], c)[args[i]->varying ? l : 0];
            v[i] = unflatten(site.args[i], f);
          }
          double r[16] = {};
          try {
            Val x;
            if (site.kind == CallSite::Element) x = element(*site.node, v[0], integral(*site.node->args[1], s(v[1]), "index"));
            else if (site.kind == CallSite::Arith) x = defval::arith(*site.node, site.op, v[0], v[1]);
            else x = defval::call(*site.node, v, static_cast<size_t>(site.count));
            flatten(x, r);
          } catch (const std::invalid_argument&) {
            if (active(ws, in, l)) return false;
          }
          for (int c = 0; c < in.n; ++c) d[static_cast<size_t>(c) * B + l] = r[c];
        }
        break;
      }
      case Op::Trap:
        for (size_t l = 0; l < m; ++l)
          if (active(ws, in, l)) return false;
        break;
      case Op::Output: {
        const size_t n = in.n;
        double* o = out[in.extra].data() + first * n;
        for (size_t c = 0; c < n; ++c) {
          const double* x = at(ws, in.a, static_cast<int>(c));
          const size_t xs = in.a.varying ? 1 : 0;
          for (size_t l = 0; l < m; ++l) o[l * n + c] = x[l * xs];
        }
        break;
      }
    }
  }
  return true;
}

DefinitionProgram::DefinitionProgram(std::unique_ptr<Impl> impl) : p_(std::move(impl)) {}
DefinitionProgram::~DefinitionProgram() = default;

std::unique_ptr<DefinitionProgram> DefinitionProgram::compile(const RuleSet& rules, const RigShape& shape,
                                                              const rt::Mesh& mesh, const UniformValues& uniforms,
                                                              const std::vector<int>& semantics) {
  auto impl = std::make_unique<Impl>();
  impl->vertices = mesh.vertexCount;
  try {
    Compiler(rules, shape, mesh, uniforms, *impl).compile(semantics);
  } catch (const NotCompilable&) {
    return nullptr;
  }
  return std::unique_ptr<DefinitionProgram>(new DefinitionProgram(std::move(impl)));
}

DefinitionProgram::Stats DefinitionProgram::stats() const { return p_->stats; }

std::vector<size_t> DefinitionProgram::run(std::vector<std::vector<double>>& out, unsigned threads) const {
  const size_t batches = (p_->vertices + B - 1) / B;
  std::vector<char> ok(batches, 1);
  std::atomic<size_t> next{0};
  std::exception_ptr error;
  std::atomic<bool> failed{false};
  auto work = [&] {
    try {
      std::vector<double> ws(p_->workspace, 0.0);
      std::copy(p_->constants.begin(), p_->constants.end(), ws.begin());
      for (size_t b; !failed && (b = next++) < batches;) ok[b] = p_->runBatch(ws.data(), b, out);
    } catch (...) {
      if (!failed.exchange(true)) error = std::current_exception();
    }
  };
  size_t n = threads ? threads : std::max(1u, std::thread::hardware_concurrency());
  n = std::min(n, std::max<size_t>(1, batches / 4));  // a few batches per thread at least
  std::vector<std::thread> pool;
  for (size_t i = 1; i < n; ++i) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
  std::vector<size_t> redo;
  for (size_t b = 0; b < batches; ++b)
    if (!ok[b]) redo.push_back(b);
  return redo;
}

}  // namespace sg
