#include "rules/expr.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <climits>
#include <vector>

namespace sg {

struct Expr::Node {
  enum Kind { Num, Name, Has, Unary, Binary } kind;
  int depth = 1;     // height of this subtree (evaluation recursion is bounded by it)
  int64_t value = 0;
  std::string text;  // name, semantic or operator
  int col = 0;       // 0-based column of the token within the expression
  std::shared_ptr<const Node> a, b;
};

namespace {

using NodeP = std::shared_ptr<const Expr::Node>;

class Parser {
 public:
  Parser(const std::string& s, const SourceLoc& loc) : s_(s), loc_(loc) {}
  NodeP parseAll() {
    if (s_.size() > kMaxExprChars)
      fail(0, fmt::format("expression is {} characters long, more than the limit of {}", s_.size(), kMaxExprChars));
    NodeP n = parseOr();
    skip();
    if (pos_ != s_.size()) fail(pos_, fmt::format("unexpected '{}' in expression", s_.substr(pos_, 1)));
    return n;
  }

 private:
  [[noreturn]] void fail(size_t at, const std::string& msg) {
    SourceLoc l = loc_;
    if (l.col > 0) l.col += static_cast<int>(at);
    throw InputError(l, msg);
  }
  void skip() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
  }
  bool eat(const char* op) {
    skip();
    size_t n = std::char_traits<char>::length(op);
    if (s_.compare(pos_, n, op) == 0) {
      // don't take '=' of '==' as '<' '=' etc.: callers try longer operators first
      pos_ += n;
      return true;
    }
    return false;
  }
  // Every node built checks the height of the tree below it: a chain `1+1+...` or
  // `((((...))))` deeper than kMaxExprDepth is refused instead of overflowing the stack.
  void checkDepth(Expr::Node& n, size_t at) {
    n.depth = 1 + std::max(n.a ? n.a->depth : 0, n.b ? n.b->depth : 0);
    if (n.depth > kMaxExprDepth) fail(at, fmt::format("expression is nested deeper than {} levels", kMaxExprDepth));
  }
  struct Nesting {  // recursion guard for parentheses and unary chains
    Parser& p;
    Nesting(Parser& p, size_t at) : p(p) {
      if (++p.nesting_ > kMaxExprDepth) p.fail(at, fmt::format("expression is nested deeper than {} levels", kMaxExprDepth));
    }
    ~Nesting() { --p.nesting_; }
  };
  NodeP bin(const char* op, NodeP a, NodeP b, size_t at) {
    auto n = std::make_shared<Expr::Node>();
    n->kind = Expr::Node::Binary;
    n->text = op;
    n->a = std::move(a);
    n->b = std::move(b);
    n->col = static_cast<int>(at);
    checkDepth(*n, at);
    return n;
  }
  // Position of the next token (an operator's column, not the blank before it).
  size_t next() {
    skip();
    return pos_;
  }
  NodeP parseOr() {
    NodeP l = parseAnd();
    for (size_t at = next(); eat("||"); at = next()) l = bin("||", l, parseAnd(), at);
    return l;
  }
  NodeP parseAnd() {
    NodeP l = parseCmp();
    for (size_t at = next(); eat("&&"); at = next()) l = bin("&&", l, parseCmp(), at);
    return l;
  }
  NodeP parseCmp() {
    NodeP l = parseAdd();
    for (;;) {
      size_t at = next();
      const char* ops[] = {"==", "!=", "<=", ">=", "<", ">"};
      const char* hit = nullptr;
      for (const char* op : ops)
        if (eat(op)) {
          hit = op;
          break;
        }
      if (!hit) return l;
      l = bin(hit, l, parseAdd(), at);
    }
  }
  NodeP parseAdd() {
    NodeP l = parseMul();
    for (;;) {
      size_t at = next();
      if (eat("+")) l = bin("+", l, parseMul(), at);
      else if (eat("-")) l = bin("-", l, parseMul(), at);
      else return l;
    }
  }
  NodeP parseMul() {
    NodeP l = parseUnary();
    for (;;) {
      size_t at = next();
      if (eat("*")) l = bin("*", l, parseUnary(), at);
      else if (eat("/")) l = bin("/", l, parseUnary(), at);
      else if (eat("%")) l = bin("%", l, parseUnary(), at);
      else return l;
    }
  }
  NodeP parseUnary() {
    skip();
    size_t at = pos_;
    Nesting guard(*this, at);
    if (s_.compare(pos_, 2, "!=") != 0 && eat("!")) {
      auto n = std::make_shared<Expr::Node>();
      n->kind = Expr::Node::Unary;
      n->text = "!";
      n->a = parseUnary();
      n->col = static_cast<int>(at);
      checkDepth(*n, at);
      return n;
    }
    if (eat("-")) {
      auto n = std::make_shared<Expr::Node>();
      n->kind = Expr::Node::Unary;
      n->text = "-";
      n->a = parseUnary();
      n->col = static_cast<int>(at);
      checkDepth(*n, at);
      return n;
    }
    return parsePrimary();
  }
  NodeP parsePrimary() {
    skip();
    size_t at = pos_;
    if (pos_ >= s_.size()) fail(pos_, "expression ends too early");
    char c = s_[pos_];
    if (c == '(') {
      ++pos_;
      NodeP n = parseOr();
      if (!eat(")")) fail(pos_, "expected ')'");
      return n;
    }
    auto n = std::make_shared<Expr::Node>();
    n->col = static_cast<int>(at);
    if (std::isdigit(static_cast<unsigned char>(c))) {
      int64_t v = 0;
      while (pos_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[pos_]))) {
        int d = s_[pos_] - '0';
        if (v > (INT64_MAX - d) / 10) fail(at, "number too large");
        v = v * 10 + d;
        ++pos_;
      }
      n->kind = Expr::Node::Num;
      n->value = v;
      return n;
    }
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      std::string id;
      while (pos_ < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '_')) id += s_[pos_++];
      if (id == "true" || id == "false") {
        n->kind = Expr::Node::Num;
        n->value = id == "true";
        return n;
      }
      if (id == "has") {
        if (!eat("(")) fail(pos_, "expected '(' after has");
        skip();
        std::string sem;
        while (pos_ < s_.size() && s_[pos_] != ')' && !std::isspace(static_cast<unsigned char>(s_[pos_]))) sem += s_[pos_++];
        if (sem.empty()) fail(pos_, "has() needs a semantic name");
        if (!eat(")")) fail(pos_, "expected ')' after the semantic in has()");
        n->kind = Expr::Node::Has;
        n->text = sem;
        return n;
      }
      n->kind = Expr::Node::Name;
      n->text = id;
      return n;
    }
    fail(at, fmt::format("unexpected '{}' in expression", std::string(1, c)));
  }

  const std::string& s_;
  SourceLoc loc_;
  size_t pos_ = 0;
  int nesting_ = 0;
};

int64_t evalNode(const Expr::Node& n, const ExprEnv& env, const SourceLoc& loc) {
  auto failAt = [&](int col, const std::string& msg) -> int64_t {
    SourceLoc l = loc;
    if (l.col > 0) l.col += col;
    throw InputError(l, msg);
  };
  switch (n.kind) {
    case Expr::Node::Num:
      return n.value;
    case Expr::Node::Name: {
      int64_t v = 0;
      if (env.lookup && env.lookup(n.text, v)) return v;
      return failAt(n.col, fmt::format("unknown name '{}' in expression", n.text));
    }
    case Expr::Node::Has:
      return env.has && env.has(n.text) ? 1 : 0;
    case Expr::Node::Unary: {
      int64_t a = evalNode(*n.a, env, loc);
      if (n.text == "!") return !a;
      if (a == INT64_MIN) return failAt(n.col, "integer overflow in expression (-INT64_MIN)");
      return -a;
    }
    case Expr::Node::Binary: {
      const std::string& op = n.text;
      int64_t a = evalNode(*n.a, env, loc);
      if (op == "&&" && !a) return 0;
      if (op == "||" && a) return 1;
      int64_t b = evalNode(*n.b, env, loc);
      if (op == "&&" || op == "||") return b != 0;
      // Checked: a wrapped value would be undefined behaviour and could land in the GLSL.
      int64_t r = 0;
      auto overflow = [&]() -> int64_t {
        return failAt(n.col, fmt::format("integer overflow in expression ({} {} {})", a, op, b));
      };
      if (op == "+") return __builtin_add_overflow(a, b, &r) ? overflow() : r;
      if (op == "-") return __builtin_sub_overflow(a, b, &r) ? overflow() : r;
      if (op == "*") return __builtin_mul_overflow(a, b, &r) ? overflow() : r;
      if (op == "/" || op == "%") {
        if (b == 0) return failAt(n.col, "division by zero in expression");
        if (a == INT64_MIN && b == -1) {
          if (op == "%") return 0;
          return overflow();
        }
        return op == "/" ? a / b : a % b;
      }
      if (op == "==") return a == b;
      if (op == "!=") return a != b;
      if (op == "<") return a < b;
      if (op == "<=") return a <= b;
      if (op == ">") return a > b;
      if (op == ">=") return a >= b;
      return 0;
    }
  }
  return 0;
}

// Whether the subtree has no names and no has(); the first always-evaluated constant part
// that fails goes to `found`. Recursion is bounded by the parse (kMaxExprDepth).
bool constantPart(const Expr::Node& n, bool always, const SourceLoc& loc, std::optional<Diagnostic>& found) {
  bool constant = n.kind == Expr::Node::Num;
  if (n.kind == Expr::Node::Unary) constant = constantPart(*n.a, always, loc, found);
  if (n.kind == Expr::Node::Binary) {
    const bool shortCircuit = n.text == "&&" || n.text == "||";
    bool a = constantPart(*n.a, always, loc, found);
    bool b = constantPart(*n.b, always && !shortCircuit, loc, found);
    constant = a && b;
  }
  if (constant && always && !found) {
    try {
      evalNode(n, ExprEnv{}, loc);
    } catch (const InputError& e) {
      found = e.diagnostic();
    }
  }
  return constant;
}

}  // namespace

std::optional<Diagnostic> Expr::failsForEveryRig() const {
  std::optional<Diagnostic> found;
  if (root_) constantPart(*root_, true, loc_, found);
  return found;
}

Expr Expr::parse(const std::string& text, const SourceLoc& loc) {
  Expr e;
  e.text_ = text;
  e.loc_ = loc;
  Parser p(text, loc);
  e.root_ = p.parseAll();
  return e;
}

int64_t Expr::eval(const ExprEnv& env) const {
  if (!root_) return 0;
  return evalNode(*root_, env, loc_);
}

}  // namespace sg
