#include "rules/snippet.h"

#include <fmt/format.h>

namespace sg {
namespace {

std::string trim(const std::string& s) {
  size_t b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  size_t e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

class Expander {
 public:
  Expander(const std::vector<TemplateLine>& lines, const SnippetContext& ctx) : lines_(lines), ctx_(ctx) {
    env_.has = ctx.rigEnv.has;
    env_.lookup = [this](const std::string& n, int64_t& v) {
      for (auto it = vars_.rbegin(); it != vars_.rend(); ++it)
        if (it->first == n) {
          v = it->second;
          return true;
        }
      return ctx_.rigEnv.lookup && ctx_.rigEnv.lookup(n, v);
    };
  }

  std::vector<ExpandedLine> run() {
    size_t end = block(0, true, nullptr);
    if (end != lines_.size()) fail(lines_[end], 0, "'@end' without a matching '@for' or '@if'");
    return std::move(out_);
  }

 private:
  [[noreturn]] void fail(const TemplateLine& l, size_t col, const std::string& msg) {
    SourceLoc loc = l.loc;
    if (loc.col > 0) loc.col += static_cast<int>(col);
    throw InputError(loc, msg);
  }

  SourceLoc exprLoc(const TemplateLine& l, size_t col) {
    SourceLoc loc = l.loc;
    if (loc.col > 0) loc.col += static_cast<int>(col);
    return loc;
  }

  // Processes lines from i until '@end'/'@else' (or the end); emits when `emit`.
  // Returns the index of the terminating directive (or lines_.size()).
  size_t block(size_t i, bool emit, std::string* terminator) {
    while (i < lines_.size()) {
      const TemplateLine& l = lines_[i];
      std::string t = trim(l.text);
      size_t ind = l.text.find_first_not_of(" \t");
      if (t == "@end" || t == "@else") {
        if (terminator) *terminator = t;
        return i;
      }
      if (t.rfind("@for ", 0) == 0) {
        // @for VAR in EXPR
        std::string rest = trim(t.substr(5));
        size_t sp = rest.find(' ');
        std::string var = rest.substr(0, sp);
        std::string tail = sp == std::string::npos ? "" : trim(rest.substr(sp));
        if (var.empty() || tail.rfind("in ", 0) != 0) fail(l, ind, "expected '@for VAR in COUNT'");
        std::string countText = trim(tail.substr(3));
        size_t countCol = ind + l.text.substr(ind).find(countText, 5);
        int64_t count = emit ? Expr::parse(countText, exprLoc(l, countCol)).eval(env_) : 0;
        if (count < 0 || count > 4096) fail(l, countCol, fmt::format("loop count {} is out of range 0..4096", count));
        size_t bodyStart = i + 1;
        size_t end = bodyStart;
        std::string term;
        if (count == 0 || !emit) {
          end = block(bodyStart, false, &term);
        } else {
          for (int64_t k = 0; k < count; ++k) {
            // Nested loops multiply: bound the total work, not just each count.
            if (++iterations_ > kMaxSnippetIterations)
              fail(l, ind, fmt::format("'@for' loops unroll more than {} iterations in total", kMaxSnippetIterations));
            vars_.emplace_back(var, k);
            end = block(bodyStart, true, &term);
            vars_.pop_back();
          }
        }
        if (end >= lines_.size()) fail(l, ind, "'@for' without '@end'");
        if (term != "@end") fail(lines_[end], 0, "'@else' inside '@for'");
        i = end + 1;
        continue;
      }
      if (t.rfind("@if ", 0) == 0) {
        std::string condText = trim(t.substr(4));
        size_t condCol = ind + l.text.substr(ind).find(condText, 3);
        bool cond = emit && Expr::parse(condText, exprLoc(l, condCol)).eval(env_) != 0;
        std::string term;
        size_t end = block(i + 1, emit && cond, &term);
        if (end >= lines_.size()) fail(l, ind, "'@if' without '@end'");
        if (term == "@else") {
          end = block(end + 1, emit && !cond, &term);
          if (end >= lines_.size() || term != "@end") fail(l, ind, "'@if' without '@end'");
        }
        i = end + 1;
        continue;
      }
      if (!t.empty() && t[0] == '@') fail(l, ind, fmt::format("unknown directive '{}'", t.substr(0, t.find(' '))));
      if (emit) {
        out_.push_back(ExpandedLine{substitute(l), l.loc});
        bytes_ += out_.back().text.size() + 1;
        if (out_.size() > kMaxSnippetLines || bytes_ > kMaxSnippetBytes)
          fail(l, ind == std::string::npos ? 0 : ind,
               fmt::format("the snippet unrolls to more than {} lines or {} bytes", kMaxSnippetLines, kMaxSnippetBytes));
      }
      ++i;
    }
    return i;
  }

  std::string substitute(const TemplateLine& l) {
    std::string out;
    const std::string& s = l.text;
    size_t i = 0;
    while (i < s.size()) {
      size_t open = s.find("${", i);
      if (open == std::string::npos) {
        out += s.substr(i);
        break;
      }
      out += s.substr(i, open - i);
      size_t close = s.find('}', open);
      if (close == std::string::npos) fail(l, open, "unterminated '${'");
      std::string inner = trim(s.substr(open + 2, close - open - 2));
      size_t innerCol = open + 2 + s.substr(open + 2).find_first_not_of(" \t");
      if (inner.empty()) fail(l, open, "empty '${}'");
      out += resolve(l, inner, innerCol);
      i = close + 1;
    }
    return out;
  }

  std::string resolve(const TemplateLine& l, const std::string& inner, size_t col) {
    if (inner == "out") return ctx_.outText;
    std::string name = inner;
    int64_t index = -1;
    size_t lb = inner.find('[');
    if (lb != std::string::npos && inner.back() == ']') {
      name = trim(inner.substr(0, lb));
      std::string idx = inner.substr(lb + 1, inner.size() - lb - 2);
      index = -2;  // parsed below only if `name` is a semantic
      std::string text;
      SourceLoc at = exprLoc(l, col);
      int64_t v = Expr::parse(idx, exprLoc(l, col + lb + 1)).eval(env_);
      if (ctx_.semantic && ctx_.semantic(name, v, at, text)) return text;
      fail(l, col, fmt::format("'{}' is not a semantic", name));
    }
    std::string text;
    if (name.find('.') != std::string::npos) {
      if (ctx_.semantic && ctx_.semantic(name, index, exprLoc(l, col), text)) return text;
      fail(l, col, fmt::format("unknown semantic '{}'", name));
    }
    return std::to_string(Expr::parse(inner, exprLoc(l, col)).eval(env_));
  }

  const std::vector<TemplateLine>& lines_;
  const SnippetContext& ctx_;
  ExprEnv env_;
  std::vector<std::pair<std::string, int64_t>> vars_;
  std::vector<ExpandedLine> out_;
  size_t bytes_ = 0;
  int64_t iterations_ = 0;
};

}  // namespace

std::vector<ExpandedLine> expandSnippet(const std::vector<TemplateLine>& lines, const SnippetContext& ctx) {
  return Expander(lines, ctx).run();
}

}  // namespace sg
