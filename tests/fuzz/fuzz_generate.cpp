// libFuzzer: the whole generate path (load, search, emit GLSL, compile to SPIR-V, checks).
// The input is up to three sections separated by a line "%%": rig YAML, fragment shader,
// rules YAML; a missing section is the Dawn face example's.
#include "fuzz_util.h"
#include "pipeline/generate.h"

#include <fstream>
#include <sstream>

namespace {
std::string readSource(const char* rel) {
  std::ifstream in(std::string(SG_SOURCE_DIR) + "/" + rel, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string defaults[3] = {readSource("examples/dawn/face.rig.yaml"),
                                          readSource("examples/dawn/face.frag"),
                                          readSource("examples/dawn/rules.yaml")};
  std::string in = sg::fuzz::text(data, size), parts[3] = {defaults[0], defaults[1], defaults[2]};
  for (int i = 0; i < 3 && !in.empty(); ++i) {
    auto cut = in.find("\n%%\n");
    parts[i] = in.substr(0, cut);
    in = cut == std::string::npos ? "" : in.substr(cut + 4);
  }
  sg::GenerateOptions o;
  o.rigPath = sg::fuzz::writeScratch("fuzz.rig.yaml", parts[0]);
  o.fragmentPath = sg::fuzz::writeScratch("fuzz.frag", parts[1]);
  o.rulesPaths = {sg::fuzz::writeScratch("fuzz.rules.yaml", parts[2])};
  sg::fuzz::expectInputErrorsOnly([&] { (void)sg::generate(o); });
  return 0;
}
