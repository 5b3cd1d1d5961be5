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
  std::string rigPath;          // YAML or MODEL.glb#M/P; "" = probe snippets against the default rigs
  bool compileSnippets = true;  // compile each snippet alone (and measure its cost)
  bool all = false;     // also report warnings and notes located in included files
  bool werror = false;  // warnings count as errors
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

// Warnings of one kind ("rule '…' is never used"), counted (`check` prints a summary).
struct FindingGroup {
  std::string kind;  // the message with quoted names replaced by '…'
  Severity severity = Severity::Warning;
  int count = 0;
};

struct CheckReport {
  std::vector<Diagnostic> findings;  // in the named files (all files with --all), by file, line, column
  std::vector<FindingGroup> groups;  // the shown warnings and notes by kind, most frequent first
  int hiddenWarnings = 0;            // warnings and notes in included files, not shown (no --all)
  bool werror = false;
  std::vector<CostRow> costs;        // in rule order
  int errors = 0;
  int warnings = 0;
  bool schemaError = false;  // a loader stopped at the first error
};

CheckReport checkRules(const CheckOptions& opts);

// Does a stated cost disagree with the measured one by more than a factor of two?
// (Differences of a single slot are tolerated so 0 vs 1 is not flagged.)
bool costsDisagree(int64_t stated, int64_t measured);

// Findings rendered with quoted lines and carets, then the warnings grouped by kind and
// "N errors, M warnings" (with -Werror, warnings are rendered and counted as errors).
std::string formatCheckReport(const CheckReport& r);
// The cost table: rule, rig, stated, measured.
std::string formatCostTable(const CheckReport& r);

}  // namespace sg
