// Hostile glTF input (issue 10): every malformed model is refused with a diagnostic naming
// the file (and line:col for JSON), before any out-of-bounds read, runaway allocation,
// stack overflow, quadratic walk or file read outside the model's folder. No shared models
// needed: every input is built here.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>

#include "../core/core_test_util.h"
#include "gltf_builder.h"
#include "rig/gltf_import.h"
#include "validate/gltf_scene.h"

namespace sg {
namespace {

namespace fs = std::filesystem;
using test::GltfBuilder;

using sgtest::errorOf;
#define EXPECT_HAS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

// One triangle whose POSITION accessor carries `posExtra` members; `rest` adds top-level
// members (after meshes and nodes).
std::string triangle(const std::string& posExtra = "", const std::string& rest = "", size_t count = 3,
                     const std::string& viewExtra = "") {
  GltfBuilder b;
  int v = b.view(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0});
  if (!viewExtra.empty()) b.views[static_cast<size_t>(v)].insert(b.views[static_cast<size_t>(v)].size() - 1, "," + viewExtra);
  b.accessor(v, 5126, count, "VEC3", posExtra);
  return b.json(R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0}])" + rest);
}

Diagnostic importError(const std::string& json, const std::string& name = "bad.gltf",
                       const GltfImportOptions& o = {}) {
  return errorOf([&] { importGltfText(json, name, o); });
}

struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& tag) {
    path = fs::temp_directory_path() / fmt::format("sg_gltf_hostile_{}_{}", tag, ::getpid());
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
  fs::path write(const std::string& rel, const std::string& bytes) const {
    fs::path p = path / rel;
    fs::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << bytes;
    return p;
  }
};

TEST(GltfHostile, TheBaseTriangleImports) {
  EXPECT_EQ(importGltfText(triangle(), "ok.gltf").data.vertexCount, 3u);
}

// --- bounds arithmetic ---

TEST(GltfHostile, AccessorOffsetNearSizeMaxDoesNotWrapPastTheCheck) {
  auto d = importError(triangle(R"("byteOffset":18446744073709551600)"));
  EXPECT_EQ(d.loc.file, "bad.gltf");
  EXPECT_HAS(d.message, "reads bytes 18446744073709551600");
  EXPECT_HAS(d.message, "buffer view 0, which has 36 bytes");
}

TEST(GltfHostile, BufferViewOffsetPlusLengthOverflowIsRefused) {
  GltfBuilder b;
  b.view(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0});
  b.views[0] = R"({"buffer":0,"byteOffset":18446744073709551615,"byteLength":36})";
  b.accessor(0, 5126, 3, "VEC3");
  auto d = importError(b.json(R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}])"));
  EXPECT_HAS(d.message, "lies outside buffer 0 (36 bytes)");
}

TEST(GltfHostile, ClaimedCountBeyondTheViewIsRefusedBeforeAllocating) {
  // 1e9 VEC3 floats would be 12 GB of zeros before the old bounds check.
  auto d = importError(triangle("", "", 1000000000));
  EXPECT_HAS(d.message, "has 1000000000 elements; the limit is 16777216");
  auto e = importError(triangle("", "", 16000000));
  EXPECT_HAS(e.message, "reads bytes 0..+192000000 of buffer view 0, which has 36 bytes");
}

TEST(GltfHostile, ZeroFilledAccessorsAreChargedAgainstAnInputProportionalBudget) {
  // No buffer view: 16M zero vertices claimed by a ~300-byte file (16M × 12 B + streams > 64 MiB).
  GltfBuilder b;
  b.view(std::vector<float>{0});
  b.accessor(-1, 5126, 16000000, "VEC3");
  auto d = importError(b.json(R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}])"));
  EXPECT_HAS(d.message, "past this model's limit of");
  EXPECT_HAS(d.message, "64.0 MiB plus 256 bytes per byte");
  // The same budget, set low, stops a model that is fine by default.
  GltfImportOptions o;
  o.maxDecodedBytes = 40;  // 3 × 12 B of positions fit, the 3 × 16 B stream does not
  auto e = importError(triangle(), "small.gltf", o);
  EXPECT_HAS(e.message, "attribute POSITION: decoding 3 elements");
}

TEST(GltfHostile, StrideSmallerThanTheElementIsRefused) {
  auto d = importError(triangle("", "", 3, R"("byteStride":4)"));
  EXPECT_HAS(d.message, "byteStride 4, less than the 12-byte element");
}

TEST(GltfHostile, NegativeOrOversizedSparseCountsAreRefused) {
  for (const char* count : {"-1", "-2147483648", "4"}) {
    GltfBuilder b;
    b.view(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0});
    int idx = b.view(std::vector<uint16_t>{0, 1});
    int val = b.view(std::vector<float>{1, 1, 1, 2, 2, 2});
    b.accessor(0, 5126, 3, "VEC3",
               fmt::format(R"("sparse":{{"count":{},"indices":{{"bufferView":{},"componentType":5123}},)"
                           R"("values":{{"bufferView":{}}}}})",
                           count, idx, val));
    auto d = importError(b.json(R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}])"));
    EXPECT_HAS(d.message, fmt::format("sparse count {} is not between 0 and the accessor's count 3", count));
  }
}

TEST(GltfHostile, SparseIndicesPastTheirViewAreRefused) {
  GltfBuilder b;
  b.view(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0});
  int idx = b.view(std::vector<uint16_t>{0, 1});
  int val = b.view(std::vector<float>{1, 1, 1, 2, 2, 2});
  b.accessor(0, 5126, 3, "VEC3",
             fmt::format(R"("sparse":{{"count":2,"indices":{{"bufferView":{},"componentType":5123,"byteOffset":2147483647}},)"
                         R"("values":{{"bufferView":{}}}}})",
                         idx, val));
  auto d = importError(b.json(R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}])"));
  EXPECT_HAS(d.message, "sparse indices reads bytes 2147483647..+4 of buffer view 1");
}

TEST(GltfHostile, WeightsChannelWithoutValuesIsRefused) {
  GltfBuilder b;
  b.view(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0});
  b.accessor(0, 5126, 3, "VEC3");
  b.accessor(b.view(std::vector<float>{0, 1}), 5126, 2, "SCALAR");
  b.accessor(-1, 5126, 0, "SCALAR");
  auto d = importError(b.json(
      R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0}],)"
      R"("animations":[{"samplers":[{"input":1,"output":2}],"channels":[{"sampler":0,"target":{"node":0,"path":"weights"}}]}])"));
  EXPECT_HAS(d.message, "0 output values do not divide into 2 keyframes");
}

// --- recursion and quadratic walks ---

std::string nodeChain(int n, bool cycle, const std::string& member = "") {
  std::string nodes;
  for (int i = 0; i < n; ++i) {
    nodes += i ? "," : "";
    if (i + 1 < n) nodes += fmt::format(R"({{{}"children":[{}]}})", member, i + 1);
    else nodes += cycle ? R"({"children":[0],"mesh":0})" : R"({"mesh":0})";
  }
  return nodes;
}

TEST(GltfHostile, DeepJsonNestingIsRefusedWithItsLineAndColumn) {
  std::string deep = std::string(100000, '[') + std::string(100000, ']');
  auto d = importError(triangle("", ",\n\"extras\":" + deep));
  EXPECT_EQ(d.loc.line, 2);
  EXPECT_EQ(d.loc.col, 9 + 64);  // bracket 64 of the list, depth 65: "extras": is 9 columns
  EXPECT_HAS(d.message, "JSON nested deeper than 64 levels");
  // Brackets inside strings do not count.
  EXPECT_NO_THROW(importGltfText(triangle("", R"(,"extras":{"s":")" + std::string(1000, '[') + R"(\"["})"), "ok.gltf"));
}

TEST(GltfHostile, LongNodeChainImportsAndPosesWithoutRecursion) {
  // 100,000 nodes in one chain, each translating by 1 along x: the old depth-first search and parent walk recursed once per
  // node (stack overflow) and the cycle check was quadratic (5·10^9 steps).
  const int n = 100000;
  GltfBuilder b;
  b.accessor(b.view(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}), 5126, 3, "VEC3");
  std::string json = b.json(R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[)" +
                            nodeChain(n, false, R"("translation":[1,0,0],)") + R"(],"scenes":[{"nodes":[0,0]}])");
  GltfImport imp = importGltfText(json, "chain.gltf");
  EXPECT_EQ(imp.data.meshNode, n - 1);
  std::vector<glm::dmat4> g = gltfNodeGlobals(imp.data, -1, 0.0);
  EXPECT_DOUBLE_EQ(g[static_cast<size_t>(n - 1)][3][0], n - 1);
}

TEST(GltfHostile, LongCycleIsFoundInLinearTime) {
  GltfBuilder b;
  b.accessor(b.view(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}), 5126, 3, "VEC3");
  auto d = importError(b.json(R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[)" +
                              nodeChain(100000, true) + "]"));
  EXPECT_HAS(d.message, "is part of a cycle in the node hierarchy");
}

// --- files: the model itself and the buffers it names ---

TEST(GltfHostile, BufferUrisOutsideTheModelsFolderAreRefused) {
  TempDir t("uris");
  std::string bin(36, '\0');
  t.write("secret.bin", bin);
  t.write("model/inside.bin", bin);
  t.write("model/sub/deeper.bin", bin);
  fs::create_symlink(t.path / "secret.bin", t.path / "model" / "link.bin");
  auto model = [&](const std::string& uri) {
    return t.write("model/m.gltf",
                   fmt::format(R"({{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":36,"uri":"{}"}}],)"
                               R"("bufferViews":[{{"buffer":0,"byteLength":36}}],)"
                               R"("accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}}],)"
                               R"("meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}]}})",
                               uri))
        .string();
  };
  EXPECT_EQ(importGltf(model("inside.bin")).data.vertexCount, 3u);
  EXPECT_EQ(importGltf(model("sub/deeper.bin")).data.vertexCount, 3u);
  EXPECT_EQ(importGltf(model("sub/../inside.bin")).data.vertexCount, 3u);
  for (std::string uri : {std::string("../secret.bin"), std::string("link.bin"), std::string("sub/../../secret.bin"),
                          std::string("%2E%2E/secret.bin"), (t.path / "secret.bin").string()}) {
    auto d = errorOf([&] { importGltf(model(uri)); });
    EXPECT_EQ(d.loc.file, (t.path / "model/m.gltf").string());
    EXPECT_TRUE(d.message.find("lies outside the model's folder") != std::string::npos ||
                d.message.find("File not found") != std::string::npos)
        << uri << ": " << d.message;
    EXPECT_EQ(d.message.find("File read"), std::string::npos) << d.message;
  }
  auto d = errorOf([&] { importGltf(model("../secret.bin")); });
  EXPECT_HAS(d.message, "secret.bin' lies outside the model's folder");
  // Text without a folder reads no files at all.
  std::ifstream in(model("inside.bin"));
  std::string text((std::istreambuf_iterator<char>(in)), {});
  EXPECT_HAS(errorOf([&] { importGltfText(text, "m.gltf"); }).message, "has no folder to read files from");
}

// Depfiles, variant cache keys and the clobbering checks all rest on this list: a .gltf
// whose .bin changes must count as a changed rig.
TEST(GltfHostile, RigListsTheModelAndEveryBufferFileItRead) {
  TempDir t("sources");
  t.write("model/sub/geometry.bin", std::string(36, '\0'));
  std::string m = t.write("model/m.gltf",
                          R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":36,"uri":"sub/geometry.bin"}],)"
                          R"("bufferViews":[{"buffer":0,"byteLength":36}],)"
                          R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}],)"
                          R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}]})")
                      .string();
  Rig rig = importGltf(m).rig;
  ASSERT_EQ(rig.sourceFiles.size(), 2u);
  EXPECT_EQ(rig.sourceFiles[0], m);
  EXPECT_EQ(fs::canonical(rig.sourceFiles[1]), fs::canonical(t.path / "model/sub/geometry.bin"));
  EXPECT_EQ(loadRig(m + "#0/0").sourceFiles, rig.sourceFiles);
}

TEST(GltfHostile, NonRegularModelFilesAreRefusedWithoutReading) {
  TempDir t("special");
  fs::create_symlink("/dev/zero", t.path / "zero.glb");
  ASSERT_EQ(::mkfifo((t.path / "fifo.gltf").c_str(), 0600), 0);
  EXPECT_HAS(errorOf([&] { importGltf((t.path / "zero.glb").string()); }).message, "not a regular file");
  EXPECT_HAS(errorOf([&] { importGltf((t.path / "fifo.gltf").string()); }).message, "not a regular file");
  EXPECT_HAS(errorOf([&] { importGltf((t.path / "missing.glb").string()); }).message, "no such file");
  // A sparse 2 GiB file: refused by its size, never read.
  { std::ofstream(t.path / "huge.glb"); }
  fs::resize_file(t.path / "huge.glb", uintmax_t{2} << 30);
  EXPECT_HAS(errorOf([&] { importGltf((t.path / "huge.glb").string()); }).message, "larger than the limit of 1024.0 MiB");
}

std::string glb(const std::string& json, const std::string& bin, uint32_t binLengthField, uint32_t totalField = 0) {
  std::string j = json;
  while (j.size() % 4) j += ' ';
  auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  std::string out = "glTF" + u32(2) + u32(0) + u32(static_cast<uint32_t>(j.size())) + "JSON" + j;
  if (!bin.empty()) out += u32(binLengthField) + "BIN" + std::string(1, '\0') + bin;
  uint32_t total = totalField ? totalField : static_cast<uint32_t>(out.size());
  std::memcpy(out.data() + 8, &total, 4);
  return out;
}

TEST(GltfHostile, GlbChunksAreCheckedAgainstTheFile) {
  TempDir t("glb");
  std::string json = R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":36}],)"
                     R"("bufferViews":[{"buffer":0,"byteLength":36}],)"
                     R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}],)"
                     R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}]})";
  std::string bin(36, '\0');
  EXPECT_EQ(importGltf(t.write("ok.glb", glb(json, bin, 36)).string()).data.vertexCount, 3u);
  // BIN chunk length reaching exactly the chunk's data end + 8: tinygltf 2.7 accepts it and
  // reads 8 bytes past the file.
  EXPECT_HAS(errorOf([&] { importGltf(t.write("a.glb", glb(json, bin, 44)).string()); }).message,
             "BIN chunk at byte");
  EXPECT_HAS(errorOf([&] { importGltf(t.write("b.glb", glb(json, bin, 36, 1u << 31)).string()); }).message,
             "claims 2147483648 bytes but the file has");
  EXPECT_HAS(errorOf([&] { importGltf(t.write("c.glb", "glTF\2\0\0\0").string()); }).message, "no 'glTF' header");
  EXPECT_HAS(errorOf([&] { importGltf(t.write("d.glb", json).string()); }).message, "no 'glTF' header");
  auto deep = errorOf([&] { importGltf(t.write("e.glb", glb("{\"x\":" + std::string(70, '[') + std::string(70, ']') + "}", "", 0)).string()); });
  EXPECT_HAS(deep.message, "JSON nested deeper than 64 levels in the GLB's JSON chunk (line 1, column 69)");
}

TEST(GltfHostile, JsonSyntaxErrorsAreLocated) {
  auto d = importError("{\"asset\":{\"version\":\"2.0\"},\n  \"meshes\": [1,,2]}");
  EXPECT_EQ(d.loc.file, "bad.gltf");
  EXPECT_EQ(d.loc.line, 2);
  EXPECT_EQ(d.loc.col, 16);  // the second comma
  EXPECT_HAS(d.message, "invalid JSON: syntax error");
}

}  // namespace
}  // namespace sg
