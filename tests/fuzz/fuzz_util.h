// Shared by the libFuzzer targets: run one input through a stage; an InputError is the
// expected answer to bad input, anything else (another exception, a crash, a sanitizer
// report, a timeout) is a finding.
#pragma once
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "common/diagnostics.h"

namespace sg::fuzz {

inline std::string text(const uint8_t* data, size_t size) { return std::string(reinterpret_cast<const char*>(data), size); }

// Runs f; swallows InputError (and renders it, so the diagnostic printer is fuzzed too).
template <typename F>
void expectInputErrorsOnly(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    (void)formatDiagnostic(e.diagnostic());
  }
}

// A private scratch directory for inputs that must be files: one per process, reused by
// every run, removed at exit.
struct ScratchDir {
  std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("shadergen-fuzz-" + std::to_string(::getpid()));
  ScratchDir() { std::filesystem::create_directories(path); }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
};
inline const std::filesystem::path& scratchDir() {
  static const ScratchDir dir;
  return dir.path;
}
inline std::string writeScratch(const std::string& name, const std::string& bytes) {
  auto p = scratchDir() / name;
  std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
  return p.string();
}

}  // namespace sg::fuzz
