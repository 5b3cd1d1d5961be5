#include "common/yaml_util.h"

#include <fmt/format.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

namespace sg {

std::string readInputFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw InputError(SourceLoc{path, 0, 0}, fmt::format("cannot open file: {}", std::strerror(errno)));
  auto size = static_cast<size_t>(in.tellg());
  if (size > kMaxInputBytes)
    throw InputError(SourceLoc{path, 0, 0},
                     fmt::format("file is {} bytes, larger than the {} byte limit for inputs", size, kMaxInputBytes));
  std::string text(size, '\0');
  in.seekg(0);
  in.read(text.data(), static_cast<std::streamsize>(size));
  return text;
}

YAML::Node parseYaml(const std::string& text, const std::string& file) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    std::string msg = e.msg.empty() ? "malformed YAML" : e.msg;
    throw InputError(SourceLoc{file, e.mark.line + 1, e.mark.column + 1}, "malformed YAML: " + msg);
  }
}

SourceLoc locOf(const YAML::Node& n, const std::string& file) {
  if (!n.IsDefined()) return SourceLoc{file, 0, 0};
  auto m = n.Mark();
  if (m.is_null()) return SourceLoc{file, 0, 0};
  return SourceLoc{file, m.line + 1, m.column + 1};
}

void YamlCtx::fail(const YAML::Node& at, const std::string& msg) const { throw InputError(locOf(at, file), msg); }

void YamlCtx::expectMap(const YAML::Node& n, const char* what) const {
  if (!n.IsMap()) fail(n, fmt::format("{} must be a mapping", what));
}
void YamlCtx::expectSeq(const YAML::Node& n, const char* what) const {
  if (!n.IsSequence()) fail(n, fmt::format("{} must be a sequence", what));
}

std::string YamlCtx::scalar(const YAML::Node& n, const char* what) const {
  if (!n.IsScalar()) fail(n, fmt::format("{} must be a scalar", what));
  return n.Scalar();
}

long long YamlCtx::integer(const YAML::Node& n, const char* what) const {
  std::string s = scalar(n, what);
  try {
    size_t used = 0;
    long long v = std::stoll(s, &used, 10);
    if (used == s.size()) return v;
  } catch (const std::exception&) {
  }
  fail(n, fmt::format("{} must be an integer, got '{}'", what, s));
}

bool YamlCtx::boolean(const YAML::Node& n, const char* what) const {
  std::string s = scalar(n, what);
  if (s == "true" || s == "yes") return true;
  if (s == "false" || s == "no") return false;
  fail(n, fmt::format("{} must be true or false, got '{}'", what, s));
}

void YamlCtx::checkKeys(const YAML::Node& map, std::initializer_list<const char*> allowed) const {
  for (auto it = map.begin(); it != map.end(); ++it) {
    std::string key = it->first.IsScalar() ? it->first.Scalar() : "";
    bool ok = false;
    for (const char* a : allowed) ok = ok || key == a;
    if (!ok) {
      std::string list;
      for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      fail(it->first, fmt::format("unknown key '{}' (expected one of: {})", key, list));
    }
  }
}

}  // namespace sg
