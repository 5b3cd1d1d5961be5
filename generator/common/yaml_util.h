// Small helpers over yaml-cpp that turn every shape error into a located InputError.
#pragma once
#include <yaml-cpp/yaml.h>

#include <initializer_list>
#include <string>

#include "common/diagnostics.h"

namespace sg {

// Input files larger than this are rejected before parsing (guards against runaway input).
constexpr size_t kMaxInputBytes = 16u << 20;

// Reads a whole file; throws InputError if it is missing, unreadable or too large.
std::string readInputFile(const std::string& path);

// Parses YAML text; parse errors become "file:line:col: error: ...".
YAML::Node parseYaml(const std::string& text, const std::string& file);

SourceLoc locOf(const YAML::Node& n, const std::string& file);

struct YamlCtx {
  std::string file;
  [[noreturn]] void fail(const YAML::Node& at, const std::string& msg) const;
  void expectMap(const YAML::Node& n, const char* what) const;
  void expectSeq(const YAML::Node& n, const char* what) const;
  std::string scalar(const YAML::Node& n, const char* what) const;
  long long integer(const YAML::Node& n, const char* what) const;
  bool boolean(const YAML::Node& n, const char* what) const;
  // Rejects keys not in `allowed` (typos in rules files must not be silently ignored).
  void checkKeys(const YAML::Node& map, std::initializer_list<const char*> allowed) const;
};

}  // namespace sg
