// Diagnostics in the compiler convention: "file:line:col: error: message",
// followed by the source line and a caret when the line is known.
#pragma once
#include <stdexcept>
#include <string>
#include <vector>

namespace sg {

struct SourceLoc {
  std::string file;
  int line = 0;  // 1-based; 0 = unknown
  int col = 0;   // 1-based; 0 = unknown
};

enum class Severity { Error, Warning, Note };

struct Diagnostic {
  Severity severity = Severity::Error;
  SourceLoc loc;
  std::string message;
  // The finding's name where an outside tool has one (the Khronos glTF-Validator's
  // "ACCESSOR_WEIGHTS_NON_NORMALIZED"), printed after the message as "[CODE]"; "" = none.
  std::string code;
};

// Thrown by loaders and stages for input errors (exit status 1).
class InputError : public std::runtime_error {
 public:
  explicit InputError(Diagnostic d);
  InputError(SourceLoc loc, const std::string& message);
  const Diagnostic& diagnostic() const { return diag_; }
  // Several findings at once (the first is the primary one).
  std::vector<Diagnostic> related;

 private:
  Diagnostic diag_;
};

// "file:line:col: error: message [CODE]" (no caret line).
std::string formatDiagnostic(const Diagnostic& d);
// formatDiagnostic plus the quoted source line and a caret, read from d.loc.file.
std::string renderDiagnostic(const Diagnostic& d);

}  // namespace sg
