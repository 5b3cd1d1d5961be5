// Runs the vertex shaders shadergen generated at build time (CMakeLists.txt) on lavapipe
// through shadergen::runtime, and checks gl_Position of every vertex against the same
// formula computed here on the CPU (docs/semantics.md: clip.position).
//
//   face: SPIR-V embedded with EMBED      -> #include "face.spv.h" (face_shader.cpp)
//   prop: SPIR-V loaded from its .spv file -> SHADERGEN_PROP_SPV (compile definition)
// Both read their vertex-input / uniform / output layout from the generated reflection
// JSON (SHADERGEN_<NAME>_REFLECTION), because the generator decides which rig attributes
// the cheapest shader actually reads.
//
// Prints gl_Position of vertex 0 (GPU and CPU) per shader, then "OK"; exits 1 on a mismatch.
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "runtime/procedural.h"
#include "runtime/vk_harness.h"

using json = nlohmann::json;

std::vector<uint32_t> faceShaderWords();  // face_shader.cpp: the embedded face.spv.h

namespace {

json readJson(const char* path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(std::string("cannot open ") + path);
  return json::parse(in);
}

std::vector<uint32_t> readSpirv(const char* path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(std::string("cannot open ") + path);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<uint32_t> words(bytes.size() / 4);
  std::memcpy(words.data(), bytes.data(), words.size() * 4);
  return words;
}

struct Format {
  VkFormat vk;
  int components;
  int bytesPerComponent;
  bool integer;
};

Format parseFormat(const std::string& f) {
  if (f == "float32") return {VK_FORMAT_R32_SFLOAT, 1, 4, false};
  if (f == "float32x2") return {VK_FORMAT_R32G32_SFLOAT, 2, 4, false};
  if (f == "float32x3") return {VK_FORMAT_R32G32B32_SFLOAT, 3, 4, false};
  if (f == "float32x4") return {VK_FORMAT_R32G32B32A32_SFLOAT, 4, 4, false};
  if (f == "uint8x4") return {VK_FORMAT_R8G8B8A8_UINT, 4, 1, true};
  if (f == "uint16x4") return {VK_FORMAT_R16G16B16A16_UINT, 4, 2, true};
  if (f == "uint32x4") return {VK_FORMAT_R32G32B32A32_UINT, 4, 4, true};
  throw std::runtime_error("this example does not handle vertex format " + f);
}

int components(const std::string& type) {
  if (type == "float" || type == "int" || type == "uint") return 1;
  return type.back() - '0';  // vec2 / vec3 / vec4 / ivec4 / uvec4
}

// One vertex buffer per shader input, filled from the mesh streams the reflection names
// ("provides": semantic + which components of the attribute carry it).
std::vector<sg::rt::VertexStream> buildStreams(const json& refl, const sg::rt::Mesh& mesh) {
  std::vector<sg::rt::VertexStream> streams;
  for (const auto& in : refl["inputs"]) {
    Format f = parseFormat(in["format"]);
    sg::rt::VertexStream s;
    s.location = in["location"];
    s.format = f.vk;
    s.stride = static_cast<uint32_t>(f.components * f.bytesPerComponent);
    std::vector<glm::vec4> values(mesh.vertexCount, glm::vec4(0.0f));
    for (const auto& p : in["provides"]) {
      const auto& src = mesh.at(p["semantic"].get<std::string>());
      std::string swz = p["components"];
      for (size_t v = 0; v < mesh.vertexCount; ++v)
        for (size_t k = 0; k < swz.size(); ++k) values[v][std::string("xyzw").find(swz[k])] = src[v][static_cast<int>(k)];
    }
    for (const auto& v : values)
      for (int c = 0; c < f.components; ++c) {
        if (!f.integer) {
          float x = v[c];
          s.data.insert(s.data.end(), reinterpret_cast<uint8_t*>(&x), reinterpret_cast<uint8_t*>(&x) + 4);
        } else {
          uint32_t x = static_cast<uint32_t>(std::lround(v[c]));
          s.data.insert(s.data.end(), reinterpret_cast<uint8_t*>(&x), reinterpret_cast<uint8_t*>(&x) + f.bytesPerComponent);
        }
      }
    streams.push_back(std::move(s));
  }
  return streams;
}

// The std140 uniform block, from the reflection's offsets and strides.
std::vector<uint8_t> buildUniforms(const json& refl, const sg::rt::Pose& pose) {
  const json& block = refl["uniform_block"];
  std::vector<uint8_t> data(block["size"].get<size_t>(), 0);
  auto put = [&](uint32_t offset, const float* src, size_t n) { std::memcpy(data.data() + offset, src, n * 4); };
  auto putMat = [&](uint32_t offset, const glm::mat4& m, uint32_t stride) {
    for (int c = 0; c < 4; ++c) put(offset + c * stride, &m[c][0], 4);
  };
  for (const auto& m : block["members"]) {
    std::string sem = m["semantic"];
    uint32_t off = m["offset"], arrayStride = m["array_stride"], matStride = m["matrix_stride"];
    if (sem == "skin.bones")
      for (int i = 0; i < m["array"].get<int>(); ++i) putMat(off + i * arrayStride, pose.bones.at(i), matStride);
    else if (sem == "morph.weights")
      for (int i = 0; i < m["array"].get<int>(); ++i) put(off + i * arrayStride, &pose.morphWeights.at(i), 1);
    else if (sem == "camera.position") put(off, &pose.cameraPosition[0], 3);
    else if (sem == "camera.view") putMat(off, pose.view, matStride);
    else if (sem == "camera.projection") putMat(off, pose.projection, matStride);
    else if (sem == "camera.view_projection") putMat(off, pose.viewProjection(), matStride);
    else if (sem == "model.matrix") putMat(off, pose.model, matStride);
    else if (sem == "dapple.matrix") putMat(off, pose.dapple, matStride);
    else throw std::runtime_error("no value for uniform semantic " + sem);
  }
  return data;
}

bool hasUniform(const json& refl, const std::string& semantic) {
  for (const auto& m : refl["uniform_block"]["members"])
    if (m["semantic"] == semantic) return true;
  return false;
}

// clip.position on the CPU, in double precision, straight from docs/semantics.md:
// object = position + sum_i w_i * morph.position[i]; M = sum_k weight_k * B[joint_k]
// (skinned) or model.matrix; clip = projection * view * M * vec4(object, 1).
glm::dvec4 cpuClipPosition(const sg::rt::Mesh& mesh, const sg::rt::Pose& pose, const json& refl, size_t v) {
  glm::dvec3 object(mesh.at("vertex.position")[v]);
  for (size_t i = 0; i < pose.morphWeights.size(); ++i)
    if (mesh.has("morph.position[" + std::to_string(i) + "]"))
      object += double(pose.morphWeights[i]) * glm::dvec3(mesh.at("morph.position[" + std::to_string(i) + "]")[v]);
  glm::dmat4 m(1.0);
  if (hasUniform(refl, "skin.bones")) {
    m = glm::dmat4(0.0);
    glm::vec4 joints = mesh.at("skin.joints[0]")[v], weights = mesh.at("skin.weights[0]")[v];
    for (int k = 0; k < 4; ++k) m += double(weights[k]) * glm::dmat4(pose.bones.at(static_cast<size_t>(joints[k])));
  } else if (hasUniform(refl, "model.matrix")) {
    m = glm::dmat4(pose.model);
  }
  return glm::dmat4(pose.projection) * glm::dmat4(pose.view) * m * glm::dvec4(object, 1.0);
}

// Runs one shader over the mesh and compares gl_Position of every vertex with the CPU.
bool check(sg::rt::Harness& harness, const char* name, std::vector<uint32_t> spirv, const json& refl,
           const sg::rt::Mesh& mesh, const sg::rt::Pose& pose) {
  sg::rt::RunRequest req;
  req.spirv = std::move(spirv);
  req.streams = buildStreams(refl, mesh);
  req.uniformData = buildUniforms(refl, pose);
  req.vertexCount = static_cast<uint32_t>(mesh.vertexCount);
  // A --capture build records the outputs in reflection order, tightly packed.
  uint32_t stride = 0, positionOffset = 0;
  for (const auto& o : refl["outputs"]) {
    if (o["name"] == "gl_Position") positionOffset = stride;
    stride += 4u * static_cast<uint32_t>(components(o["type"]));
  }
  req.capture.strideBytes = stride;
  sg::rt::RunResult res = harness.run(req);

  bool ok = true;
  double worst = 0;
  for (size_t v = 0; v < mesh.vertexCount; ++v) {
    glm::vec4 gpu;
    std::memcpy(&gpu[0], res.captured.data() + v * stride + positionOffset, sizeof gpu);
    glm::dvec4 cpu = cpuClipPosition(mesh, pose, refl, v);
    for (int c = 0; c < 4; ++c) {
      double err = std::abs(gpu[c] - cpu[c]) / (1.0 + std::abs(cpu[c]));
      worst = std::max(worst, err);
      if (!(err <= 1e-4)) ok = false;
    }
    if (v == 0)
      std::printf("%s: gl_Position[0] gpu (%.5f, %.5f, %.5f, %.5f) cpu (%.5f, %.5f, %.5f, %.5f)\n", name, gpu.x, gpu.y,
                  gpu.z, gpu.w, cpu.x, cpu.y, cpu.z, cpu.w);
  }
  std::printf("%s: %zu vertices, max relative error %.2g: %s\n", name, mesh.vertexCount, worst, ok ? "match" : "MISMATCH");
  return ok;
}

}  // namespace

int main() {
  try {
    sg::rt::Harness harness;  // lavapipe, Khronos validation layers if installed
    std::printf("device: %s\n", harness.deviceName().c_str());

    // Dawn's face rig: 98 bones, 4 influences, 5 morph targets moving position and normal.
    sg::rt::MeshOptions faceOpts;
    faceOpts.bones = 98;
    faceOpts.influences = 4;
    faceOpts.morphTargets = 5;
    sg::rt::Mesh head = sg::rt::makeHead(3, 4, faceOpts);
    // A simple pose: the rest pose, the neck bent 30 degrees, the jaw moved, two morphs on.
    sg::rt::Pose facePose = sg::rt::makeRestPose(sg::rt::rigShapeFor(faceOpts));
    facePose.bones[0] = glm::rotate(glm::mat4(1.0f), glm::radians(30.0f), glm::vec3(1, 0, 0));
    facePose.bones[1] = glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, -0.1f, 0.05f));
    facePose.morphWeights = {0.5f, 0.25f, 0.0f, 0.0f, 1.0f};
    bool ok = check(harness, "face", faceShaderWords(), readJson(SHADERGEN_FACE_REFLECTION), head, facePose);

    // The prop: unskinned, placed by its model matrix.
    sg::rt::MeshOptions propOpts;
    propOpts.influences = 0;
    propOpts.morphTargets = 0;
    sg::rt::Mesh limb = sg::rt::makeLimb(2, 4, propOpts);
    sg::rt::Pose propPose = sg::rt::makeRestPose(sg::rt::rigShapeFor(propOpts));
    propPose.model = glm::translate(glm::mat4(1.0f), glm::vec3(0.5f, 0.0f, -1.0f)) *
                     glm::rotate(glm::mat4(1.0f), glm::radians(45.0f), glm::vec3(0, 1, 0));
    ok = check(harness, "prop", readSpirv(SHADERGEN_PROP_SPV), readJson(SHADERGEN_PROP_REFLECTION), limb, propPose) && ok;

    for (const auto& m : harness.validationMessages()) std::printf("validation: %s\n", m.c_str());
    ok = ok && harness.validationMessages().empty();
    std::printf("%s\n", ok ? "OK" : "FAILED");
    return ok ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "shadergen_consumer: %s\n", e.what());
    return 1;
  }
}
