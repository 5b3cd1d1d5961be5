#include "common/diagnostics.h"

#include <fmt/format.h>

#include "common/input_file.h"

namespace sg {

InputError::InputError(Diagnostic d) : std::runtime_error(formatDiagnostic(d)), diag_(std::move(d)) {}
InputError::InputError(SourceLoc loc, const std::string& message)
    : InputError(Diagnostic{Severity::Error, std::move(loc), message}) {}

namespace {
// Names from input files end up in messages: show control bytes as \xNN so that a
// message cannot move the cursor or fake another diagnostic line.
std::string printable(const std::string& s, bool keepNewlines) {
  std::string o;
  for (char c : s) {
    auto u = static_cast<unsigned char>(c);
    if ((u < 0x20 && c != '\t' && !(keepNewlines && c == '\n')) || u == 0x7f) o += fmt::format("\\x{:02x}", u);
    else o += c;
  }
  return o;
}
}  // namespace

std::string formatDiagnostic(const Diagnostic& d) {
  const char* sev = d.severity == Severity::Error ? "error" : d.severity == Severity::Warning ? "warning" : "note";
  std::string where = d.loc.file.empty() ? "shadergen" : printable(d.loc.file, false);
  if (d.loc.line > 0) where += fmt::format(":{}", d.loc.line);
  if (d.loc.line > 0 && d.loc.col > 0) where += fmt::format(":{}", d.loc.col);
  std::string out = fmt::format("{}: {}: {}", where, sev, printable(d.message, true));
  if (!d.code.empty()) out += " [" + printable(d.code, false) + "]";
  return out;
}

std::string renderDiagnostic(const Diagnostic& d) {
  std::string out = formatDiagnostic(d);
  if (d.loc.file.empty() || d.loc.line <= 0) return out;
  // Bounded: a FIFO, a device or an oversize file is not re-read (common/input_file.h).
  std::string line = inputFileLine(d.loc.file, d.loc.line);
  if (line.empty() || line.size() > 200) return out;  // don't quote minified/huge lines
  for (char& c : line)
    if (static_cast<unsigned char>(c) < 0x20 && c != '\t') c = '?';  // no terminal control codes
  out += "\n  " + line;
  if (d.loc.col > 0) out += "\n  " + std::string(static_cast<size_t>(d.loc.col - 1), ' ') + "^";
  return out;
}

}  // namespace sg
