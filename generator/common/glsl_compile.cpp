#include "common/glsl_compile.h"

#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>

#include <mutex>
#include <algorithm>
#include <sstream>

namespace sg {

bool parseTargetEnv(const std::string& s, TargetEnv& out) {
  if (s == "vulkan1.0" || s == "vulkan") out = TargetEnv::Vulkan1_0;
  else if (s == "vulkan1.1") out = TargetEnv::Vulkan1_1;
  else if (s == "vulkan1.2") out = TargetEnv::Vulkan1_2;
  else if (s == "vulkan1.3") out = TargetEnv::Vulkan1_3;
  else return false;
  return true;
}

const char* targetEnvName(TargetEnv e) {
  switch (e) {
    case TargetEnv::Vulkan1_0: return "vulkan1.0";
    case TargetEnv::Vulkan1_1: return "vulkan1.1";
    case TargetEnv::Vulkan1_2: return "vulkan1.2";
    case TargetEnv::Vulkan1_3: return "vulkan1.3";
  }
  return "vulkan1.0";
}

void ensureGlslangInitialized() {
  static std::once_flag once;
  std::call_once(once, [] { glslang::InitializeProcess(); });
}

namespace {

// "ERROR: 0:12: message" → severity, source string, line, message. Parsed by hand: a
// std::regex over a message that quotes a 30 KB token recurses once per character.
bool splitLogLine(const std::string& line, Severity& sev, size_t& src, int& lineNo, std::string& msg) {
  size_t p = 0;
  if (line.rfind("ERROR: ", 0) == 0) {
    sev = Severity::Error;
    p = 7;
  } else if (line.rfind("WARNING: ", 0) == 0) {
    sev = Severity::Warning;
    p = 9;
  } else {
    return false;
  }
  auto number = [&](unsigned long long& v) {
    size_t b = p;
    v = 0;
    while (p < line.size() && line[p] >= '0' && line[p] <= '9') {
      if (v < 1'000'000'000ull) v = v * 10 + static_cast<unsigned>(line[p] - '0');  // saturates, never throws
      ++p;
    }
    return p > b;
  };
  unsigned long long s = 0, l = 0;
  if (!number(s) || p >= line.size() || line[p++] != ':') return false;
  if (!number(l) || line.compare(p, 2, ": ") != 0) return false;
  src = static_cast<size_t>(s);
  lineNo = static_cast<int>(std::min<unsigned long long>(l, 1'000'000'000ull));
  msg = line.substr(p + 2);
  return true;
}

}  // namespace

std::vector<Diagnostic> parseGlslangLog(const std::string& log, const GlslUnit& unit) {
  std::vector<Diagnostic> out;
  std::istringstream in(log);
  std::string line;
  while (std::getline(in, line)) {
    Diagnostic d;
    size_t src = 0;
    if (!splitLogLine(line, d.severity, src, d.loc.line, d.message)) {
      // Unlocated messages (e.g. linker errors) still matter.
      if (line.rfind("ERROR: ", 0) == 0 && line.find("compilation errors") == std::string::npos)
        out.push_back(Diagnostic{Severity::Error, SourceLoc{unit.fileName, 0, 0}, line.substr(7)});
      continue;
    }
    d.loc.file = (src >= 1 && src <= unit.sourceFiles.size()) ? unit.sourceFiles[src - 1] : unit.fileName;
    while (!d.message.empty() && d.message.back() == ' ') d.message.pop_back();
    if (d.message == "compilation terminated") continue;  // follows the real error
    out.push_back(std::move(d));
  }
  return out;
}

CompileResult compileGlsl(const GlslUnit& unit, TargetEnv env) {
  ensureGlslangInitialized();
  CompileResult res;
  EShLanguage lang = unit.stage == Stage::Vertex ? EShLangVertex : EShLangFragment;
  glslang::TShader shader(lang);
  const char* src = unit.text.c_str();
  const char* names = unit.fileName.c_str();
  shader.setStringsWithLengthsAndNames(&src, nullptr, &names, 1);
  glslang::EShTargetClientVersion client = glslang::EShTargetVulkan_1_0;
  glslang::EShTargetLanguageVersion spv = glslang::EShTargetSpv_1_0;
  switch (env) {
    case TargetEnv::Vulkan1_0: break;
    case TargetEnv::Vulkan1_1: client = glslang::EShTargetVulkan_1_1; spv = glslang::EShTargetSpv_1_3; break;
    case TargetEnv::Vulkan1_2: client = glslang::EShTargetVulkan_1_2; spv = glslang::EShTargetSpv_1_5; break;
    case TargetEnv::Vulkan1_3: client = glslang::EShTargetVulkan_1_3; spv = glslang::EShTargetSpv_1_6; break;
  }
  shader.setEnvInput(glslang::EShSourceGlsl, lang, glslang::EShClientVulkan, 100);
  shader.setEnvClient(glslang::EShClientVulkan, client);
  shader.setEnvTarget(glslang::EShTargetSpv, spv);
  auto messages = static_cast<EShMessages>(EShMsgSpvRules | EShMsgVulkanRules);
  bool ok = shader.parse(GetDefaultResources(), 450, ECoreProfile, false, false, messages);
  res.diagnostics = parseGlslangLog(shader.getInfoLog(), unit);
  if (!ok) return res;
  glslang::TProgram program;
  program.addShader(&shader);
  if (!program.link(messages)) {
    auto more = parseGlslangLog(program.getInfoLog(), unit);
    res.diagnostics.insert(res.diagnostics.end(), more.begin(), more.end());
    return res;
  }
  glslang::SpvOptions opts;
  opts.disableOptimizer = true;
  opts.validate = false;
  glslang::GlslangToSpv(*program.getIntermediate(lang), res.spirv, &opts);
  res.ok = true;
  return res;
}

}  // namespace sg
