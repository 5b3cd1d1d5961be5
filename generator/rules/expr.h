// Integer expressions used by rules (`when:`, `cost:`, semantic `count:`, snippet `${...}`
// and `@for`/`@if`): literals, identifiers (rig parameters, loop variables),
// has(semantic), + - * / % comparisons && || ! and parentheses.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "common/diagnostics.h"

namespace sg {

// Limits (docs/limits.md): longer or deeper expressions are refused when parsed.
constexpr size_t kMaxExprChars = 4096;
constexpr int kMaxExprDepth = 64;

struct ExprEnv {
  // Value of an identifier, or nullopt-like false return if unknown.
  std::function<bool(const std::string& name, int64_t& value)> lookup;
  // has(semantic): does the rig provide it (or any instance of an array semantic)?
  std::function<bool(const std::string& semantic)> has;
};

class Expr {
 public:
  Expr() = default;
  // Parses `text`; `loc` is where text starts in its file (errors point inside it).
  static Expr parse(const std::string& text, const SourceLoc& loc);
  // Throws InputError (unknown name, division by zero, 64-bit overflow).
  int64_t eval(const ExprEnv& env) const;
  // The error every rig gets: a part without names or has() that is always evaluated (not
  // the right side of && or ||) and fails (overflow, division by zero). nullopt if none.
  std::optional<Diagnostic> failsForEveryRig() const;
  const std::string& text() const { return text_; }
  bool empty() const { return !root_; }
  struct Node;

 private:
  std::string text_;
  SourceLoc loc_;
  std::shared_ptr<const Node> root_;
};

}  // namespace sg
