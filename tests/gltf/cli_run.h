// Running the shadergen CLI (or any shell command) from a test: exit status and output.
#pragma once
#include <fmt/format.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace sg::test {
// A shell command's exit status and its standard output and error together.
struct CliRun {
  int status = -1;
  std::string out;
};
inline CliRun shell(const std::string& cmd) {
  CliRun r;
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return r;
  std::array<char, 65536> buf{};
  size_t n = 0;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) r.out.append(buf.data(), n);
  int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}
// The shadergen CLI with `args` (lavapipe needs an XDG_RUNTIME_DIR).
inline CliRun cli(const std::string& args) { return shell(fmt::format("XDG_RUNTIME_DIR=/tmp \"{}\" {}", SG_CLI, args)); }

}  // namespace sg::test
