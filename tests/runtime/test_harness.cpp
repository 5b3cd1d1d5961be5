// The Vulkan harness against CPU-computed expectations: every captured float of
// every vertex, with the validation layer on and silent, its synchronization checks too
// (the staging copies of device-local inputs need their barrier).
#include "runtime/vk_harness.h"

#include "common/glsl_compile.h"
#include "runtime/vk_setup.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <memory>
#include <random>
#include <sstream>

#include "synchronization_validation.h"

namespace {

using sg::rt::Harness;
using sg::rt::RunRequest;
using sg::rt::RunResult;
using sg::rt::VertexStream;

std::vector<uint32_t> compileVertexShader(const std::string& source) {
  sg::CompileResult r = sg::compileGlsl(sg::GlslUnit{sg::Stage::Vertex, source, "test.vert", {}}, sg::TargetEnv::Vulkan1_0);
  if (!r.ok) {
    std::string log;
    for (const auto& d : r.diagnostics) log += sg::renderDiagnostic(d) + "\n";
    throw std::runtime_error("GLSL compile failed:\n" + log);
  }
  return r.spirv;
}

constexpr int kBones = 8;
constexpr uint32_t kStride = 100;  // the Dawn face shader's output record size
constexpr uint32_t kUsedBytes = 76;

// Skinning-like shader over three stream formats; bytes 76..99 of each record are padding.
const char* kSkinShader = R"(#version 450
layout(location = 0) in vec3 inPosition;   // R32G32B32_SFLOAT
layout(location = 1) in uvec4 inJoints;    // R8G8B8A8_UINT
layout(location = 2) in vec4 inWeights;    // R8G8B8A8_UNORM

layout(set = 0, binding = 0, std140) uniform Params {
  mat4 bones[8];
  float scale;
} params;

out gl_PerVertex { layout(xfb_buffer = 0, xfb_offset = 0) vec4 gl_Position; };

layout(location = 0, xfb_buffer = 0, xfb_offset = 16, xfb_stride = 100) out vec3 outSkinned;
layout(location = 1, xfb_buffer = 0, xfb_offset = 28) out float outWeightSum;
layout(location = 2, xfb_buffer = 0, xfb_offset = 32) out vec4 outWeights;
layout(location = 3, xfb_buffer = 0, xfb_offset = 48) out vec4 outJoints;
layout(location = 4, xfb_buffer = 0, xfb_offset = 64) out vec3 outPosition;

void main() {
  vec4 p = vec4(inPosition, 1.0);
  vec4 s = vec4(0.0);
  for (int i = 0; i < 4; ++i) s += inWeights[i] * (params.bones[inJoints[i] & 7u] * p);
  outSkinned = s.xyz;
  outWeightSum = inWeights.x + inWeights.y + inWeights.z + inWeights.w;
  outWeights = inWeights;
  outJoints = vec4(inJoints);
  outPosition = inPosition;
  gl_Position = vec4(s.xyz * params.scale, 1.0);
}
)";

struct Mat4 {
  float m[4][4];  // m[column][row], as std140 stores it
};

struct SkinInput {
  uint32_t vertexCount = 0;
  uint32_t positionStride = 12;
  std::vector<float> positions;  // 3 per vertex
  std::vector<uint8_t> joints;   // 4 per vertex
  std::vector<uint8_t> weights;  // 4 per vertex
  Mat4 bones[kBones];
  float scale = 0;
};

SkinInput makeInput(uint32_t vertexCount, uint32_t seed, uint32_t positionStride = 12) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-2.0f, 2.0f), unit(-1.0f, 1.0f);
  std::uniform_int_distribution<int> byte(0, 255);
  SkinInput in;
  in.vertexCount = vertexCount;
  in.positionStride = positionStride;
  for (auto& b : in.bones)
    for (auto& col : b.m)
      for (float& v : col) v = unit(rng);
  in.scale = 0.5f + 0.25f * unit(rng);
  in.positions.resize(size_t(vertexCount) * 3);
  in.joints.resize(size_t(vertexCount) * 4);
  in.weights.resize(size_t(vertexCount) * 4);
  for (float& v : in.positions) v = pos(rng);
  for (uint8_t& v : in.joints) v = uint8_t(byte(rng));
  for (uint8_t& v : in.weights) v = uint8_t(byte(rng));
  return in;
}

RunRequest makeRequest(const SkinInput& in, const std::vector<uint32_t>& spirv) {
  RunRequest req;
  req.spirv = spirv;
  req.vertexCount = in.vertexCount;
  req.capture.strideBytes = kStride;

  VertexStream position{0, VK_FORMAT_R32G32B32_SFLOAT, in.positionStride, {}};
  position.data.assign(size_t(in.vertexCount) * in.positionStride, 0xCD);  // junk in the gaps
  for (uint32_t v = 0; v < in.vertexCount; ++v)
    std::memcpy(&position.data[size_t(v) * in.positionStride], &in.positions[size_t(v) * 3], 12);
  VertexStream joints{1, VK_FORMAT_R8G8B8A8_UINT, 4, in.joints};
  VertexStream weights{2, VK_FORMAT_R8G8B8A8_UNORM, 4, in.weights};
  req.streams = {position, joints, weights};

  req.uniformData.assign(528, 0);  // std140: bones at 0, scale at 512, block padded to 16
  std::memcpy(req.uniformData.data(), in.bones, sizeof(in.bones));
  std::memcpy(req.uniformData.data() + 512, &in.scale, sizeof(float));
  return req;
}

// Counts mismatches; a float matches when |got - want| <= 1e-5 * max(|want|, magnitude),
// magnitude being the sum of |terms| that produced it (relative error of a sum).
struct Checker {
  size_t mismatches = 0;
  std::ostringstream report;
  void expect(const char* what, uint32_t vertex, int component, float got, double want, double magnitude = 0) {
    double tol = 1e-5 * std::max(std::abs(want), magnitude);
    if (std::abs(double(got) - want) <= tol) return;
    if (mismatches++ < 10)
      report << "vertex " << vertex << " " << what << "[" << component << "]: got " << got << ", want " << want << "\n";
  }
};

void checkSkinOutputs(const SkinInput& in, const RunResult& res) {
  ASSERT_EQ(res.captured.size(), size_t(in.vertexCount) * kStride);
  Checker c;
  size_t nonzeroPadding = 0;
  for (uint32_t v = 0; v < in.vertexCount; ++v) {
    const uint8_t* rec = &res.captured[size_t(v) * kStride];
    auto f = [&](uint32_t offset) {
      float x;
      std::memcpy(&x, rec + offset, 4);
      return x;
    };
    const float* p = &in.positions[size_t(v) * 3];
    const uint8_t* j = &in.joints[size_t(v) * 4];
    double w[4], skinned[3] = {0, 0, 0}, magnitude[3] = {0, 0, 0}, weightSum = 0;
    for (int i = 0; i < 4; ++i) {
      w[i] = in.weights[size_t(v) * 4 + i] / 255.0;
      weightSum += w[i];
      const Mat4& m = in.bones[j[i] & 7];
      for (int r = 0; r < 3; ++r) {
        double terms[4] = {m.m[0][r] * double(p[0]), m.m[1][r] * double(p[1]), m.m[2][r] * double(p[2]), double(m.m[3][r])};
        for (double t : terms) {
          skinned[r] += w[i] * t;
          magnitude[r] += std::abs(w[i] * t);
        }
      }
    }
    for (int r = 0; r < 3; ++r) {
      c.expect("gl_Position", v, r, f(4 * r), skinned[r] * in.scale, magnitude[r] * std::abs(in.scale));
      c.expect("outSkinned", v, r, f(16 + 4 * r), skinned[r], magnitude[r]);
      c.expect("outPosition", v, r, f(64 + 4 * r), p[r]);
    }
    c.expect("gl_Position", v, 3, f(12), 1.0);
    c.expect("outWeightSum", v, 0, f(28), weightSum);
    for (int i = 0; i < 4; ++i) {
      c.expect("outWeights", v, i, f(32 + 4 * i), w[i]);
      c.expect("outJoints", v, i, f(48 + 4 * i), j[i]);
    }
    for (uint32_t b = kUsedBytes; b < kStride; ++b) nonzeroPadding += rec[b] != 0;
  }
  EXPECT_EQ(c.mismatches, 0u) << c.report.str();
  EXPECT_EQ(nonzeroPadding, 0u) << "bytes no output writes must read back as zero";
}

std::string joinMessages(const Harness& h) {
  std::string all;
  for (const auto& m : h.validationMessages()) all += m + "\n";
  return all;
}

class HarnessTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    sgtest::enableSynchronizationValidation();
    harness_ = std::make_unique<Harness>();
    skinSpirv_ = compileVertexShader(kSkinShader);
  }
  static void TearDownTestSuite() { harness_.reset(); }
  void TearDown() override {
    EXPECT_TRUE(harness_->validationMessages().empty()) << joinMessages(*harness_);
  }
  static std::unique_ptr<Harness> harness_;
  static std::vector<uint32_t> skinSpirv_;
};
std::unique_ptr<Harness> HarnessTest::harness_;
std::vector<uint32_t> HarnessTest::skinSpirv_;

TEST_F(HarnessTest, PicksLavapipeByDefault) {
  EXPECT_NE(harness_->deviceName().find("llvmpipe"), std::string::npos) << harness_->deviceName();
  if (!harness_->validationEnabled()) std::cout << "note: VK_LAYER_KHRONOS_validation not installed; running without it\n";
}

TEST_F(HarnessTest, CapturesEveryOutputOfSeveralThousandVertices) {
  SkinInput in = makeInput(5000, 1);
  RunResult res = harness_->run(makeRequest(in, skinSpirv_));
  checkSkinOutputs(in, res);
}

TEST_F(HarnessTest, HonoursStreamStrideLargerThanTheFormat) {
  SkinInput in = makeInput(3001, 2, /*positionStride=*/20);
  RunResult res = harness_->run(makeRequest(in, skinSpirv_));
  checkSkinOutputs(in, res);
}

TEST_F(HarnessTest, RunsAtDawnScale) {
  SkinInput in = makeInput(200000, 3);
  RunResult res = harness_->run(makeRequest(in, skinSpirv_));
  checkSkinOutputs(in, res);
  const auto& t = res.timings;
  std::cout << "200000 vertices x " << kStride << " bytes: setup " << t.setupMs << " ms, upload " << t.uploadMs
            << " ms, run " << t.runMs << " ms, readback " << t.readbackMs << " ms\n";
  EXPECT_GT(t.runMs, 0.0);
}

TEST_F(HarnessTest, RepeatedRunsAreByteIdentical) {
  SkinInput in = makeInput(2048, 4);
  RunRequest req = makeRequest(in, skinSpirv_);
  RunResult a = harness_->run(req);
  RunResult b = harness_->run(req);
  EXPECT_TRUE(a.captured == b.captured);
}

// Every kind of input (a stream, the uniform block, a storage buffer) read from device-local
// memory through a staging copy and from mapped memory: the same exact outputs either way.
TEST_F(HarnessTest, InputsInDeviceLocalAndMappedMemoryGiveTheSameOutputs) {
  const char* src = R"(#version 450
layout(location = 0) in vec4 inValue;
layout(set = 0, binding = 0, std140) uniform Params { vec4 offset; } params;
layout(set = 0, binding = 1, std430) readonly buffer Scales { float scales[]; };
out gl_PerVertex { layout(xfb_buffer = 0, xfb_offset = 0, xfb_stride = 16) vec4 gl_Position; };
void main() { gl_Position = inValue * scales[gl_VertexIndex] + params.offset; }
)";
  const uint32_t n = 1001;  // odd: the capture pads to 1002 vertices, the storage buffer covers them
  std::vector<float> values(size_t(n) * 4), scales(n + 1);
  for (size_t i = 0; i < values.size(); ++i) values[i] = float(i % 97) - 48.0f;
  for (size_t i = 0; i < scales.size(); ++i) scales[i] = float(i % 5) + 0.5f;
  const float offset[4] = {1, -2, 3, -4};
  RunRequest req;
  req.spirv = compileVertexShader(src);
  req.vertexCount = n;
  req.capture.strideBytes = 16;
  VertexStream s{0, VK_FORMAT_R32G32B32A32_SFLOAT, 16, std::vector<uint8_t>(values.size() * 4)};
  std::memcpy(s.data.data(), values.data(), s.data.size());
  req.streams = {s};
  req.uniformData.resize(sizeof offset);
  std::memcpy(req.uniformData.data(), offset, sizeof offset);
  sg::rt::StorageBufferData sb;
  sb.binding = 1;
  sb.data.resize(scales.size() * 4);
  std::memcpy(sb.data.data(), scales.data(), sb.data.size());
  req.storageBuffers = {sb};
  req.declared = {{0, 0, sg::rt::DescriptorKind::UniformBuffer, "Params"}, {0, 1, sg::rt::DescriptorKind::StorageBuffer, "Scales"}};
  for (sg::rt::InputMemory memory : {sg::rt::InputMemory::DeviceLocal, sg::rt::InputMemory::Mapped}) {
    req.memory = memory;
    RunResult res = harness_->run(req);
    ASSERT_EQ(res.captured.size(), size_t(n) * 16);
    Checker c;
    for (uint32_t v = 0; v < n; ++v) {
      float rec[4];
      std::memcpy(rec, &res.captured[size_t(v) * 16], 16);
      for (int i = 0; i < 4; ++i) c.expect("gl_Position", v, i, rec[i], values[size_t(v) * 4 + i] * scales[v] + offset[i]);
    }
    EXPECT_EQ(c.mismatches, 0u) << (memory == sg::rt::InputMemory::Mapped ? "mapped: " : "device-local: ") << c.report.str();
  }
}

// The memory types a discrete NVIDIA GPU lists (the order of Vulkan-ValidationLayers issue
// 5908's dump; the heap sizes of an RTX 2070 Super under Linux, iree issue 5268): a 246 MiB
// device-local window that the host can map, beside all of video memory and system memory.
VkPhysicalDeviceMemoryProperties discreteGpuMemory() {
  VkPhysicalDeviceMemoryProperties m{};
  m.memoryHeapCount = 3;
  m.memoryHeaps[0] = {8ull << 30, VK_MEMORY_HEAP_DEVICE_LOCAL_BIT};
  m.memoryHeaps[1] = {25235137536ull, 0};
  m.memoryHeaps[2] = {246ull << 20, VK_MEMORY_HEAP_DEVICE_LOCAL_BIT};
  m.memoryTypeCount = 4;
  m.memoryTypes[0] = {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0};
  m.memoryTypes[1] = {VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT, 1};
  m.memoryTypes[2] = {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT, 2};
  m.memoryTypes[3] = {VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT | VK_MEMORY_PROPERTY_HOST_CACHED_BIT, 1};
  return m;
}

TEST(MemoryTypes, DeviceLocalInputsLandInVideoMemoryAndMappedOnesInTheWindow) {
  using sg::rt::setup::chooseMemoryType;
  const VkPhysicalDeviceMemoryProperties m = discreteGpuMemory();
  const VkMemoryPropertyFlags hostWritten = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  // Device-local: the first type with the flag, all of video memory, not the mappable window.
  EXPECT_EQ(chooseMemoryType(m, 0xF, 0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT), 0u);
  // Mapped with device-local preferred: the window; where a buffer may not use it, system memory.
  EXPECT_EQ(chooseMemoryType(m, 0xF, hostWritten, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT), 2u);
  EXPECT_EQ(chooseMemoryType(m, 0xB, hostWritten, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT), 1u);
  // Read back by the host: cached system memory.
  EXPECT_EQ(chooseMemoryType(m, 0xF, hostWritten, VK_MEMORY_PROPERTY_HOST_CACHED_BIT), 3u);
  EXPECT_EQ(chooseMemoryType(m, 0x1, hostWritten, 0), UINT32_MAX);
  EXPECT_EQ(sg::rt::setup::describeMemoryType(m, 2),
            "type 2 (device-local, host-visible, host-coherent) of heap 2 (246 MiB, device-local)");
  EXPECT_EQ(sg::rt::setup::describeMemoryType(m, 0), "type 0 (device-local) of heap 0 (8.0 GiB, device-local)");
  EXPECT_EQ(sg::rt::setup::describeMemoryType(m, 1), "type 1 (host-visible, host-coherent) of heap 1 (23.5 GiB, host)");
}

TEST_F(HarnessTest, RunsWithoutUniformBlock) {
  const char* src = R"(#version 450
layout(location = 3) in vec4 inValue;
out gl_PerVertex { layout(xfb_buffer = 0, xfb_offset = 0) vec4 gl_Position; };
layout(location = 0, xfb_buffer = 0, xfb_offset = 16, xfb_stride = 20) out float outLength;
void main() {
  gl_Position = inValue * 2.0;
  outLength = float(gl_VertexIndex);
}
)";
  const uint32_t n = 4099;
  RunRequest req;
  req.spirv = compileVertexShader(src);
  req.vertexCount = n;
  req.capture.strideBytes = 20;
  std::vector<float> values(size_t(n) * 4);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> dist(-100.0f, 100.0f);
  for (float& v : values) v = dist(rng);
  VertexStream s{3, VK_FORMAT_R32G32B32A32_SFLOAT, 16, std::vector<uint8_t>(values.size() * 4)};
  std::memcpy(s.data.data(), values.data(), s.data.size());
  req.streams = {s};
  RunResult res = harness_->run(req);
  ASSERT_EQ(res.captured.size(), size_t(n) * 20);
  Checker c;
  for (uint32_t v = 0; v < n; ++v) {
    float rec[5];
    std::memcpy(rec, &res.captured[size_t(v) * 20], 20);
    for (int i = 0; i < 4; ++i) c.expect("gl_Position", v, i, rec[i], values[size_t(v) * 4 + i] * 2.0);
    c.expect("gl_VertexIndex", v, 0, rec[4], v);
  }
  EXPECT_EQ(c.mismatches, 0u) << c.report.str();
}

TEST_F(HarnessTest, RefusesADeclaredDescriptorThatNothingFeedsAndReadsItOnceFed) {
  const char* src = R"(#version 450
layout(location = 0) in vec4 inValue;
layout(set = 0, binding = 2, std430) readonly buffer Deltas { vec4 deltas[]; };
out gl_PerVertex { layout(xfb_buffer = 0, xfb_offset = 0, xfb_stride = 16) vec4 gl_Position; };
void main() { gl_Position = inValue + deltas[gl_VertexIndex]; }
)";
  // glslang's reflection names what the program uses: a storage block at set 0, binding 2.
  sg::GlslShader parsed(sg::GlslUnit{sg::Stage::Vertex, src, "deltas.vert", {}}, sg::TargetEnv::Vulkan1_0);
  ASSERT_TRUE(parsed.ok());
  std::vector<sg::ShaderDescriptor> reflected = parsed.descriptors();
  ASSERT_EQ(reflected.size(), 1u);
  EXPECT_EQ(reflected[0].kind, sg::ShaderDescriptor::Kind::StorageBlock);
  EXPECT_EQ(reflected[0].set, 0u);
  EXPECT_EQ(reflected[0].binding, 2u);

  const uint32_t n = 7;  // odd: the capture pass pads to 8, so the buffer holds 8 elements
  std::vector<float> values(size_t(n) * 4), deltas(size_t(n + 1) * 4);
  for (size_t i = 0; i < values.size(); ++i) values[i] = float(i) * 0.5f;
  for (size_t i = 0; i < deltas.size(); ++i) deltas[i] = 100.0f + float(i);
  RunRequest req;
  req.spirv = parsed.spirv();
  req.vertexCount = n;
  req.capture.strideBytes = 16;
  VertexStream s{0, VK_FORMAT_R32G32B32A32_SFLOAT, 16, std::vector<uint8_t>(values.size() * 4)};
  std::memcpy(s.data.data(), values.data(), s.data.size());
  req.streams = {s};
  req.declared = {{0, 2, sg::rt::DescriptorKind::StorageBuffer, "Deltas"}};
  auto refusal = [&](const RunRequest& r) -> std::string {
    try {
      harness_->run(r);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  };
  const std::string unfed = "reads storage buffer 'Deltas' at set 0, binding 2, which nothing feeds";
  EXPECT_NE(refusal(req).find(unfed), std::string::npos) << refusal(req);
  sg::rt::StorageBufferData buffer{3, std::vector<uint8_t>(deltas.size() * 4)};
  std::memcpy(buffer.data.data(), deltas.data(), buffer.data.size());
  req.storageBuffers = {buffer};  // at the wrong binding
  EXPECT_NE(refusal(req).find(unfed), std::string::npos) << refusal(req);
  req.storageBuffers[0].binding = 2;
  RunResult res = harness_->run(req);
  ASSERT_EQ(res.captured.size(), size_t(n) * 16);
  Checker c;
  for (uint32_t v = 0; v < n; ++v)
    for (int i = 0; i < 4; ++i) {
      float got;
      std::memcpy(&got, &res.captured[(size_t(v) * 4 + size_t(i)) * 4], 4);
      c.expect("gl_Position", v, i, got, double(values[v * 4 + i]) + double(deltas[v * 4 + i]));
    }
  EXPECT_EQ(c.mismatches, 0u) << c.report.str();
}

TEST_F(HarnessTest, RejectsMalformedRequests) {
  SkinInput in = makeInput(16, 6);
  RunRequest good = makeRequest(in, skinSpirv_);
  auto expectThrow = [&](RunRequest req, const char* what) {
    EXPECT_THROW(harness_->run(req), std::runtime_error) << what;
  };
  RunRequest r = good;
  r.spirv.clear();
  expectThrow(r, "empty SPIR-V");
  r = good;
  r.vertexCount = 0;
  expectThrow(r, "no vertices");
  r = good;
  r.vertexCount = 17;
  expectThrow(r, "streams shorter than vertexCount");
  r = good;
  r.capture.strideBytes = 98;
  expectThrow(r, "capture stride not a multiple of 4");
  r = good;
  r.streams[1].location = 0;
  expectThrow(r, "duplicate location");
  // The harness is still usable afterwards.
  checkSkinOutputs(in, harness_->run(good));
}

TEST(HarnessDevice, UnknownDeviceNameThrowsNamingIt) {
  sg::rt::HarnessOptions opt;
  opt.deviceName = "NoSuchGpu-42";
  try {
    Harness h(opt);
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("NoSuchGpu-42"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("llvmpipe"), std::string::npos) << "should list available devices: " << e.what();
  }
}

TEST(HarnessDevice, SelectsByNameSubstring) {
  sg::rt::HarnessOptions opt;
  opt.deviceName = "llvmpipe";
  opt.validation = false;
  Harness h(opt);
  EXPECT_FALSE(h.validationEnabled());
  EXPECT_NE(h.deviceName().find("llvmpipe"), std::string::npos);
}

// The help's "default lavapipe" names the driver; its device calls itself "llvmpipe (LLVM ...)".
TEST(HarnessDevice, LavapipeNamesTheMesaDriver) {
  sg::rt::HarnessOptions opt;
  opt.deviceName = "lavapipe";
  opt.validation = false;
  Harness h(opt);
  EXPECT_NE(h.deviceName().find("llvmpipe"), std::string::npos) << h.deviceName();
}

// The messenger must actually deliver messages, or "no messages" proves nothing.
TEST(HarnessDevice, CollectsValidationMessages) {
  Harness h;
  if (!h.validationEnabled()) GTEST_SKIP() << "validation layer not installed";
  SkinInput in = makeInput(64, 7);
  RunRequest req = makeRequest(in, compileVertexShader(kSkinShader));
  req.streams[2].format = VK_FORMAT_R8G8B8A8_SINT;  // the shader reads a float vec4 here: a type mismatch
  h.run(req);
  EXPECT_FALSE(h.validationMessages().empty());
}

}  // namespace
