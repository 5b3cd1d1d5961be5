#include "emit/cross_compile.h"

#include <fmt/format.h>
#include <spirv_cross_c.h>

#include <algorithm>
#include <memory>
#include <tuple>

#include "common/diagnostics.h"

namespace sg {

const char* const kShaderModels = "5.0, 5.1, 6.0 .. 6.7";
const char* const kMslVersions = "1.2, 2.0 .. 2.4, 3.0";

namespace {

// "M.N" with one digit each side.
bool splitVersion(const std::string& s, int& major, int& minor) {
  if (s.size() != 3 || s[1] != '.' || s[0] < '0' || s[0] > '9' || s[2] < '0' || s[2] > '9') return false;
  major = s[0] - '0';
  minor = s[2] - '0';
  return true;
}

// Locations a vertex output occupies: one per matrix column, times the array elements.
int slotsOf(Type t, int arraySize) {
  int columns = t == Type::Mat3 ? 3 : t == Type::Mat4 ? 4 : 1;
  return columns * std::max(1, arraySize);
}

// One SPIRV-Cross context per translation; every call's failure becomes an InputError
// carrying the library's own message.
class Cross {
 public:
  explicit Cross(std::string name) : name_(std::move(name)) {
    if (spvc_context_create(&ctx_) != SPVC_SUCCESS) fail("SPIRV-Cross: cannot create a context");
  }
  ~Cross() { spvc_context_destroy(ctx_); }
  Cross(const Cross&) = delete;
  Cross& operator=(const Cross&) = delete;

  [[noreturn]] void fail(const std::string& what) const {
    const char* detail = ctx_ ? spvc_context_get_last_error_string(ctx_) : "";
    throw InputError(SourceLoc{name_, 0, 0},
                     detail && *detail ? fmt::format("{}: {}", what, detail) : what);
  }
  void check(spvc_result r, const char* what) const {
    if (r != SPVC_SUCCESS) fail(fmt::format("SPIRV-Cross: {}", what));
  }

  spvc_compiler compiler(const std::vector<uint32_t>& words, spvc_backend backend) {
    spvc_parsed_ir ir = nullptr;
    check(spvc_context_parse_spirv(ctx_, words.data(), words.size(), &ir), "cannot parse the SPIR-V");
    spvc_compiler c = nullptr;
    check(spvc_context_create_compiler(ctx_, backend, ir, SPVC_CAPTURE_MODE_TAKE_OWNERSHIP, &c),
          "cannot create a compiler");
    return c;
  }

  // The module's buffers as (id, GLSL block name, set, binding, is uniform block), by binding.
  struct Buffer {
    spvc_variable_id id;
    std::string block;
    uint32_t set, binding;
    bool uniform;
  };
  std::vector<Buffer> buffers(spvc_compiler c) {
    spvc_resources res = nullptr;
    check(spvc_compiler_create_shader_resources(c, &res), "cannot reflect the resources");
    std::vector<Buffer> out;
    for (auto [type, uniform] : {std::pair{SPVC_RESOURCE_TYPE_UNIFORM_BUFFER, true},
                                 std::pair{SPVC_RESOURCE_TYPE_STORAGE_BUFFER, false}}) {
      const spvc_reflected_resource* list = nullptr;
      size_t n = 0;
      check(spvc_resources_get_resource_list_for_type(res, type, &list, &n), "cannot list the resources");
      for (size_t i = 0; i < n; ++i)
        out.push_back(Buffer{list[i].id, list[i].name,
                             spvc_compiler_get_decoration(c, list[i].id, SpvDecorationDescriptorSet),
                             spvc_compiler_get_decoration(c, list[i].id, SpvDecorationBinding), uniform});
    }
    std::sort(out.begin(), out.end(), [](const Buffer& a, const Buffer& b) {
      return std::tie(a.set, a.binding) < std::tie(b.set, b.binding);
    });
    return out;
  }

  spvc_compiler_options options(spvc_compiler c) {
    spvc_compiler_options o = nullptr;
    check(spvc_compiler_create_compiler_options(c, &o), "cannot create options");
    return o;
  }

  std::string compile(spvc_compiler c, spvc_compiler_options o) {
    check(spvc_compiler_install_compiler_options(c, o), "cannot set the options");
    const char* text = nullptr;
    check(spvc_compiler_compile(c, &text), "cannot translate the SPIR-V");
    return text ? text : "";
  }

 private:
  std::string name_;
  spvc_context ctx_ = nullptr;
};

// The names the translated source gives the buffers: stable across plans and -O (SPIRV-Cross
// would otherwise name an anonymous block by its SPIR-V id).
std::string variableName(const Cross::Buffer& b, const EmittedGlsl& glsl) {
  if (b.uniform) return "uniforms";
  for (const auto& e : glsl.buffers)
    if (static_cast<uint32_t>(e.binding) == b.binding) return e.name + "_data";
  return fmt::format("buffer{}", b.binding);
}

std::vector<CrossVariable> inputsOf(const EmittedGlsl& glsl) {
  std::vector<CrossVariable> out;
  for (const auto& in : glsl.inputs) out.push_back(CrossVariable{in.name, in.location, 1, ""});
  return out;
}

std::vector<CrossVariable> outputsOf(const EmittedGlsl& glsl) {
  std::vector<CrossVariable> out;
  for (const auto& o : glsl.outputs) out.push_back(CrossVariable{o.name, o.location, slotsOf(o.type, o.arraySize), ""});
  return out;
}

}  // namespace

bool parseShaderModel(const std::string& s, int& out) {
  int major = 0, minor = 0;
  if (!splitVersion(s, major, minor)) return false;
  // Vertex shaders read storage buffers as ByteAddressBuffer from 5.0; 6.7 is the newest
  // model DXC knows.
  if (!((major == 5 && minor <= 1) || (major == 6 && minor <= 7))) return false;
  out = major * 10 + minor;
  return true;
}

bool parseMslVersion(const std::string& s, MslOptions& out) {
  int major = 0, minor = 0;
  if (!splitVersion(s, major, minor)) return false;
  if (!((major == 1 && minor == 2) || (major == 2 && minor <= 4) || (major == 3 && minor == 0))) return false;
  out.major = major;
  out.minor = minor;
  return true;
}

bool parseMslPlatform(const std::string& s, MslPlatform& out) {
  if (s == "macos") out = MslPlatform::MacOS;
  else if (s == "ios") out = MslPlatform::IOS;
  else return false;
  return true;
}

std::string shaderModelName(int shaderModel) { return fmt::format("{}.{}", shaderModel / 10, shaderModel % 10); }
std::string mslVersionName(const MslOptions& o) { return fmt::format("{}.{}", o.major, o.minor); }
const char* mslPlatformName(MslPlatform p) { return p == MslPlatform::IOS ? "ios" : "macos"; }

CrossShader translateToHlsl(const std::vector<uint32_t>& spirv, const EmittedGlsl& glsl, const HlslOptions& opts,
                            const std::string& name) {
  Cross cross(name);
  spvc_compiler c = cross.compiler(spirv, SPVC_BACKEND_HLSL);
  spvc_compiler_options o = cross.options(c);
  cross.check(spvc_compiler_options_set_uint(o, SPVC_COMPILER_OPTION_HLSL_SHADER_MODEL,
                                             static_cast<unsigned>(opts.shaderModel)),
              "shader model");
  CrossShader out;
  out.version = shaderModelName(opts.shaderModel);
  out.profile = fmt::format("vs_{}_{}", opts.shaderModel / 10, opts.shaderModel % 10);
  // Vertex inputs: TEXCOORD<location>, set explicitly so the semantic is ours, not a default.
  out.inputs = inputsOf(glsl);
  for (auto& in : out.inputs) {
    in.binding = fmt::format("TEXCOORD{}", in.location);
    spvc_hlsl_vertex_attribute_remap remap{static_cast<unsigned>(in.location), in.binding.c_str()};
    cross.check(spvc_compiler_hlsl_add_vertex_attribute_remap(c, &remap, 1), "vertex input semantic");
  }
  // Outputs: SPIRV-Cross names a user output TEXCOORD<location> (the following locations for
  // its further columns or elements); the round trip (validate --via hlsl) binds by these.
  out.outputs = outputsOf(glsl);
  for (auto& v : out.outputs) v.binding = v.location < 0 ? "SV_Position" : fmt::format("TEXCOORD{}", v.location);
  // Registers: the uniform block b0, storage buffers t0, t1, ... in binding order (space 0).
  uint32_t srv = 0;
  for (const auto& b : cross.buffers(c)) {
    CrossResource r{b.block, variableName(b, glsl), b.uniform, b.set, b.binding, "", b.uniform ? 0u : srv++};
    r.slot = fmt::format("{}{}", b.uniform ? 'b' : 't', r.index);
    spvc_hlsl_resource_binding rb;
    spvc_hlsl_resource_binding_init(&rb);
    rb.stage = SpvExecutionModelVertex;
    rb.desc_set = b.set;
    rb.binding = b.binding;
    rb.cbv = {0, r.index};
    rb.srv = {0, r.index};
    cross.check(spvc_compiler_hlsl_add_resource_binding(c, &rb), "register binding");
    spvc_compiler_set_name(c, b.id, r.variable.c_str());
    out.resources.push_back(std::move(r));
  }
  out.text = cross.compile(c, o);
  for (const auto& r : out.resources)
    if (!spvc_compiler_hlsl_is_resource_used(c, SpvExecutionModelVertex, r.set, r.binding))
      cross.fail(fmt::format("SPIRV-Cross did not use the register {} asked for {}", r.slot, r.name));
  out.entryPoint = spvc_compiler_get_cleansed_entry_point_name(c, "main", SpvExecutionModelVertex);
  return out;
}

CrossShader translateToMsl(const std::vector<uint32_t>& spirv, const EmittedGlsl& glsl, const MslOptions& opts,
                           const std::string& name) {
  Cross cross(name);
  spvc_compiler c = cross.compiler(spirv, SPVC_BACKEND_MSL);
  spvc_compiler_options o = cross.options(c);
  cross.check(spvc_compiler_options_set_uint(o, SPVC_COMPILER_OPTION_MSL_VERSION,
                                             SPVC_MAKE_MSL_VERSION(opts.major, opts.minor, 0)),
              "MSL version");
  cross.check(spvc_compiler_options_set_uint(
                  o, SPVC_COMPILER_OPTION_MSL_PLATFORM,
                  opts.platform == MslPlatform::IOS ? SPVC_MSL_PLATFORM_IOS : SPVC_MSL_PLATFORM_MACOS),
              "MSL platform");
  CrossShader out;
  out.hlsl = false;
  out.version = mslVersionName(opts);
  out.profile = mslPlatformName(opts.platform);
  out.inputs = inputsOf(glsl);
  for (auto& in : out.inputs) in.binding = fmt::format("attribute({})", in.location);
  out.outputs = outputsOf(glsl);
  for (auto& v : out.outputs) v.binding = v.location < 0 ? "position" : fmt::format("user(locn{})", v.location);
  // [[buffer(n)]]: the uniform block 0, storage buffers 1, 2, ... in binding order; Metal
  // shares this table with the vertex buffers, which take the indices after them.
  uint32_t next = 1;
  for (const auto& b : cross.buffers(c)) {
    CrossResource r{b.block, variableName(b, glsl), b.uniform, b.set, b.binding, "", b.uniform ? 0u : next++};
    r.slot = fmt::format("buffer({})", r.index);
    spvc_msl_resource_binding rb;
    spvc_msl_resource_binding_init(&rb);
    rb.stage = SpvExecutionModelVertex;
    rb.desc_set = b.set;
    rb.binding = b.binding;
    rb.msl_buffer = r.index;
    cross.check(spvc_compiler_msl_add_resource_binding(c, &rb), "buffer binding");
    spvc_compiler_set_name(c, b.id, r.variable.c_str());
    out.resources.push_back(std::move(r));
  }
  out.firstVertexBuffer = next;
  out.text = cross.compile(c, o);
  // Read back what the compiler used from its own parse: the reflection must say what the
  // text declares.
  for (const auto& b : cross.buffers(c)) {
    auto r = std::find_if(out.resources.begin(), out.resources.end(),
                          [&](const CrossResource& x) { return x.set == b.set && x.binding == b.binding; });
    if (r == out.resources.end() || !spvc_compiler_msl_is_resource_used(c, SpvExecutionModelVertex, b.set, b.binding) ||
        spvc_compiler_msl_get_automatic_resource_binding(c, b.id) != r->index)
      cross.fail(fmt::format("SPIRV-Cross did not place {} at [[{}]]", b.block, r == out.resources.end() ? "?" : r->slot));
  }
  out.entryPoint = spvc_compiler_get_cleansed_entry_point_name(c, "main", SpvExecutionModelVertex);
  return out;
}

}  // namespace sg
