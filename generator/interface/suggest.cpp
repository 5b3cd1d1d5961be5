#include "interface/suggest.h"

#include <algorithm>
#include <cctype>
#include <map>
#include <tuple>

#include "rules/rules.h"

namespace sg {
namespace {

// Abbreviations engines use in varying names, to the words of this project's semantics.
const std::map<std::string, std::string>& synonyms() {
  static const std::map<std::string, std::string> m{
      {"pos", "position"},    {"p", "position"},      {"nrm", "normal"},      {"norm", "normal"},
      {"n", "normal"},        {"nor", "normal"},      {"tan", "tangent"},     {"t", "tangent"},
      {"bitangent", "binormal"}, {"bitan", "binormal"}, {"binorm", "binormal"}, {"b", "binormal"},
      {"uv", "texcoord0"},    {"uv0", "texcoord0"},   {"uv1", "texcoord1"},   {"uv2", "texcoord1"},
      {"texcoord", "texcoord0"}, {"texcoords", "texcoord0"}, {"tc", "texcoord0"}, {"tex", "texcoord0"},
      {"col", "color0"},      {"color", "color0"},    {"colour", "color0"},   {"ws", "world"},
      {"w", "world"},         {"wpos", "world"},      {"vs", "eye"},          {"view", "eye"},
      {"cs", "clip"},         {"os", "object"},       {"obj", "object"},      {"local", "object"},
      {"direction", "dir"},   {"ao", "occlusion"},    {"sign", "handedness"}, {"frag", ""}};
  return m;
}

bool isLower(char c) { return std::islower(static_cast<unsigned char>(c)) != 0; }
bool isUpper(char c) { return std::isupper(static_cast<unsigned char>(c)) != 0; }
bool isDigit(char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }

}  // namespace

std::vector<std::string> nameWords(const std::string& name, bool isSemantic) {
  std::string s = name;
  if (!isSemantic) {
    // Engine prefixes that mark a varying, not part of its meaning.
    for (const char* pre : {"vertex_", "v_", "out_", "in_", "vs_", "fs_", "o_", "i_", "f_", "pass_", "frag_"}) {
      std::string p(pre);
      if (s.size() > p.size() && s.compare(0, p.size(), p) == 0) {
        s = s.substr(p.size());
        break;
      }
    }
    if (s.size() > 1 && (s[0] == 'v' || s[0] == 'o' || s[0] == 'i') && isUpper(s[1])) s = s.substr(1);  // vNormal
  }
  std::vector<std::string> words;
  std::string cur;
  auto flush = [&] {
    if (!cur.empty()) words.push_back(cur);
    cur.clear();
  };
  for (size_t i = 0; i < s.size(); ++i) {
    char c = s[i];
    if (c == '_' || c == '.' || c == '[' || c == ']') {
      flush();
      continue;
    }
    char prev = i > 0 ? s[i - 1] : '_';
    if (isUpper(c) && !cur.empty() && (isLower(prev) || isDigit(prev) || (i + 1 < s.size() && isLower(s[i + 1]))))
      flush();  // camelCase and "TBNMatrix" boundaries
    cur += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  flush();
  // A lone number belongs to the word before it: texcoord_0 -> texcoord0.
  std::vector<std::string> joined;
  for (auto& w : words) {
    if (!joined.empty() && std::all_of(w.begin(), w.end(), isDigit) && !isDigit(joined.back().back())) joined.back() += w;
    else joined.push_back(w);
  }
  std::vector<std::string> out;
  for (auto& w : joined) {
    if (!isSemantic) {
      auto it = synonyms().find(w);
      if (it != synonyms().end()) w = it->second;
      if (w.rfind("texcoord", 0) == 0 && w.size() > 8 && w[8] == '_') w.erase(8, 1);
    }
    if (!w.empty()) out.push_back(w);
  }
  return out;
}

std::vector<std::string> closestSemantics(const RuleSet& rules, const std::string& inputName, Type type, size_t limit) {
  std::vector<std::string> in = nameWords(inputName, false);
  if (in.empty()) return {};
  // Prefer the space shading usually happens in when words tie (v_normal: world.normal first).
  auto spaceRank = [](const std::string& sem) {
    static const char* order[] = {"world.", "eye.", "vertex.", "object.", "view.", "frame.", "clip."};
    for (size_t i = 0; i < std::size(order); ++i)
      if (sem.rfind(order[i], 0) == 0) return static_cast<int>(i);
    return 100;
  };
  using Key = std::tuple<int, int, int, int, std::string>;  // sort ascending
  std::vector<Key> ranked;
  for (const auto& d : rules.semantics) {
    if (isMatrix(d.type) || d.arraySize || !d.arrayParam.empty() || !d.count.empty() || !d.bufferOf.empty())
      continue;  // not a varying
    if (d.name == "clip.position") continue;  // gl_Position, never a fragment input
    if (scalarKind(d.type) != scalarKind(type)) continue;
    std::vector<std::string> sem = nameWords(d.name, true);
    int matched = 0;
    for (const auto& w : in)
      if (std::find(sem.begin(), sem.end(), w) != sem.end()) ++matched;
    if (matched == 0) continue;
    int unmatched = static_cast<int>(sem.size()) - matched;  // semantic words the name does not mention
    bool sameType = d.type == type || (isMatrix(type) && componentCount(d.type) * 3 == componentCount(type));
    ranked.emplace_back(-matched, sameType ? 0 : 1, unmatched, spaceRank(d.name), d.name);
  }
  std::sort(ranked.begin(), ranked.end());
  std::vector<std::string> out;
  for (const auto& k : ranked) {
    if (out.size() == limit) break;
    if (std::get<0>(k) > std::get<0>(ranked.front())) break;  // only the best-matching words
    out.push_back(std::get<4>(k));
  }
  return out;
}

}  // namespace sg
