// libFuzzer: the rules loader (YAML text → RuleSet, expressions and snippets included).
#include "fuzz_util.h"
#include "rules/rules.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sg::fuzz::expectInputErrorsOnly([&] {
    sg::RuleSet set;
    sg::loadRulesText(set, sg::fuzz::text(data, size), "fuzz.rules.yaml");
  });
  return 0;
}
