#include "emit/spirv.h"

#include <fmt/format.h>
#include <glslang/Include/Types.h>
#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <spirv-tools/libspirv.hpp>
#include <spirv-tools/optimizer.hpp>

#include <map>
#include <memory>
#include <stdexcept>

namespace sg {
namespace {

spv_target_env spvEnv(TargetEnv e) {
  switch (e) {
    case TargetEnv::Vulkan1_0: return SPV_ENV_VULKAN_1_0;
    case TargetEnv::Vulkan1_1: return SPV_ENV_VULKAN_1_1;
    case TargetEnv::Vulkan1_2: return SPV_ENV_VULKAN_1_2;
    case TargetEnv::Vulkan1_3: return SPV_ENV_VULKAN_1_3;
  }
  return SPV_ENV_VULKAN_1_0;
}

glslang::EShTargetClientVersion clientVersion(TargetEnv e) {
  switch (e) {
    case TargetEnv::Vulkan1_0: return glslang::EShTargetVulkan_1_0;
    case TargetEnv::Vulkan1_1: return glslang::EShTargetVulkan_1_1;
    case TargetEnv::Vulkan1_2: return glslang::EShTargetVulkan_1_2;
    case TargetEnv::Vulkan1_3: return glslang::EShTargetVulkan_1_3;
  }
  return glslang::EShTargetVulkan_1_0;
}

[[noreturn]] void throwDiagnostics(std::vector<Diagnostic> diags, const std::string& fallbackFile, const char* what) {
  if (diags.empty()) throw InputError(SourceLoc{fallbackFile, 0, 0}, what);
  // Errors first.
  std::stable_partition(diags.begin(), diags.end(), [](const Diagnostic& d) { return d.severity == Severity::Error; });
  InputError e(diags.front());
  e.related.assign(diags.begin() + 1, diags.end());
  throw e;
}

// A parsed shader with the Vulkan environment set; nullptr-free, owned by the caller.
std::unique_ptr<glslang::TShader> parseStage(EShLanguage lang, const std::string& text, TargetEnv env) {
  auto s = std::make_unique<glslang::TShader>(lang);
  const char* src = text.c_str();
  s->setStrings(&src, 1);
  s->setEnvInput(glslang::EShSourceGlsl, lang, glslang::EShClientVulkan, 100);
  s->setEnvClient(glslang::EShClientVulkan, clientVersion(env));
  s->setEnvTarget(glslang::EShTargetSpv, glslang::EShTargetSpv_1_0);
  auto msgs = static_cast<EShMessages>(EShMsgSpvRules | EShMsgVulkanRules);
  if (!s->parse(GetDefaultResources(), 450, ECoreProfile, false, false, msgs)) return nullptr;
  return s;
}

// Location → type of a single stage's user inputs or outputs, as compiled.
std::map<int, const glslang::TType*> interfaceByLocation(glslang::TProgram& prog, bool outputs) {
  prog.buildReflection(EShReflectionAllIOVariables | EShReflectionIntermediateIO);
  std::map<int, const glslang::TType*> m;
  int n = outputs ? prog.getNumPipeOutputs() : prog.getNumPipeInputs();
  for (int i = 0; i < n; ++i) {
    const auto& r = outputs ? prog.getPipeOutput(i) : prog.getPipeInput(i);
    const glslang::TType* t = r.getType();
    if (t && t->getQualifier().hasLocation()) m[static_cast<int>(t->getQualifier().layoutLocation)] = t;
  }
  return m;
}

}  // namespace

SpirvModule compileVertexShader(const EmittedGlsl& glsl, const std::string& glslFileName, TargetEnv env) {
  GlslUnit unit{Stage::Vertex, glsl.text, glslFileName, glsl.sourceFiles};
  CompileResult r = compileGlsl(unit, env);
  if (!r.ok) throwDiagnostics(r.diagnostics, glslFileName, "the generated vertex shader does not compile");
  SpirvModule m;
  m.words = std::move(r.spirv);

  // Uniform layout as the compiler laid it out (std140), for the runtime to fill.
  glslang::TProgram program;
  auto shader = parseStage(EShLangVertex, glsl.text, env);
  if (shader) program.addShader(shader.get());
  if (shader && program.link(static_cast<EShMessages>(EShMsgSpvRules | EShMsgVulkanRules)) &&
      program.buildReflection(EShReflectionAllBlockVariables)) {
    for (int i = 0; i < program.getNumUniformBlocks(); ++i)
      if (program.getUniformBlock(i).name == "ShadergenUniforms")
        m.uniformBlockSize = static_cast<uint32_t>(program.getUniformBlock(i).size);
    for (int i = 0; i < program.getNumUniformVariables(); ++i) {
      const glslang::TObjectReflection& u = program.getUniform(i);
      UniformLayout l;
      l.name = u.name.substr(0, u.name.find('['));
      l.offset = static_cast<uint32_t>(u.offset);
      l.arrayStride = static_cast<uint32_t>(std::max(0, u.arrayStride));
      const glslang::TType* t = u.getType();
      l.matrixStride = t && t->isMatrix() ? 16u : 0u;
      l.size = t && t->isMatrix() ? 16u * static_cast<uint32_t>(t->getMatrixCols())
                                  : 4u * static_cast<uint32_t>(t ? std::max(1, t->getVectorSize()) : 1);
      m.uniforms.push_back(l);
    }
  }
  return m;
}

std::string validateSpirv(const std::vector<uint32_t>& words, TargetEnv env) {
  spvtools::SpirvTools tools(spvEnv(env));
  std::string messages;
  tools.SetMessageConsumer([&](spv_message_level_t, const char*, const spv_position_t& pos, const char* msg) {
    messages += fmt::format("spirv-val: instruction {}: {}\n", pos.index, msg);
  });
  if (tools.Validate(words)) return "";
  return messages.empty() ? "spirv-val: invalid module" : messages;
}

std::vector<uint32_t> optimizeSpirv(const std::vector<uint32_t>& words, TargetEnv env) {
  spvtools::Optimizer opt(spvEnv(env));
  std::string messages;
  opt.SetMessageConsumer([&](spv_message_level_t level, const char*, const spv_position_t&, const char* msg) {
    if (level <= SPV_MSG_ERROR) messages += std::string(msg) + "\n";
  });
  opt.RegisterPerformancePasses();
  std::vector<uint32_t> out;
  if (!opt.Run(words.data(), words.size(), &out)) throw std::runtime_error("spirv-opt failed: " + messages);
  return out;
}

size_t countInstructions(const std::vector<uint32_t>& words) {
  size_t n = 0;
  for (size_t i = 5; i < words.size();) {
    uint32_t len = words[i] >> 16;
    if (len == 0) break;
    i += len;
    ++n;
  }
  return n;
}

void checkLink(const EmittedGlsl& vertex, const std::string& fragmentSource, const std::string& fragmentFile,
               TargetEnv env) {
  ensureGlslangInitialized();
  auto msgs = static_cast<EShMessages>(EShMsgSpvRules | EShMsgVulkanRules);
  auto vs = parseStage(EShLangVertex, vertex.text, env);
  auto fs = parseStage(EShLangFragment, fragmentSource, env);
  if (!vs || !fs) throw InputError(SourceLoc{fragmentFile, 0, 0}, "link check: a stage failed to compile");
  glslang::TProgram program;
  program.addShader(vs.get());
  program.addShader(fs.get());
  if (!program.link(msgs))
    throw InputError(SourceLoc{fragmentFile, 0, 0},
                     std::string("the vertex and fragment shaders do not link: ") + program.getInfoLog());
  // glslang's linker does not match locations across stages: compare them ourselves.
  glslang::TProgram vsOnly, fsOnly;
  vsOnly.addShader(vs.get());
  fsOnly.addShader(fs.get());
  vsOnly.link(msgs);
  fsOnly.link(msgs);
  auto outs = interfaceByLocation(vsOnly, true);
  for (const auto& [loc, t] : interfaceByLocation(fsOnly, false)) {
    auto it = outs.find(loc);
    if (it == outs.end())
      throw InputError(SourceLoc{fragmentFile, 0, 0},
                       fmt::format("link check: fragment input at location {} has no vertex output", loc));
    if (it->second->getBasicType() != t->getBasicType() || it->second->getVectorSize() != t->getVectorSize() ||
        it->second->getMatrixCols() != t->getMatrixCols())
      throw InputError(SourceLoc{fragmentFile, 0, 0},
                       fmt::format("link check: location {}: vertex writes {} but the fragment shader reads {}", loc,
                                   it->second->getCompleteString(), t->getCompleteString()));
  }
}

}  // namespace sg
