#include "common/yaml_util.h"

#include <fmt/format.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string_view>
#include <vector>

namespace sg {

namespace {

// Walks the parsed document without recursion: refuses nesting deeper than
// kMaxYamlDepth, more than kMaxYamlNodes nodes (aliases make a small file a huge tree)
// and a key repeated in one mapping (yaml-cpp keeps the last one silently).
void checkYamlShape(const YAML::Node& root, const std::string& file) {
  struct Item {
    YAML::Node node;
    int depth;
  };
  std::vector<Item> stack{{root, 1}};
  size_t visited = 0;
  while (!stack.empty()) {
    Item item = std::move(stack.back());
    stack.pop_back();
    if (++visited > kMaxYamlNodes)
      throw InputError(locOf(item.node, file),
                       fmt::format("YAML document has more than {} nodes (aliases expanded)", kMaxYamlNodes));
    if (item.depth > kMaxYamlDepth)
      throw InputError(locOf(item.node, file), fmt::format("YAML nesting is deeper than {} levels", kMaxYamlDepth));
    if (item.node.IsSequence()) {
      for (auto it = item.node.begin(); it != item.node.end(); ++it) stack.push_back({YAML::Node(*it), item.depth + 1});
    } else if (item.node.IsMap()) {
      std::map<std::string, SourceLoc> seen;
      for (auto it = item.node.begin(); it != item.node.end(); ++it) {
        YAML::Node key = it->first, value = it->second;
        if (key.IsScalar()) {
          SourceLoc at = locOf(key, file);
          auto [prev, fresh] = seen.emplace(key.Scalar(), at);
          if (!fresh)
            throw InputError(at, fmt::format("duplicate key '{}' (first at line {})", key.Scalar(), prev->second.line));
        } else {
          stack.push_back({key, item.depth + 1});
        }
        stack.push_back({value, item.depth + 1});
      }
    }
  }
}

// YAML::Load reads the first document and drops the rest without a word, and YAML::LoadAll hung
// on a 26-byte tagged scalar (tests/bad-input/rules/tag_that_hung_load_all); so a second document
// is found by its markers, which YAML allows only at the start of a line and never inside a scalar.
void refuseSecondDocument(const std::string& text, const std::string& file) {
  auto isMarker = [](std::string_view line, std::string_view marker) {
    return line.substr(0, 3) == marker && (line.size() == 3 || line[3] == ' ' || line[3] == '\t' || line[3] == '\r');
  };
  bool started = false, ended = false;  // a '---' seen; a '...' seen
  int lineNo = 0;
  for (size_t at = 0; at < text.size();) {
    size_t end = text.find('\n', at);
    if (end == std::string::npos) end = text.size();
    std::string_view line(text.data() + at, end - at);
    at = end + 1;
    ++lineNo;
    size_t first = line.find_first_not_of(" \t\r");
    bool blank = first == std::string_view::npos || line[first] == '#';
    if (isMarker(line, "---")) {
      if (started || ended)
        throw InputError(SourceLoc{file, lineNo, 1},
                         "a second YAML document starts here: a file holds one document (put it in a file of its own)");
      started = true;
    } else if (isMarker(line, "...")) {
      ended = true;
    } else if (ended && !blank) {
      throw InputError(SourceLoc{file, lineNo, static_cast<int>(first) + 1},
                       "content after the document's end marker '...': a file holds one document");
    }
    // Content before any '---' is the first document, implicitly started.
    if (!blank && line[0] != '%' && !isMarker(line, "...")) started = true;
  }
}

}  // namespace

YAML::Node parseYaml(const std::string& text, const std::string& file) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    std::string msg = e.msg.empty() ? "malformed YAML" : e.msg;
    throw InputError(SourceLoc{file, e.mark.line + 1, e.mark.column + 1}, "malformed YAML: " + msg);
  }
  refuseSecondDocument(text, file);
  checkYamlShape(root, file);
  return root;
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
