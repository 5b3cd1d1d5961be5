// Tree-walking evaluation of semantic definitions, one vertex at a time, with a per-vertex
// cache of every semantic already evaluated (outputs share their intermediates).
#include "validate/interpreter.h"

#include "validate/definition_program.h"
#include "validate/definition_values.h"

#include <fmt/format.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <utility>

namespace sg {

using namespace defval;

namespace {

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
  unsigned threads = 0;

  State(const RuleSet& r, const RigShape& sh, const rt::Mesh& m, const UniformValues& u)
      : rules(r), shape(sh), mesh(m), uniforms(u), cache(r.semantics.size()), cachedAt(r.semantics.size(), 0) {}

  int semanticIndex(const std::string& name) const {
    for (size_t i = 0; i < rules.semantics.size(); ++i)
      if (rules.semantics[i].name == name) return static_cast<int>(i);
    throw UndefinedSemantic(fmt::format("unknown semantic '{}'", name));
  }

  void record(const std::string& name, const Val& v) {
    if (trace && traced.insert(name).second) trace->push_back(name + " = " + showVal(v));
  }

  // Where a provided semantic instance lives, resolved once per (semantic, index).
  std::map<std::pair<int, int64_t>, Source> sources;

  const Source& sourceOf(int sem, int64_t index, const DefNode* at) {
    auto key = std::make_pair(sem, index);
    if (auto it = sources.find(key); it != sources.end()) return it->second;
    Source src = findSource(rules, mesh, uniforms, sem, index);
    if (!src.error.empty()) {
      if (at && src.outOfRange) fail(*at, src.error);
      throw std::invalid_argument(src.error);
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
      out = streamValue((*src.stream)[vertex], t);
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

  // Output arrays for `semantics` (and their indexes).
  std::vector<std::vector<double>> outputs(const std::vector<std::string>& semantics, std::vector<int>& idx) const {
    std::vector<std::vector<double>> out;
    for (const auto& name : semantics) {
      idx.push_back(semanticIndex(name));
      const auto n = static_cast<size_t>(defTypeComponents(declType(rules.semantics[static_cast<size_t>(idx.back())].type)));
      out.emplace_back(mesh.vertexCount * n);
    }
    return out;
  }

  // Tree-walks vertices [begin, end) into `out`.
  void walk(const std::vector<int>& idx, std::vector<std::vector<double>>& out, size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v) {
      vertex = v;
      ++stamp;
      for (size_t k = 0; k < idx.size(); ++k) {
        const size_t n = out[k].size() / std::max<size_t>(1, mesh.vertexCount);
        flatten(semantic(idx[k], nullptr), out[k].data() + v * n);
      }
    }
  }

  // A call on evaluated arguments; has() reads the rig, not values.
  Val callNode(const DefNode& n) {
    if (n.text == "has") {
      const std::string& name = n.args[0]->text;
      bool has = shape.provided.count(name) || shape.provided.count(indexedName(name, 0));
      return scalar(has ? 1.0 : 0.0, DefType::Bool);
    }
    // At most 4 arguments once checked (mat4 of 4 columns, vec4 of 4 scalars): no allocation.
    if (n.args.size() > 4) fail(n, fmt::format("'{}' has {} arguments", n.text, n.args.size()));
    Val a[4];
    for (size_t i = 0; i < n.args.size(); ++i) a[i] = eval(*n.args[i]);
    return call(n, a, n.args.size());
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
      case DefNode::Call: return callNode(n);
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
          return compare(op, a, b);
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
        int64_t count = integral(n, s(eval(*n.args[1])), "the count of sum()");
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
        int64_t i = integral(*n.args[1], s(eval(*n.args[1])), "index");
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
        return element(n, eval(base), i);
      }
      case DefNode::Swizzle: return swizzle(n.text, eval(*n.args[0]));
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

void Interpreter::setThreads(unsigned threads) { s_->threads = threads; }

std::vector<std::vector<double>> Interpreter::evaluate(const std::vector<std::string>& semantics) {
  return evaluator(semantics)();
}

std::function<std::vector<std::vector<double>>()> Interpreter::evaluator(const std::vector<std::string>& semantics) {
  std::vector<int> idx;
  std::vector<std::vector<double>> blank = s_->outputs(semantics, idx);
  std::shared_ptr<DefinitionProgram> program = DefinitionProgram::compile(s_->rules, s_->shape, s_->mesh, s_->uniforms, idx);
  return [this, idx, blank = std::move(blank), program] {
    std::vector<std::vector<double>> out = blank;
    if (!program) {
      s_->walk(idx, out, 0, s_->mesh.vertexCount);
      return out;
    }
    // Batches where a check failed: the tree walker throws the error it finds there.
    for (size_t b : program->run(out, s_->threads)) {
      const size_t first = b * DefinitionProgram::kBatch;
      s_->walk(idx, out, first, std::min(s_->mesh.vertexCount, first + DefinitionProgram::kBatch));
    }
    return out;
  };
}

std::vector<std::vector<double>> Interpreter::evaluateByTree(const std::vector<std::string>& semantics) {
  std::vector<int> idx;
  std::vector<std::vector<double>> out = s_->outputs(semantics, idx);
  s_->walk(idx, out, 0, s_->mesh.vertexCount);
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

std::optional<std::set<std::string>> definitionReadsOf(const RuleSet& rules, const std::string& semantic) {
  const SemanticDecl* d = rules.findSemantic(semantic);
  if (!d) return std::nullopt;
  std::set<std::string> seen;
  std::vector<const SemanticDecl*> todo{d};
  while (!todo.empty()) {
    const SemanticDecl* x = todo.back();
    todo.pop_back();
    if (!seen.insert(x->name).second || !x->definition) continue;
    for (int r : definitionReads(*x->definition)) todo.push_back(&rules.semantics[static_cast<size_t>(r)]);
  }
  return seen;
}

}  // namespace sg
