#include "common/glsl_compile.h"

#include <fmt/format.h>
#include <glslang/Include/PoolAlloc.h>
#include <glslang/Include/Types.h>
#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>
#include <glslang/SPIRV/spirv.hpp>
#include <spirv-tools/libspirv.hpp>
#include <spirv-tools/optimizer.hpp>

#include <algorithm>
#include <cctype>
#include <tuple>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>

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

namespace {

// Process-wide glslang initialisation (thread-safe; glslang parses concurrently once done).
void ensureGlslangInitialized() {
  static std::once_flag once;
  std::call_once(once, [] { glslang::InitializeProcess(); });
}

constexpr auto kMessages = static_cast<EShMessages>(EShMsgSpvRules | EShMsgVulkanRules);

// Each Vulkan version with the SPIR-V version it guarantees (as glslc does).
struct EnvVersions {
  glslang::EShTargetClientVersion client;
  glslang::EShTargetLanguageVersion spirv;
  spv_target_env tools;
};

EnvVersions versionsOf(TargetEnv e) {
  switch (e) {
    case TargetEnv::Vulkan1_0: break;
    case TargetEnv::Vulkan1_1: return {glslang::EShTargetVulkan_1_1, glslang::EShTargetSpv_1_3, SPV_ENV_VULKAN_1_1};
    case TargetEnv::Vulkan1_2: return {glslang::EShTargetVulkan_1_2, glslang::EShTargetSpv_1_5, SPV_ENV_VULKAN_1_2};
    case TargetEnv::Vulkan1_3: return {glslang::EShTargetVulkan_1_3, glslang::EShTargetSpv_1_6, SPV_ENV_VULKAN_1_3};
  }
  return {glslang::EShTargetVulkan_1_0, glslang::EShTargetSpv_1_0, SPV_ENV_VULKAN_1_0};
}

// glslang allocates from a per-thread pool that TShader::parse and TProgram::link replace
// with the object's own and never restore: once that object is destroyed, the thread's
// pool dangles and the next type-to-string or reflection call crashes. Every call into
// glslang here runs inside a PoolScope with a pool the wrapper owns.
class PoolScope {
 public:
  explicit PoolScope(glslang::TPoolAllocator& pool) : previous_(&glslang::GetThreadPoolAllocator()) {
    glslang::SetThreadPoolAllocator(&pool);
  }
  ~PoolScope() { glslang::SetThreadPoolAllocator(previous_); }
  PoolScope(const PoolScope&) = delete;
  PoolScope& operator=(const PoolScope&) = delete;

 private:
  glslang::TPoolAllocator* previous_;
};

EShLanguage languageOf(Stage s) { return s == Stage::Vertex ? EShLangVertex : EShLangFragment; }

std::optional<Type> typeOf(const glslang::TType& t) {
  if (t.isArray() || t.isStruct()) return std::nullopt;
  if (t.isMatrix()) {
    if (t.getBasicType() != glslang::EbtFloat || t.getMatrixCols() != t.getMatrixRows()) return std::nullopt;
    if (t.getMatrixCols() == 3) return Type::Mat3;
    if (t.getMatrixCols() == 4) return Type::Mat4;
    return std::nullopt;
  }
  int n = t.getVectorSize();
  switch (t.getBasicType()) {
    case glslang::EbtFloat: return vectorType(ScalarKind::Float, n);
    case glslang::EbtInt: return vectorType(ScalarKind::Int, n);
    case glslang::EbtUint: return vectorType(ScalarKind::UInt, n);
    default: return std::nullopt;
  }
}

}  // namespace

struct GlslShader::Impl {
  glslang::TPoolAllocator scratch;  // declared first: outlives the glslang objects below
  GlslUnit unit;
  TargetEnv env = TargetEnv::Vulkan1_0;
  EShLanguage lang = EShLangVertex;
  TBuiltInResource resources{};  // what the parse was given (the link reads it too)
  std::unique_ptr<glslang::TShader> shader;
  std::unique_ptr<glslang::TProgram> program;  // this stage linked alone
  std::vector<Diagnostic> diagnostics;
  bool ok = false;
  bool reflected = false;

  // glslang builds a program's reflection once: ask for everything any caller reads.
  glslang::TProgram& reflection() {
    if (!reflected)
      program->buildReflection(EShReflectionAllIOVariables | EShReflectionIntermediateIO |
                               EShReflectionAllBlockVariables);
    reflected = true;
    return *program;
  }
};

GlslShader::GlslShader(const GlslUnit& unit, TargetEnv env) : impl_(std::make_unique<Impl>()) {
  ensureGlslangInitialized();
  Impl& m = *impl_;
  PoolScope scope(m.scratch);
  m.unit = unit;
  m.env = env;
  m.lang = languageOf(unit.stage);
  m.shader = std::make_unique<glslang::TShader>(m.lang);
  // Unnamed: glslang then reports string numbers, which `#line L S` directives set and
  // parseGlslangLog maps to files (a name would stick across #line).
  const char* src = m.unit.text.c_str();
  // A UTF-8 byte-order mark (some Windows editors write one) is no GLSL token: glslang
  // would stop at it. Editors do not show it, so line 1's columns count without it.
  if (m.unit.text.rfind("\xEF\xBB\xBF", 0) == 0) src += 3;
  m.shader->setStrings(&src, 1);
  EnvVersions v = versionsOf(env);
  const bool hlsl = unit.language == SourceLanguage::Hlsl;
  m.shader->setEnvInput(hlsl ? glslang::EShSourceHlsl : glslang::EShSourceGlsl, m.lang, glslang::EShClientVulkan, 100);
  m.shader->setEnvClient(glslang::EShClientVulkan, v.client);
  m.shader->setEnvTarget(glslang::EShTargetSpv, v.spirv);
  EShMessages messages = kMessages;
  if (hlsl) {
    messages = static_cast<EShMessages>(messages | EShMsgReadHlsl);
    m.shader->setEntryPoint("main");
    m.shader->setHlslIoMapping(true);  // registers give bindings
    m.shader->setShiftBinding(glslang::EResTexture, unit.hlslTextureBindingShift);
    m.shader->setAutoMapLocations(true);  // bindSemantics sets the real ones
    m.shader->setEnvTargetHlslFunctionality1();
  }
  m.resources = *GetDefaultResources();
  if (unit.maxCaptureStrideBytes > 0)
    m.resources.maxTransformFeedbackInterleavedComponents = static_cast<int>(unit.maxCaptureStrideBytes / 4);
  bool parsed = m.shader->parse(&m.resources, hlsl ? 500 : 450, ECoreProfile, false, false, messages);
  m.diagnostics = parseGlslangLog(m.shader->getInfoLog(), m.unit);
  if (!parsed) return;
  m.program = std::make_unique<glslang::TProgram>();
  m.program->addShader(m.shader.get());
  if (!m.program->link(messages) || (hlsl && !m.program->mapIO())) {
    auto more = parseGlslangLog(m.program->getInfoLog(), m.unit);
    m.diagnostics.insert(m.diagnostics.end(), more.begin(), more.end());
    return;
  }
  m.ok = true;
}

GlslShader::~GlslShader() = default;
GlslShader::GlslShader(GlslShader&&) noexcept = default;
GlslShader& GlslShader::operator=(GlslShader&&) noexcept = default;

bool GlslShader::ok() const { return impl_->ok; }
const std::vector<Diagnostic>& GlslShader::diagnostics() const { return impl_->diagnostics; }
const GlslUnit& GlslShader::unit() const { return impl_->unit; }
TargetEnv GlslShader::env() const { return impl_->env; }

std::vector<uint32_t> GlslShader::spirv() const {
  if (!impl_->ok) throw std::logic_error("GlslShader::spirv() of a shader that did not compile");
  PoolScope scope(impl_->scratch);
  std::vector<uint32_t> words;
  glslang::SpvOptions opts;
  opts.disableOptimizer = true;
  opts.validate = false;
  glslang::GlslangToSpv(*impl_->program->getIntermediate(impl_->lang), words, &opts);
  return words;
}

namespace {

std::vector<StageVariable> stageVariables(glslang::TProgram& prog, bool outputs) {
  std::vector<StageVariable> out;
  int n = outputs ? prog.getNumPipeOutputs() : prog.getNumPipeInputs();
  for (int i = 0; i < n; ++i) {
    const glslang::TObjectReflection& r = outputs ? prog.getPipeOutput(i) : prog.getPipeInput(i);
    StageVariable v;
    v.name = r.name;
    const glslang::TType* t = r.getType();
    if (t) {
      v.type = typeOf(*t);
      if (t->isArray() && !t->isStruct() && t->getArraySizes()->getNumDims() == 1 && t->getOuterArraySize() > 0) {
        glslang::TType element(*t, 0);  // the array's element type
        v.type = typeOf(element);
        v.arraySize = t->getOuterArraySize();
      }
      v.typeText = t->getCompleteString();
      const auto& q = t->getQualifier();
      if (q.hasLocation()) v.location = static_cast<int>(q.layoutLocation);
      if (q.hasComponent()) v.component = static_cast<int>(q.layoutComponent);
      v.flat = q.flat;
      v.block = t->getBasicType() == glslang::EbtBlock;
      if (v.block) v.blockName = t->getTypeName().c_str();
    }
    if (r.name.find('.') != std::string::npos) {  // glslang's "Block.member"
      v.block = true;
      v.blockName = r.name.substr(0, r.name.find('.'));
    }
    out.push_back(std::move(v));
  }
  return out;
}

}  // namespace

std::vector<StageVariable> GlslShader::inputs() const {
  if (!impl_->ok) return {};
  PoolScope scope(impl_->scratch);
  return stageVariables(impl_->reflection(), false);
}

std::vector<StageVariable> GlslShader::outputs() const {
  if (!impl_->ok) return {};
  PoolScope scope(impl_->scratch);
  return stageVariables(impl_->reflection(), true);
}

std::vector<UniformBlock> GlslShader::uniformBlocks() const {
  std::vector<UniformBlock> out;
  if (!impl_->ok) return out;
  PoolScope scope(impl_->scratch);
  glslang::TProgram& p = impl_->reflection();
  for (int i = 0; i < p.getNumUniformBlocks(); ++i)
    out.push_back(UniformBlock{p.getUniformBlock(i).name, static_cast<uint32_t>(p.getUniformBlock(i).size)});
  return out;
}

std::vector<UniformMember> GlslShader::uniformMembers() const {
  std::vector<UniformMember> out;
  if (!impl_->ok) return out;
  PoolScope scope(impl_->scratch);
  glslang::TProgram& p = impl_->reflection();
  for (int i = 0; i < p.getNumUniformVariables(); ++i) {
    const glslang::TObjectReflection& u = p.getUniform(i);
    UniformMember l;
    l.name = u.name.substr(0, u.name.find('['));
    l.offset = static_cast<uint32_t>(u.offset);
    l.arrayStride = static_cast<uint32_t>(std::max(0, u.arrayStride));
    const glslang::TType* t = u.getType();
    l.matrixStride = t && t->isMatrix() ? 16u : 0u;
    l.size = t && t->isMatrix() ? 16u * static_cast<uint32_t>(t->getMatrixCols())
                                : 4u * static_cast<uint32_t>(t ? std::max(1, t->getVectorSize()) : 1);
    out.push_back(l);
  }
  return out;
}

std::vector<ShaderDescriptor> GlslShader::descriptors() const {
  std::vector<ShaderDescriptor> out;
  if (!impl_->ok) return out;
  PoolScope scope(impl_->scratch);
  glslang::TProgram& p = impl_->reflection();
  auto add = [&](const glslang::TObjectReflection& r, ShaderDescriptor::Kind kind) {
    const glslang::TType* t = r.getType();
    ShaderDescriptor d;
    d.name = r.name;
    // glslang lists buffer blocks with the uniform blocks unless asked to separate them.
    d.kind = t && t->getQualifier().storage == glslang::EvqBuffer ? ShaderDescriptor::Kind::StorageBlock : kind;
    if (t && t->getQualifier().hasSet()) d.set = t->getQualifier().layoutSet;
    if (t && t->getQualifier().hasBinding()) d.binding = t->getQualifier().layoutBinding;
    d.cube = t && t->getBasicType() == glslang::EbtSampler && t->getSampler().dim == glslang::EsdCube;
    out.push_back(std::move(d));
  };
  for (int i = 0; i < p.getNumUniformBlocks(); ++i) add(p.getUniformBlock(i), ShaderDescriptor::Kind::UniformBlock);
  for (int i = 0; i < p.getNumBufferBlocks(); ++i) add(p.getBufferBlock(i), ShaderDescriptor::Kind::StorageBlock);
  for (int i = 0; i < p.getNumUniformVariables(); ++i) {
    const glslang::TObjectReflection& u = p.getUniform(i);
    if (u.getType() && u.getType()->getBasicType() == glslang::EbtSampler) add(u, ShaderDescriptor::Kind::Sampler);
  }
  return out;
}

std::string GlslShader::linkWith(const GlslShader& next) const {
  if (!impl_->ok || !next.impl_->ok) return "a stage failed to compile";
  PoolScope scope(impl_->scratch);
  glslang::TProgram program;
  program.addShader(impl_->shader.get());
  program.addShader(next.impl_->shader.get());
  if (program.link(kMessages)) return "";
  std::string log = program.getInfoLog();
  return log.empty() ? "link failed" : log;
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
  GlslShader s(unit, env);
  CompileResult res;
  res.diagnostics = s.diagnostics();
  if (!s.ok()) return res;
  res.spirv = s.spirv();
  res.ok = true;
  return res;
}

void throwDiagnostics(std::vector<Diagnostic> diags, const std::string& fallbackFile, const char* what) {
  if (diags.empty()) throw InputError(SourceLoc{fallbackFile, 0, 0}, what);
  // Errors first.
  std::stable_partition(diags.begin(), diags.end(), [](const Diagnostic& d) { return d.severity == Severity::Error; });
  InputError e(diags.front());
  e.related.assign(diags.begin() + 1, diags.end());
  throw e;
}

std::string validateSpirv(const std::vector<uint32_t>& words, TargetEnv env) {
  spvtools::SpirvTools tools(versionsOf(env).tools);
  std::string messages;
  tools.SetMessageConsumer([&](spv_message_level_t, const char*, const spv_position_t& pos, const char* msg) {
    messages += fmt::format("spirv-val: instruction {}: {}\n", pos.index, msg);
  });
  if (tools.Validate(words)) return "";
  return messages.empty() ? "spirv-val: invalid module" : messages;
}

std::vector<uint32_t> optimizeSpirv(const std::vector<uint32_t>& words, TargetEnv env, bool unrollLoops) {
  spvtools::Optimizer opt(versionsOf(env).tools);
  std::string messages;
  opt.SetMessageConsumer([&](spv_message_level_t level, const char*, const spv_position_t&, const char* msg) {
    if (level <= SPV_MSG_ERROR) messages += std::string(msg) + "\n";
  });
  opt.RegisterPerformancePasses();
  std::vector<uint32_t> in = words;
  if (unrollLoops) {
    // The unroller only takes loops marked Unroll: mark every loop (OpLoopMerge's control).
    constexpr uint32_t kOpLoopMerge = 246, kUnroll = 0x1, kDontUnroll = 0x2;
    for (size_t i = 5; i < in.size();) {
      const uint32_t len = in[i] >> 16;
      if (len == 0 || i + len > in.size()) break;
      if ((in[i] & 0xffffu) == kOpLoopMerge && len >= 4) in[i + 3] = (in[i + 3] & ~kDontUnroll) | kUnroll;
      i += len;
    }
    opt.RegisterPass(spvtools::CreateLoopUnrollPass(true));
    opt.RegisterPerformancePasses();
  }
  std::vector<uint32_t> out;
  if (!opt.Run(in.data(), in.size(), &out)) throw std::runtime_error("spirv-opt failed: " + messages);
  return out;
}

namespace {

// A module as its instructions (each with its opcode word), for the rewrites below.
struct SpirvInstructions {
  std::vector<uint32_t> header;
  std::vector<std::vector<uint32_t>> ops;

  explicit SpirvInstructions(const std::vector<uint32_t>& words) {
    if (words.size() < 5) throw std::invalid_argument("not a SPIR-V module");
    header.assign(words.begin(), words.begin() + 5);
    for (size_t i = 5; i < words.size();) {
      const uint32_t len = words[i] >> 16;
      if (len == 0 || i + len > words.size()) throw std::invalid_argument("truncated SPIR-V instruction");
      ops.emplace_back(words.begin() + static_cast<long>(i), words.begin() + static_cast<long>(i + len));
      i += len;
    }
  }
  std::vector<uint32_t> words() const {
    std::vector<uint32_t> out = header;
    for (const auto& op : ops) out.insert(out.end(), op.begin(), op.end());
    return out;
  }
  static uint32_t opcode(const std::vector<uint32_t>& op) { return op[0] & 0xffffu; }
  static std::vector<uint32_t> make(spv::Op code, std::vector<uint32_t> operands) {
    operands.insert(operands.begin(), (static_cast<uint32_t>(operands.size() + 1) << 16) | code);
    return operands;
  }
  // A literal string operand starting at word `at`.
  static std::string string(const std::vector<uint32_t>& op, size_t at) {
    std::string s;
    for (size_t w = at; w < op.size(); ++w)
      for (int b = 0; b < 4; ++b) {
        char c = static_cast<char>((op[w] >> (8 * b)) & 0xffu);
        if (c == 0) return s;
        s += c;
      }
    return s;
  }
  // Interface variables of a storage class.
  std::vector<uint32_t> variables(spv::StorageClass sc) const {
    std::vector<uint32_t> ids;
    for (const auto& op : ops)
      if (opcode(op) == spv::OpVariable && op.size() >= 4 && op[3] == static_cast<uint32_t>(sc)) ids.push_back(op[2]);
    return ids;
  }
  // The operand of `OpDecorate id decoration operand`, or -1.
  int64_t decoration(uint32_t id, spv::Decoration d) const {
    for (const auto& op : ops)
      if (opcode(op) == spv::OpDecorate && op.size() >= 4 && op[1] == id && op[2] == static_cast<uint32_t>(d)) return op[3];
    return -1;
  }
  void setDecoration(uint32_t id, spv::Decoration d, uint32_t value) {
    size_t firstAnnotation = ops.size();
    for (size_t i = 0; i < ops.size(); ++i) {
      const uint32_t code = opcode(ops[i]);
      if (code == spv::OpDecorate && ops[i].size() >= 4 && ops[i][1] == id && ops[i][2] == static_cast<uint32_t>(d)) {
        ops[i][3] = value;
        return;
      }
      if (firstAnnotation == ops.size() && (code == spv::OpDecorate || code == spv::OpMemberDecorate ||
                                            code == spv::OpDecorateString || code == spv::OpMemberDecorateString))
        firstAnnotation = i;
    }
    ops.insert(ops.begin() + static_cast<long>(firstAnnotation), make(spv::OpDecorate, {id, static_cast<uint32_t>(d), value}));
  }
};

std::string upper(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

std::vector<uint32_t> bindSemantics(const std::vector<uint32_t>& words, const std::map<std::string, int>& inputs,
                                    const std::map<std::string, int>& outputs, const std::string& name) {
  SpirvInstructions m(words);
  constexpr auto kSemantic = static_cast<uint32_t>(spv::DecorationHlslSemanticGOOGLE);
  std::map<uint32_t, std::string> semantics;  // variable id -> semantic
  for (const auto& op : m.ops)
    if (SpirvInstructions::opcode(op) == spv::OpDecorateString && op.size() >= 4 && op[2] == kSemantic)
      semantics[op[1]] = upper(SpirvInstructions::string(op, 3));
  for (auto [sc, table, what] : {std::tuple{spv::StorageClassInput, &inputs, "input"},
                                 std::tuple{spv::StorageClassOutput, &outputs, "output"}}) {
    std::map<std::string, int> byName;
    for (const auto& [k, loc] : *table) byName[upper(k)] = loc;
    for (uint32_t id : m.variables(sc)) {
      if (m.decoration(id, spv::DecorationBuiltIn) >= 0) continue;  // SV_Position and other system values
      auto s = semantics.find(id);
      auto to = s == semantics.end() ? byName.end() : byName.find(s->second);
      if (to == byName.end())
        throw InputError(SourceLoc{name, 0, 0},
                         fmt::format("HLSL vertex {} with semantic '{}' is not in the reflection", what,
                                     s == semantics.end() ? std::string("(none)") : s->second));
      m.setDecoration(id, spv::DecorationLocation, static_cast<uint32_t>(to->second));
    }
  }
  // Drop the semantic strings and the extensions that declare them.
  std::vector<std::vector<uint32_t>> kept;
  for (auto& op : m.ops) {
    const uint32_t code = SpirvInstructions::opcode(op);
    if ((code == spv::OpDecorateString || code == spv::OpMemberDecorateString) && op.size() >= 3 &&
        (op[2] == kSemantic || op[2] == static_cast<uint32_t>(spv::DecorationUserTypeGOOGLE) ||
         (code == spv::OpMemberDecorateString && op.size() >= 4 &&
          (op[3] == kSemantic || op[3] == static_cast<uint32_t>(spv::DecorationUserTypeGOOGLE)))))
      continue;
    if (code == spv::OpExtension && SpirvInstructions::string(op, 1).rfind("SPV_GOOGLE_", 0) == 0) continue;
    kept.push_back(std::move(op));
  }
  m.ops = std::move(kept);
  return m.words();
}

std::vector<uint32_t> withCapture(const std::vector<uint32_t>& words, uint32_t stride,
                                  const std::map<int, uint32_t>& offsets) {
  SpirvInstructions m(words);
  for (uint32_t id : m.variables(spv::StorageClassOutput)) {
    const int64_t builtIn = m.decoration(id, spv::DecorationBuiltIn), location = m.decoration(id, spv::DecorationLocation);
    if (builtIn >= 0 ? builtIn != spv::BuiltInPosition : location < 0) continue;  // not captured
    auto at = offsets.find(builtIn >= 0 ? -1 : static_cast<int>(location));
    if (at == offsets.end()) continue;
    m.setDecoration(id, spv::DecorationXfbBuffer, 0);
    m.setDecoration(id, spv::DecorationXfbStride, stride);
    m.setDecoration(id, spv::DecorationOffset, at->second);
  }
  size_t lastCapability = 0, entry = 0;
  for (size_t i = 0; i < m.ops.size(); ++i) {
    if (SpirvInstructions::opcode(m.ops[i]) == spv::OpCapability) lastCapability = i;
    if (SpirvInstructions::opcode(m.ops[i]) == spv::OpEntryPoint) entry = i;
  }
  const uint32_t entryId = m.ops.at(entry).at(2);
  m.ops.insert(m.ops.begin() + static_cast<long>(entry) + 1,
               SpirvInstructions::make(spv::OpExecutionMode, {entryId, static_cast<uint32_t>(spv::ExecutionModeXfb)}));
  m.ops.insert(m.ops.begin() + static_cast<long>(lastCapability) + 1,
               SpirvInstructions::make(spv::OpCapability, {static_cast<uint32_t>(spv::CapabilityTransformFeedback)}));
  return m.words();
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

}  // namespace sg
