#include "emit/spirv.h"

#include <fmt/format.h>

#include <map>

namespace sg {

CompiledVertexShader compileVertex(const EmittedGlsl& glsl, const std::string& glslFileName, TargetEnv env,
                                   uint32_t maxCaptureBytes) {
  GlslUnit unit{Stage::Vertex, glsl.text, glslFileName, glsl.sourceFiles};
  unit.maxCaptureStrideBytes = maxCaptureBytes > 0 ? maxCaptureBytes : glsl.captureStride;
  GlslShader parsed(unit, env);
  if (!parsed.ok())
    throwDiagnostics(parsed.diagnostics(), glslFileName, "the generated vertex shader does not compile");
  SpirvModule m;
  m.words = parsed.spirv();
  // Uniform layout as the compiler laid it out (std140), for the runtime to fill.
  for (const auto& b : parsed.uniformBlocks())
    if (b.name == "ShadergenUniforms") m.uniformBlockSize = b.size;
  for (const auto& u : parsed.uniformMembers())
    m.uniforms.push_back(UniformLayout{u.name, u.offset, u.arrayStride, u.matrixStride, u.size});
  m.descriptors = parsed.descriptors();
  return CompiledVertexShader{std::move(m), std::move(parsed)};
}

SpirvModule compileVertexShader(const EmittedGlsl& glsl, const std::string& glslFileName, TargetEnv env) {
  return compileVertex(glsl, glslFileName, env).module;
}

void checkLink(const GlslShader& vertex, const GlslShader& fragment) {
  const std::string& fragmentFile = fragment.unit().fileName;
  if (!vertex.ok() || !fragment.ok())
    throw InputError(SourceLoc{fragmentFile, 0, 0}, "link check: a stage failed to compile");
  if (std::string log = vertex.linkWith(fragment); !log.empty())
    throw InputError(SourceLoc{fragmentFile, 0, 0}, "the vertex and fragment shaders do not link: " + log);
  // glslang's linker does not match locations across stages: compare them ourselves.
  std::map<int, StageVariable> outs;
  for (auto& v : vertex.outputs())
    if (v.location >= 0) outs[v.location] = v;
  std::map<int, StageVariable> ins;
  for (auto& v : fragment.inputs())
    if (v.location >= 0) ins[v.location] = v;
  for (const auto& [loc, in] : ins) {
    auto it = outs.find(loc);
    if (it == outs.end())
      throw InputError(SourceLoc{fragmentFile, 0, 0},
                       fmt::format("link check: fragment input at location {} has no vertex output", loc));
    if (it->second.type != in.type || !in.type || it->second.arraySize != in.arraySize)
      throw InputError(SourceLoc{fragmentFile, 0, 0},
                       fmt::format("link check: location {}: vertex writes {} but the fragment shader reads {}", loc,
                                   it->second.typeText, in.typeText));
  }
}

void checkLink(const EmittedGlsl& vertex, const std::string& fragmentSource, const std::string& fragmentFile,
               TargetEnv env) {
  GlslShader vs(GlslUnit{Stage::Vertex, vertex.text, "vertex shader", vertex.sourceFiles}, env);
  GlslShader fs(GlslUnit{Stage::Fragment, fragmentSource, fragmentFile, {}}, env);
  checkLink(vs, fs);
}

}  // namespace sg
