// `shadergen check`: static checks of rules files (docs/rules-authoring.md lists every
// finding). Schema errors stop at the first (the loaders throw); the semantic checks
// collect every finding, each located in a rules (or rig) file.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/diagnostics.h"

namespace sg {

struct CheckOptions {
  std::vector<std::string> rulesPaths;
  std::string rigPath;          // "" = probe snippets against the default rigs
  bool compileSnippets = true;  // compile each snippet alone (and measure its cost)
};

// One row of the stated-versus-measured cost table (`check --costs`).
struct CostRow {
  std::string rule;
  SourceLoc loc;
  std::string rig;                 // the rig the snippet was instantiated for ("" = not probed)
  bool isAuto = false;
  std::optional<int64_t> stated;   // evaluated `cost:` (none for auto)
  std::optional<int64_t> measured; // auto cost of the snippet (none if it did not compile)
  bool disagrees = false;          // differs by more than a factor of two
};

struct CheckReport {
  std::vector<Diagnostic> findings;  // sorted by file, line, column
  std::vector<CostRow> costs;        // in rule order
  int errors = 0;
  int warnings = 0;
  bool schemaError = false;  // a loader stopped at the first error
};

CheckReport checkRules(const CheckOptions& opts);

// Does a stated cost disagree with the measured one by more than a factor of two?
// (Differences of a single slot are tolerated so 0 vs 1 is not flagged.)
bool costsDisagree(int64_t stated, int64_t measured);

// Findings rendered with quoted lines and carets, then "N errors, M warnings".
std::string formatCheckReport(const CheckReport& r);
// The cost table: rule, rig, stated, measured.
std::string formatCostTable(const CheckReport& r);

}  // namespace sg
