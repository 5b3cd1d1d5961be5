// shadergen render on lavapipe: each test asserts something a broken renderer, a broken
// generated shader or broken textures would get wrong.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <tuple>
#include <cstdlib>

#include "render/render.h"
#include "rig/gltf_import.h"
#include "runtime/reference.h"
#include "test_util.h"

namespace {

using namespace sgtest;

constexpr uint32_t kSize = 128;

sg::RenderSession& session() {
  static sg::RenderSession s("", true);
  return s;
}

sg::RenderOptions dawnOptions(const std::string& rules = sourcePath("examples/dawn/rules.yaml")) {
  sg::RenderOptions o;
  o.gen.rigPath = sourcePath("examples/dawn/face.rig.yaml");
  o.gen.fragmentPath = sourcePath("examples/dawn/face.frag");
  o.gen.rulesPaths = {rules};
  o.width = o.height = kSize;
  return o;
}

sg::RenderOptions normalsOptions() {
  sg::RenderOptions o = dawnOptions(sourcePath("rules/standard.yaml"));
  o.gen.fragmentPath = sourcePath("examples/render/normals.frag");
  return o;
}

sg::RenderResult renderChecked(const sg::RenderOptions& o) {
  sg::RenderResult r = session().render(o);
  EXPECT_TRUE(r.validationMessages.empty()) << r.validationMessages.front();
  return r;
}

// Coverage from the depth buffer (cleared to 1).
std::vector<bool> covered(const sg::rt::Image& img) {
  std::vector<bool> m(img.depth.size());
  for (size_t i = 0; i < m.size(); ++i) m[i] = img.depth[i] < 1.0f;
  return m;
}

// The mesh's silhouette rasterized on the CPU from the reference clip positions (not the
// GPU's): a pixel is covered if its centre is inside a triangle.
std::vector<bool> cpuSilhouette(const sg::RenderScene& s, uint32_t w, uint32_t h) {
  std::vector<glm::vec4> clip = sg::rt::referenceValues("clip.position", s.mesh, s.pose, s.shape);
  std::vector<glm::vec2> px(clip.size());
  for (size_t i = 0; i < clip.size(); ++i) {
    EXPECT_GT(clip[i].w, 0.0f) << "vertex " << i << " behind the camera";
    px[i] = {(clip[i].x / clip[i].w * 0.5f + 0.5f) * float(w), (clip[i].y / clip[i].w * 0.5f + 0.5f) * float(h)};
  }
  std::vector<bool> m(size_t(w) * h, false);
  auto edge = [](glm::vec2 a, glm::vec2 b, glm::vec2 p) { return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x); };
  for (size_t t = 0; t + 2 < s.indices.size(); t += 3) {
    glm::vec2 a = px[s.indices[t]], b = px[s.indices[t + 1]], c = px[s.indices[t + 2]];
    int x0 = std::max(0, int(std::floor(std::min({a.x, b.x, c.x})))), x1 = std::min(int(w) - 1, int(std::ceil(std::max({a.x, b.x, c.x}))));
    int y0 = std::max(0, int(std::floor(std::min({a.y, b.y, c.y})))), y1 = std::min(int(h) - 1, int(std::ceil(std::max({a.y, b.y, c.y}))));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        glm::vec2 p(x + 0.5f, y + 0.5f);
        float e0 = edge(a, b, p), e1 = edge(b, c, p), e2 = edge(c, a, p);
        if ((e0 >= 0 && e1 >= 0 && e2 >= 0) || (e0 <= 0 && e1 <= 0 && e2 <= 0)) m[size_t(y) * w + size_t(x)] = true;
      }
  }
  return m;
}

// True if pixel (x, y) or one of its 8 neighbours differs in `m` from the pixel: on a boundary.
bool onBoundary(const std::vector<bool>& m, int x, int y, int w, int h) {
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      int nx = x + dx, ny = y + dy;
      if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
      if (m[size_t(ny) * w + size_t(nx)] != m[size_t(y) * w + size_t(x)]) return true;
    }
  return false;
}

void expectSilhouette(const sg::RenderOptions& o, const sg::RenderResult& r, double tolerance = 0.01) {
  sg::Rig rig = sg::loadRig(o.gen.rigPath);
  sg::RenderScene scene = sg::renderScene(rig, o);
  std::vector<bool> cpu = cpuSilhouette(scene, o.width, o.height), gpu = covered(r.image);
  size_t cpuCount = 0, mismatched = 0, inner = 0;
  for (int y = 0; y < int(o.height); ++y)
    for (int x = 0; x < int(o.width); ++x) {
      size_t i = size_t(y) * o.width + size_t(x);
      cpuCount += cpu[i];
      if (cpu[i] == gpu[i]) continue;
      ++mismatched;
      // Sample points on a shared edge may go either way; anywhere else is a real difference.
      if (!onBoundary(cpu, x, y, int(o.width), int(o.height))) ++inner;
    }
  EXPECT_GT(cpuCount, size_t(o.width) * o.height / 8) << "the framed mesh should fill a good part of the image";
  EXPECT_EQ(inner, 0u) << "pixels away from the silhouette's edge differ";
  EXPECT_LT(double(mismatched), tolerance * double(cpuCount));
}

// Every covered pixel has some light: NaN converts to 0 in UNORM, so does a missing term.
void expectNoBlackCoveredPixel(const sg::rt::Image& img) {
  size_t black = 0, cov = 0;
  for (size_t i = 0; i < img.depth.size(); ++i) {
    if (img.depth[i] >= 1.0f) continue;
    ++cov;
    const uint8_t* p = &img.rgba[i * 4];
    black += p[0] == 0 && p[1] == 0 && p[2] == 0;
  }
  EXPECT_EQ(black, 0u) << "of " << cov << " covered pixels";
}

double meanLuma(const sg::rt::Image& img, uint32_t x0, uint32_t x1) {
  double sum = 0;
  size_t n = 0;
  for (uint32_t y = 0; y < img.height; ++y)
    for (uint32_t x = x0; x < x1; ++x) {
      size_t i = size_t(y) * img.width + x;
      if (img.depth[i] >= 1.0f) continue;
      const uint8_t* p = &img.rgba[i * 4];
      sum += 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
      ++n;
    }
  return n ? sum / double(n) : 0.0;
}

TEST(Render, NormalsSilhouetteMatchesTheCpuRasterizationAndHasNoHoles) {
  sg::RenderOptions o = normalsOptions();
  o.camera.yawDegrees = 30;
  o.camera.pitchDegrees = 15;
  sg::RenderResult r = renderChecked(o);
  expectSilhouette(o, r);
  // Normal as colour: decoded back (2c - 1), every covered pixel holds a unit vector (8-bit
  // rounding allows ~1%): a hole, NaN or unnormalised normal would not.
  for (size_t i = 0; i < r.image.depth.size(); ++i) {
    if (r.image.depth[i] >= 1.0f) continue;
    const uint8_t* p = &r.image.rgba[i * 4];
    glm::vec3 n(2.0f * p[0] / 255.0f - 1.0f, 2.0f * p[1] / 255.0f - 1.0f, 2.0f * p[2] / 255.0f - 1.0f);
    ASSERT_NEAR(glm::length(n), 1.0f, 0.02f) << "pixel " << i;
  }
}

TEST(Render, GltfFoxSkinnedSilhouetteMatchesTheCpuRasterization) {
  // A real model without normals (flat shading from derivatives), skinned, mid-animation:
  // its own triangles, posed as validation poses it.
  std::string fox = std::string(SG_SHARED_DIR) + "/models/Fox/Fox.glb";
  if (!fs::exists(fox)) GTEST_SKIP() << "no " << fox;
  sg::RenderOptions o = normalsOptions();
  o.gen.rigPath = fox;
  o.gen.fragmentPath = sourcePath("examples/render/flat.frag");
  o.time = 0.5;
  o.camera.yawDegrees = 60;
  o.camera.zoom = 1.6f;
  sg::RenderResult r = renderChecked(o);
  expectSilhouette(o, r, 0.02);
}

TEST(Render, GltfStripsAndFansBecomeTriangleLists) {
  using V = std::vector<uint32_t>;
  EXPECT_EQ(sg::triangleList({0, 1, 2, 3}, 5, 4, "m"), (V{0, 1, 2, 2, 1, 3}));  // strip: second reversed
  EXPECT_EQ(sg::triangleList({0, 1, 2, 3}, 6, 4, "m"), (V{0, 1, 2, 0, 2, 3}));  // fan
  EXPECT_EQ(sg::triangleList({}, 4, 7, "m"), (V{0, 1, 2, 3, 4, 5}));           // unindexed, partial triangle dropped
  EXPECT_THROW(sg::triangleList({0, 1}, 1, 2, "m"), sg::InputError);          // lines
  EXPECT_THROW(sg::triangleList({0, 1}, 4, 2, "m"), sg::InputError);          // no whole triangle
}

TEST(Render, NormalsFaceTheirSide) {
  // World normals: the right half of the head points to +x (red high), the top to +y.
  sg::RenderOptions o = normalsOptions();
  sg::RenderResult r = renderChecked(o);
  auto at = [&](uint32_t x, uint32_t y) { return &r.image.rgba[(size_t(y) * kSize + x) * 4]; };
  EXPECT_GT(at(kSize * 7 / 8, kSize / 2)[0], 200);  // right: +x
  EXPECT_LT(at(kSize / 8, kSize / 2)[0], 60);       // left: -x
  EXPECT_GT(at(kSize / 2, kSize / 2)[2], 240);      // centre faces the camera: +z
}

TEST(Render, DawnFaceSilhouetteAndNoBlackHoles) {
  sg::RenderOptions o = dawnOptions();
  o.camera.yawDegrees = -25;
  o.poseSeed = 0;
  sg::RenderResult r = renderChecked(o);
  expectSilhouette(o, r);
  expectNoBlackCoveredPixel(r.image);
}

TEST(Render, LightingFollowsTheKeyLight) {
  sg::RenderOptions o = dawnOptions();
  o.lighting.keyDirection = {1, 0.2f, 0.4f};
  double rightLit = meanLuma(renderChecked(o).image, kSize / 2, kSize) - meanLuma(renderChecked(o).image, 0, kSize / 2);
  o.lighting.keyDirection = {-1, 0.2f, 0.4f};
  sg::rt::Image left = renderChecked(o).image;
  double leftLit = meanLuma(left, 0, kSize / 2) - meanLuma(left, kSize / 2, kSize);
  EXPECT_GT(rightLit, 5.0);
  EXPECT_GT(leftLit, 5.0);
}

TEST(Render, HilightFollowsTheRimLightCubeMap) {
  sg::RenderOptions o = dawnOptions();
  o.lighting.rimDirection = {0, 0, 1};
  double with = meanLuma(renderChecked(o).image, 0, kSize);
  o.lighting.rimDirection = {0, 0, -1};
  double without = meanLuma(renderChecked(o).image, 0, kSize);
  EXPECT_NE(with, without);
}

TEST(Render, BufferFedPlanCoversExactlyThePixelsOfTheAttributeFedPlan) {
  // --max-attributes 8 moves morph deltas and skin influences into storage buffers
  // (docs/buffers.md): the same rig, pose and camera must draw the same silhouette. A
  // random pose, so bones and morph weights matter.
  sg::RenderOptions o = dawnOptions();
  o.poseSeed = 3;
  o.camera.yawDegrees = 25;
  sg::RenderResult attributes = renderChecked(o);
  o.gen.maxAttributes = 8;
  sg::RenderResult buffers = renderChecked(o);
  auto readsBuffers = [](const sg::RenderResult& r) {
    return std::any_of(r.rules.begin(), r.rules.end(), [](const std::string& n) { return n.find("buffer") != std::string::npos; });
  };
  EXPECT_FALSE(readsBuffers(attributes));
  EXPECT_TRUE(readsBuffers(buffers));
  std::vector<bool> a = covered(attributes.image), b = covered(buffers.image);
  EXPECT_GT(std::count(a.begin(), a.end(), true), long(kSize) * kSize / 8);
  EXPECT_EQ(a, b);
}

TEST(Render, FragmentSamplersAreTheOnesTheShaderDeclares) {
  // examples/dawn/face.frag declares its six samplers at set 1, bindings 0-5, the last three cubes.
  sg::FragmentProgram f = sg::compileFragmentFile(sourcePath("examples/dawn/face.frag"), sg::TargetEnv::Vulkan1_0);
  std::vector<std::tuple<std::string, uint32_t, uint32_t, bool>> got;
  for (const auto& d : f.descriptors)
    if (d.kind == sg::ShaderDescriptor::Kind::Sampler) got.emplace_back(d.name, d.set, d.binding, d.cube);
  std::sort(got.begin(), got.end(), [](const auto& x, const auto& y) { return std::get<2>(x) < std::get<2>(y); });
  const std::vector<std::tuple<std::string, uint32_t, uint32_t, bool>> want = {
      {"SkinColorFrontSpecMap", 1, 0, false}, {"SkinNormSideSpecMap", 1, 1, false}, {"SpecularColorShiftMap", 1, 2, false},
      {"DiffuseCubeMap", 1, 3, true},         {"SpecularCubeMap", 1, 4, true},      {"HilightCubeMap", 1, 5, true}};
  EXPECT_EQ(got, want);
}

TEST(Render, BrokenEyeDirectionChangesTheShadingNotTheSilhouette) {
  sg::RenderOptions o = dawnOptions();
  sg::RenderResult good = renderChecked(o);
  RulesCopy rules("render_eye");
  ASSERT_TRUE(rules.edit("view.yaml", "normalize(${world.position} - ${camera.position})",
                         "normalize(${camera.position} - ${world.position})"));
  sg::RenderResult bad = renderChecked(dawnOptions(rules.dawnRules().string()));
  EXPECT_EQ(good.image.depth, bad.image.depth);
  double diff = 0;
  for (size_t i = 0; i < good.image.rgba.size(); ++i) diff += std::abs(int(good.image.rgba[i]) - int(bad.image.rgba[i]));
  EXPECT_GT(diff / double(good.image.rgba.size()), 1.0);
}

TEST(Render, BrokenProjectionMovesTheSilhouette) {
  RulesCopy rules("render_proj");
  ASSERT_TRUE(rules.edit("projection.yaml", "${out} = ${camera.projection} * ${eye.position};",
                         "${out} = ${camera.projection} * (${eye.position} + vec4(0.2, 0.0, 0.0, 0.0));"));
  sg::RenderOptions o = normalsOptions();
  sg::RenderResult good = renderChecked(o);
  o.gen.rulesPaths = {rules.rulesFile("standard.yaml").string()};
  sg::RenderResult bad = renderChecked(o);
  size_t differ = 0;
  for (size_t i = 0; i < good.image.depth.size(); ++i) differ += (good.image.depth[i] < 1.0f) != (bad.image.depth[i] < 1.0f);
  EXPECT_GT(differ, size_t(kSize) * kSize / 50);
}

TEST(Render, MatchesTheStoredReferenceImage) {
  // tests/render/data/dawn-face-96.png was made by
  //   shadergen render --rig examples/dawn/face.rig.yaml -f examples/dawn/face.frag
  //     -r examples/dawn/rules.yaml --size 96x96 --yaw 20 -o dawn-face-96.png
  // and checked by eye. Rounding differences (LLVM versions) are allowed, drift is not.
  sg::RenderOptions o = dawnOptions();
  o.width = o.height = 96;
  o.camera.yawDegrees = 20;
  sg::rt::Image now = renderChecked(o).image;
  sg::rt::Image ref = sg::readPng(sourcePath("tests/render/data/dawn-face-96.png"));
  ASSERT_EQ(ref.width, now.width);
  ASSERT_EQ(ref.height, now.height);
  size_t far = 0;
  double sum = 0;
  for (size_t i = 0; i < size_t(now.width) * now.height; ++i)
    for (int c = 0; c < 3; ++c) {
      int d = std::abs(int(now.rgba[i * 4 + c]) - int(ref.rgba[i * 4 + c]));
      sum += d;
      far += d > 24;
    }
  EXPECT_LT(sum / (3.0 * now.width * now.height), 1.0);
  EXPECT_LT(far, size_t(now.width) * now.height / 100);
}

TEST(Render, SamePixelsSamePngBytes) {
  sg::RenderOptions o = dawnOptions();
  o.width = o.height = 64;
  std::string a = sg::encodePng(renderChecked(o).image), b = sg::encodePng(renderChecked(o).image);
  EXPECT_EQ(a, b);
  EXPECT_EQ(a.substr(1, 3), "PNG");
}

TEST(Render, ScannedHeadLitByListing34IsDeterministicAndWhole) {
  // The README picture (examples/head/make-picture.sh) at test size: the scanned head
  // baked (occlusion, tangents), drawn with Dawn's face shader. Its silhouette must be the
  // CPU rasterization's, no covered pixel black (NaN or missing light), two draws the
  // same PNG bytes.
  const char* env = std::getenv("SHADERGEN_SHARED_DIR");
  std::string head = std::string(env && *env ? env : SG_SHARED_DIR) + "/models/LeePerrySmith/LeePerrySmith.glb";
  if (!fs::exists(head)) GTEST_SKIP() << "no " << head << " (examples/head/README.md)";
  fs::path dir = fs::temp_directory_path() / ("sg_render_head_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::string occluded = (dir / "occluded.glb").string(), baked = (dir / "head.glb").string();
  ASSERT_EQ(std::system((std::string(SG_CLI) + " bake occlusion " + head + " -o " + occluded + " --rays 32 -q").c_str()), 0);
  ASSERT_EQ(std::system((std::string(SG_CLI) + " bake tangents " + occluded + " -o " + baked + " -q").c_str()), 0);
  sg::RenderOptions o = dawnOptions();
  o.gen.rigPath = baked + "#0/0";
  o.gen.overrides = {{"SkinSilhouetteVec", {"object.visibility", "view.one_minus_ndotv_sq", "view.one_minus_ndotv", "view.one_minus_ndotv"}},
                     {"SkinUVST", {"vertex.texcoord0", "vertex.texcoord0"}}};
  o.camera.yawDegrees = 30;
  o.camera.pitchDegrees = 5;
  o.camera.zoom = 1.3f;
  sg::RenderResult r = renderChecked(o);
  expectSilhouette(o, r);
  expectNoBlackCoveredPixel(r.image);
  EXPECT_EQ(sg::encodePng(r.image), sg::encodePng(renderChecked(o).image));
  fs::remove_all(dir);
}

TEST(Render, UnknownSamplerIsAnErrorAtItsDeclaration) {
  fs::path dir = fs::temp_directory_path() / ("sg_render_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::string frag = readText(sourcePath("examples/dawn/face.frag"));
  ASSERT_TRUE(replaceOnce(frag, "HilightCubeMap;", "MysteryCubeMap;"));
  ASSERT_TRUE(replaceOnce(frag, "texture(HilightCubeMap,", "texture(MysteryCubeMap,"));
  writeText(dir / "f.frag", frag);
  sg::RenderOptions o = dawnOptions();
  o.gen.fragmentPath = (dir / "f.frag").string();
  try {
    session().render(o);
    ADD_FAILURE() << "no error";
  } catch (const sg::InputError& e) {
    std::string msg = sg::renderDiagnostic(e.diagnostic());
    EXPECT_NE(msg.find("f.frag:16:"), std::string::npos) << msg;
    EXPECT_NE(msg.find("MysteryCubeMap"), std::string::npos) << msg;
  }
  fs::remove_all(dir);
}

TEST(Render, CliWritesThePngAndRejectsBadOptions) {
  fs::path dir = fs::temp_directory_path() / ("sg_render_cli_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::string base = std::string(SG_CLI) + " render --rig " + sourcePath("examples/dawn/face.rig.yaml") + " -f " +
                     sourcePath("examples/render/normals.frag") + " -r " + sourcePath("rules/standard.yaml") + " ";
  std::string out = (dir / "n.png").string();
  EXPECT_EQ(std::system((base + "--size 48x32 -o " + out + " > /dev/null").c_str()), 0);
  sg::rt::Image img = sg::readPng(out);
  EXPECT_EQ(img.width, 48u);
  EXPECT_EQ(img.height, 32u);
  EXPECT_NE(WEXITSTATUS(std::system((base + "--size 0x32 -o " + out + " 2> /dev/null").c_str())), 0);
  EXPECT_NE(WEXITSTATUS(std::system((base + "--light 1,nan,0 -o " + out + " 2> /dev/null").c_str())), 0);
  // The output must not replace an input.
  EXPECT_NE(WEXITSTATUS(std::system((base + "-o " + sourcePath("examples/render/normals.frag") + " 2> /dev/null").c_str())), 0);
  EXPECT_EQ(readText(sourcePath("examples/render/normals.frag")).substr(0, 8), "#version");
  fs::remove_all(dir);
}

}  // namespace
