// Helpers for the analysis tests: scratch files and running the shadergen CLI.
#pragma once
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace sg::testing {

inline std::string sourceDir() { return SG_SOURCE_DIR; }

inline std::filesystem::path scratchRoot() {
  return std::filesystem::temp_directory_path() / ("sg_analysis_" + std::to_string(::getpid()));
}

// Removes this process's scratch files when the test program exits.
struct ScratchCleanup {
  ~ScratchCleanup() {
    std::error_code ec;
    std::filesystem::remove_all(scratchRoot(), ec);
  }
};
inline ScratchCleanup scratchCleanup;

// A fresh directory per test (removed when the test program exits).
inline std::filesystem::path scratchDir(const std::string& name) {
  auto dir = scratchRoot() / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline std::string writeFile(const std::filesystem::path& path, const std::string& text) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
  return path.string();
}

inline std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// 1-based line of the first line containing `needle`, and 1-based column of `needle` in it.
inline std::pair<int, int> lineColOf(const std::string& text, const std::string& needle) {
  std::istringstream in(text);
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    auto at = line.find(needle);
    if (at != std::string::npos) return {n, static_cast<int>(at) + 1};
  }
  return {0, 0};
}

struct CliResult {
  int status = -1;
  std::string output;  // stdout and stderr together
};

inline std::string shellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

inline CliResult runCli(const std::vector<std::string>& args) {
  std::string cmd = shellQuote(SG_CLI);
  for (const auto& a : args) cmd += " " + shellQuote(a);
  cmd += " 2>&1";
  CliResult r;
  FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf{};
  size_t n;
  while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0) r.output.append(buf.data(), n);
  int st = ::pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

}  // namespace sg::testing
