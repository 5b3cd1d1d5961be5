// The renderer (runtime/vk_render.h).
//
// Textures are mipmapped at upload (runtime/vk_setup.cpp): a pattern minified far must
// come out as its average, not as whichever texels the pixel centres happen to hit.
// Pattern: a white line every 4th texel column, black elsewhere, so the average is 1/4
// (64 of 255) while a point sample at any single spot is 0, 255 or a blend of the two.
#include "runtime/vk_render.h"

#include "common/glsl_compile.h"

#include <glm/gtc/packing.hpp>
#include <gtest/gtest.h>

#include "synchronization_validation.h"

#include <algorithm>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <utility>

namespace {

using namespace sg::rt;

std::vector<uint32_t> compile(sg::Stage stage, const std::string& source) {
  sg::CompileResult r = sg::compileGlsl(sg::GlslUnit{stage, source, "mip.glsl", {}}, sg::TargetEnv::Vulkan1_0);
  if (!r.ok) {
    std::string log;
    for (const auto& d : r.diagnostics) log += sg::renderDiagnostic(d) + "\n";
    throw std::runtime_error("GLSL compile failed:\n" + log);
  }
  return r.spirv;
}

// A quad covering the whole target, uv 0..1 across it.
const char* kQuad = R"(#version 450
layout(location = 0) in vec2 position;
layout(location = 0) out vec2 uv;
void main() {
  uv = position * 0.5 + 0.5;
  gl_Position = vec4(position, 0.0, 1.0);
})";

// Texel (x, y) of the pattern: 1 on every 4th column.
float lines(uint32_t x) { return x % 4 == 0 ? 1.0f : 0.0f; }

Texture patternTexture(uint32_t size, bool cube, VkFormat format, uint32_t binding) {
  Texture t;
  t.binding = binding;
  t.cube = cube;
  t.size = size;
  t.format = format;
  for (uint32_t f = 0; f < (cube ? 6u : 1u); ++f)
    for (uint32_t y = 0; y < size; ++y)
      for (uint32_t x = 0; x < size; ++x)
        for (int c = 0; c < 4; ++c) {
          float v = c == 3 ? 1.0f : lines(x);
          if (format == VK_FORMAT_R8G8B8A8_UNORM) {
            t.data.push_back(static_cast<uint8_t>(v * 255.0f));
          } else {
            uint16_t h = glm::packHalf1x16(v);
            t.data.push_back(static_cast<uint8_t>(h & 0xFF));
            t.data.push_back(static_cast<uint8_t>(h >> 8));
          }
        }
  return t;
}

class Mipmaps : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    sgtest::enableSynchronizationValidation();
    harness_ = std::make_unique<Harness>();
    renderer_ = std::make_unique<Renderer>(*harness_);
  }
  static void TearDownTestSuite() {
    renderer_.reset();
    harness_.reset();
  }

  // The quad from x = -1 to `right` in clip space, full height, into a width x height target,
  // with `fragment` reading `textures`.
  static DrawRequest quad(const std::string& fragment, std::vector<Texture> textures, uint32_t width, uint32_t height,
                          float right = 1) {
    DrawRequest r;
    r.vertexCount = 4;
    VertexStream s;
    s.location = 0;
    s.format = VK_FORMAT_R32G32_SFLOAT;
    s.stride = 8;
    const float corners[8] = {-1, -1, right, -1, right, 1, -1, 1};
    s.data.resize(sizeof corners);
    std::memcpy(s.data.data(), corners, sizeof corners);
    r.streams.push_back(s);
    r.textures = std::move(textures);
    r.vertexSpirv = compile(sg::Stage::Vertex, kQuad);
    r.fragmentSpirv = compile(sg::Stage::Fragment, fragment);
    r.indices = {0, 1, 2, 0, 2, 3};
    r.width = width;
    r.height = height;
    return r;
  }
  // Draws the quad into a size x size target.
  static Image draw(const std::string& fragment, std::vector<Texture> textures, uint32_t size) {
    Image img = renderer_->draw(quad(fragment, std::move(textures), size, size));
    EXPECT_TRUE(harness_->validationMessages().empty()) << harness_->validationMessages().front();
    return img;
  }

  static std::unique_ptr<Harness> harness_;
  static std::unique_ptr<Renderer> renderer_;
};
std::unique_ptr<Harness> Mipmaps::harness_;
std::unique_ptr<Renderer> Mipmaps::renderer_;

// Every pixel's red channel lies in [lo, hi]; returns how many do not.
size_t outside(const Image& img, int lo, int hi) {
  size_t n = 0;
  for (size_t i = 0; i < img.rgba.size(); i += 4) n += img.rgba[i] < lo || img.rgba[i] > hi;
  return n;
}

TEST_F(Mipmaps, MinifiedPatternIsItsAverage) {
  // 256 texels over 24 pixels: 10.7 texels per pixel (LOD 3.4, between levels 3 and 4,
  // where every texel is the 1/4 average), and pixel centres fall on varying texel phases.
  const std::string frag = R"(#version 450
layout(location = 0) in vec2 uv;
layout(set = 1, binding = 0) uniform sampler2D pattern;
layout(location = 0) out vec4 color;
void main() { color = texture(pattern, uv); })";
  for (VkFormat format : {VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_R16G16B16A16_SFLOAT}) {
    Image img = draw(frag, {patternTexture(256, false, format, 0)}, 24);
    EXPECT_EQ(outside(img, 62, 66), 0u) << "format " << format << ": pixel 0 is " << int(img.rgba[0]);
    // Magnified (8 pixels a texel, so level 0 is sampled): the lines keep their contrast
    // (bilinear weights at pixel centres reach 15/16 of a line texel).
    Image close = draw(frag, {patternTexture(16, false, format, 0)}, 128);
    int lo = 255, hi = 0;
    for (size_t i = 0; i < close.rgba.size(); i += 4) lo = std::min<int>(lo, close.rgba[i]), hi = std::max<int>(hi, close.rgba[i]);
    EXPECT_EQ(lo, 0);
    EXPECT_GE(hi, 238);
  }
}

TEST_F(Mipmaps, CubeMapsGetTheirChainToo) {
  // The last level of each face (1x1) is the face's average; LOD 20 is clamped to it.
  const std::string frag = R"(#version 450
layout(location = 0) in vec2 uv;
layout(set = 1, binding = 0) uniform samplerCube pattern;
layout(location = 0) out vec4 color;
void main() { color = textureLod(pattern, vec3(1.0, uv.y - 0.5, uv.x - 0.5), 20.0); })";
  for (VkFormat format : {VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_R16G16B16A16_SFLOAT}) {
    Image img = draw(frag, {patternTexture(64, true, format, 0)}, 8);
    EXPECT_EQ(outside(img, 62, 66), 0u) << "format " << format << ": pixel 0 is " << int(img.rgba[0]);
  }
}

TEST_F(Mipmaps, NonPowerOfTwoSizesMakeAChainDownToOnePixel) {
  // 48 -> 24 -> 12 -> 6 -> 3 -> 1: each level halves (rounding down) to 1x1.
  const std::string frag = R"(#version 450
layout(location = 0) in vec2 uv;
layout(set = 1, binding = 0) uniform sampler2D pattern;
layout(location = 0) out vec4 color;
void main() { color = textureLod(pattern, uv, 20.0); })";
  Image img = draw(frag, {patternTexture(48, false, VK_FORMAT_R8G8B8A8_UNORM, 0)}, 4);
  // Level 1 alternates 1/2 and 0 per column pair, level 2 on is 1/4 everywhere, so the
  // odd 3 -> 1 step (a linear blit of a uniform row) keeps it: the last level is the average.
  EXPECT_EQ(outside(img, 62, 66), 0u) << "pixel 0 is " << int(img.rgba[0]);
}

}  // namespace

// The quad's stream and indices read from device-local memory through a staging copy, and from
// mapped memory: the same pixels and depths; timed frames (several submits into one target)
// say where their inputs were.
TEST_F(Mipmaps, InputsInDeviceLocalAndMappedMemoryDrawTheSameImage) {
  const std::string flat = R"(#version 450
layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;
void main() { color = vec4(uv, 0.25, 1.0); })";
  DrawRequest r = quad(flat, {}, 40, 30, 0.5f);
  r.memory = InputMemory::DeviceLocal;
  const Image staged = renderer_->draw(r);
  r.memory = InputMemory::Mapped;
  const Image mapped = renderer_->draw(r);
  EXPECT_TRUE(staged.rgba == mapped.rgba);
  EXPECT_TRUE(staged.depth == mapped.depth);
  // Three quarters of the target drawn (x from -1 to 0.5), the rest cleared.
  EXPECT_EQ(std::count(staged.depth.begin(), staged.depth.end(), 1.0f), 10 * 30);
  for (InputMemory memory : {InputMemory::DeviceLocal, InputMemory::Mapped}) {
    r.memory = memory;
    TimingRequest t;
    t.drawsPerFrame = 2;
    t.frames = 3;
    const Timing tm = renderer_->time(r, t);
    EXPECT_EQ(tm.frameNs.size(), 3u);
    EXPECT_EQ(tm.inputMemory.rfind("type ", 0), 0u) << tm.inputMemory;
  }
  EXPECT_TRUE(harness_->validationMessages().empty()) << harness_->validationMessages().front();
}

// Two triangles that tile a rectangle of pixels cover each of its pixels once (the top-left
// rule gives the shared edge's pixels to one of them). A device counts at least those
// invocations and may add helpers (lavapipe shades whole blocks along an edge: 3,456 for the
// 3,072 pixels of a full 64x48 target), never a fragment for a quad wholly off the target. Each
// of the 4 vertices is shaded at least once and at most once per index that names it.
TEST_F(Mipmaps, DrawStatisticsCountTheCoveredPixelsAndTheShadedVertices) {
  const std::string flat = R"(#version 450
layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;
void main() { color = vec4(uv, 0.0, 1.0); })";
  uint64_t previous = UINT64_MAX;
  for (auto [right, covered] : {std::pair{1.0f, 64u * 48u}, std::pair{0.0f, 32u * 48u}, std::pair{-0.5f, 16u * 48u}}) {
    std::optional<DrawStatistics> st = renderer_->statistics(quad(flat, {}, 64, 48, right));
    if (!st) GTEST_SKIP() << "the device has no pipelineStatisticsQuery";
    EXPECT_GE(st->fragmentInvocations, covered) << "right edge at " << right;
    EXPECT_LT(st->fragmentInvocations, 2u * covered) << "right edge at " << right;
    EXPECT_LT(st->fragmentInvocations, previous) << "right edge at " << right;  // less covered, fewer
    previous = st->fragmentInvocations;
    EXPECT_GE(st->vertexInvocations, 4u);
    EXPECT_LE(st->vertexInvocations, 6u);
  }
  // From x = -2 to -1: left of the target, its right edge on the target's left one.
  DrawRequest off = quad(flat, {}, 64, 48, -2.0f);
  EXPECT_EQ(renderer_->statistics(off)->fragmentInvocations, 0u);
  EXPECT_TRUE(harness_->validationMessages().empty()) << harness_->validationMessages().front();
}
