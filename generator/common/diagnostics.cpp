#include "common/diagnostics.h"

#include <fmt/format.h>

#include <fstream>

namespace sg {

InputError::InputError(Diagnostic d) : std::runtime_error(formatDiagnostic(d)), diag_(std::move(d)) {}
InputError::InputError(SourceLoc loc, const std::string& message)
    : InputError(Diagnostic{Severity::Error, std::move(loc), message}) {}

std::string formatDiagnostic(const Diagnostic& d) {
  const char* sev = d.severity == Severity::Error ? "error" : d.severity == Severity::Warning ? "warning" : "note";
  std::string where = d.loc.file.empty() ? "shadergen" : d.loc.file;
  if (d.loc.line > 0) where += fmt::format(":{}", d.loc.line);
  if (d.loc.line > 0 && d.loc.col > 0) where += fmt::format(":{}", d.loc.col);
  return fmt::format("{}: {}: {}", where, sev, d.message);
}

std::string renderDiagnostic(const Diagnostic& d) {
  std::string out = formatDiagnostic(d);
  if (d.loc.file.empty() || d.loc.line <= 0) return out;
  std::ifstream in(d.loc.file, std::ios::binary);
  std::string line;
  for (int i = 0; i < d.loc.line && std::getline(in, line); ++i) {
  }
  if (!in && line.empty()) return out;
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line.size() > 200) return out;  // don't quote minified/huge lines
  out += "\n  " + line;
  if (d.loc.col > 0) out += "\n  " + std::string(static_cast<size_t>(d.loc.col - 1), ' ') + "^";
  return out;
}

}  // namespace sg
