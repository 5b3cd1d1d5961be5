// libFuzzer: the integer expression parser and evaluator (when:, cost:, count:, ${...}).
// Identifiers a..e and the rig parameters have values (extremes included, to reach the
// overflow checks); has() is true for semantics starting with "vertex.".
#include "fuzz_util.h"
#include "rules/expr.h"

#include <cstdint>
#include <limits>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sg::ExprEnv env;
  env.lookup = [](const std::string& name, int64_t& v) {
    if (name == "bones") return v = 98, true;
    if (name == "influences") return v = 4, true;
    if (name == "morph_targets") return v = 5, true;
    if (name == "a") return v = std::numeric_limits<int64_t>::min(), true;
    if (name == "b") return v = std::numeric_limits<int64_t>::max(), true;
    if (name == "c") return v = -1, true;
    if (name == "d") return v = 0, true;
    if (name == "e") return v = 1 << 30, true;
    return false;
  };
  env.has = [](const std::string& s) { return s.rfind("vertex.", 0) == 0; };
  sg::fuzz::expectInputErrorsOnly([&] {
    sg::Expr e = sg::Expr::parse(sg::fuzz::text(data, size), sg::SourceLoc{"fuzz.rules.yaml", 1, 1});
    (void)e.eval(env);
  });
  return 0;
}
