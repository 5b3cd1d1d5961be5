// What an engine writes to make vertex shaders at load time with shadergen::core: here
// it remakes two of the variants the build made (shadergen_add_shader_variants) from the
// build's index and checks the SPIR-V is the same, byte for byte; then shows how a bad
// input comes back (diagnostics, no exception).
#include <shadergen/shadergen.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>

int main() {
  const std::filesystem::path index = SHADERGEN_VARIANTS_INDEX;
  std::ifstream in(index);
  nlohmann::json doc = nlohmann::json::parse(in);
  int checked = 0;
  for (const auto& v : doc["variants"]) {
    if (checked == 2) break;
    shadergen::Options o;
    o.rig = v["rig_file"];
    o.fragment = v["fragment_file"];
    o.rules = doc["rules"].get<std::vector<std::string>>();
    o.rigParameters = v["parameters"].get<std::map<std::string, int64_t>>();
    o.targetEnv = doc["target_env"];
    o.optimize = doc["optimize"];
    o.templates = SHADERGEN_TEMPLATES_DIR;
    shadergen::Result r = shadergen::generate(o);
    if (!r.ok) {
      for (const auto& d : r.diagnostics) std::cerr << d.text() << "\n";
      return 1;
    }
    std::ifstream spv(index.parent_path() / v["outputs"]["spv"].get<std::string>(), std::ios::binary);
    std::string built((std::istreambuf_iterator<char>(spv)), std::istreambuf_iterator<char>());
    std::string made(reinterpret_cast<const char*>(r.spirv.data()), r.spirv.size() * 4);
    std::cout << "variant " << v["name"].get<std::string>() << ": cost " << r.cost << ", " << r.rules.size()
              << " rules, " << (made == built ? "same SPIR-V as the build" : "DIFFERENT SPIR-V") << "\n";
    if (made != built) return 1;
    ++checked;
  }
  shadergen::Options bad;
  bad.rig = "no-such.rig.yaml";
  bad.fragment = "face.frag";
  bad.rules = doc["rules"].get<std::vector<std::string>>();
  shadergen::Result r = shadergen::generate(bad);
  if (r.ok || r.diagnostics.empty()) return 1;
  std::cout << "bad input: " << r.diagnostics.front().text() << "\n";
  std::cout << (checked == 2 ? "OK" : "too few variants") << "\n";
  return checked == 2 ? 0 : 1;
}
