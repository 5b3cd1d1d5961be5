#include "emit/depfile.h"

#include <fmt/format.h>

#include "common/diagnostics.h"

namespace sg {

std::string makeDepfile(const std::vector<std::string>& targets, const std::vector<std::string>& deps) {
  auto esc = [](const std::string& s) {
    std::string o;
    for (char c : s) {
      if (c == ' ' || c == '#') o += '\\';
      if (c == '$') o += '$';
      o += c;
    }
    return o;
  };
  for (const auto* list : {&targets, &deps})
    for (const auto& p : *list)
      if (p.find_first_of("\n\r") != std::string::npos)
        throw InputError(SourceLoc{}, fmt::format("cannot write a depfile naming '{}': the path contains a newline", p));
  std::string out;
  for (const auto& t : targets) out += (out.empty() ? "" : " ") + esc(t);
  out += ":";
  for (const auto& d : deps) out += " \\\n  " + esc(d);
  return out + "\n";
}

}  // namespace sg
