#include "emit/templates.h"

#include <fmt/format.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <stdexcept>

#include "common/diagnostics.h"
#include "common/yaml_util.h"

namespace sg {

TemplateSet TemplateSet::load(const std::string& dir) {
  std::string path = (std::filesystem::path(dir) / "vertex.glsl").string();
  return parse(readInputFile(path), path);
}

TemplateSet TemplateSet::parse(const std::string& text, const std::string& file) {
  TemplateSet t;
  t.file_ = file;
  std::string current;
  std::string body;
  bool inSection = false;
  auto flush = [&] {
    if (!inSection) return;
    if (!body.empty() && body.back() == '\n') body.pop_back();
    t.sections_[current] = body;
  };
  size_t start = 0;
  int lineNo = 0;
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    std::string line = text.substr(start, end == std::string::npos ? std::string::npos : end - start);
    start = end == std::string::npos ? text.size() : end + 1;
    ++lineNo;
    if (line.rfind("--- ", 0) == 0) {
      flush();
      current = line.substr(4);
      body.clear();
      inSection = true;
      if (t.sections_.count(current))
        throw InputError(SourceLoc{file, lineNo, 5}, fmt::format("template section '{}' defined twice", current));
      continue;
    }
    if (inSection) body += line + "\n";
  }
  flush();
  for (const char* required : {"shader", "source", "input", "uniform_block", "uniform_member", "output",
                               "position_block", "xfb", "rule", "line", "store", "pack"})
    if (!t.sections_.count(required))
      throw InputError(SourceLoc{file, 0, 0}, fmt::format("template section '{}' is missing", required));
  return t;
}

std::string TemplateSet::fill(const std::string& name, const std::map<std::string, std::string>& values) const {
  auto it = sections_.find(name);
  if (it == sections_.end()) throw std::logic_error("no template section " + name);
  const std::string& s = it->second;
  std::string out;
  size_t i = 0;
  while (i < s.size()) {
    size_t open = s.find("{{", i);
    if (open == std::string::npos) {
      out += s.substr(i);
      break;
    }
    size_t close = s.find("}}", open);
    if (close == std::string::npos) throw std::logic_error(fmt::format("{}: unterminated {{{{ in '{}'", file_, name));
    out += s.substr(i, open - i);
    std::string key = s.substr(open + 2, close - open - 2);
    auto v = values.find(key);
    if (v == values.end()) throw std::logic_error(fmt::format("{}: section '{}' uses unknown key '{}'", file_, name, key));
    out += v->second;
    i = close + 2;
  }
  return out;
}

std::string defaultTemplateDir() {
  if (const char* env = std::getenv("SHADERGEN_TEMPLATES")) return env;
  std::error_code ec;
  auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    auto installed = exe.parent_path().parent_path() / "share" / "shadergen" / "templates";
    if (std::filesystem::exists(installed / "vertex.glsl", ec)) return installed.string();
  }
  return SHADERGEN_SOURCE_TEMPLATES;
}

}  // namespace sg
