// Small helpers over yaml-cpp that turn every shape error into a located InputError.
#pragma once
#include <yaml-cpp/yaml.h>

#include <initializer_list>
#include <string>

#include "common/diagnostics.h"
#include "common/input_file.h"

namespace sg {

// Documents nested deeper than this, or with more nodes (aliases expanded), are refused:
// the formats need a few levels and a few thousand nodes (docs/limits.md).
constexpr int kMaxYamlDepth = 32;
constexpr size_t kMaxYamlNodes = 1u << 20;

// Parses YAML text; parse errors become "file:line:col: error: ...". Also refuses
// duplicate keys in a mapping and the limits above.
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
