#include "measure/corpus.h"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>

namespace sg {
namespace {

// Deterministic picks from std::mt19937's raw output (the distributions of the standard
// library differ between implementations).
struct Pick {
  std::mt19937 g;
  explicit Pick(uint32_t seed) : g(seed) {}
  uint32_t below(uint32_t n) { return static_cast<uint32_t>(g() % n); }
  bool percent(uint32_t p) { return below(100) < p; }
  template <class T>
  const T& of(const std::vector<T>& v) { return v[below(static_cast<uint32_t>(v.size()))]; }
};

// A varying of the vocabulary and what the rig must carry to serve it.
struct Request {
  std::vector<std::string> names;  // inputs declared together (the frame's three rows)
  const char* type;
  bool normal, frame, uv1, occlusion;
};

const std::vector<Request>& vocabulary() {
  static const std::vector<Request> v = {
      {{"world_position"}, "vec3", false, false, false, false},
      {{"WorldEyeDir"}, "vec3", false, false, false, false},
      {{"world_normal"}, "vec3", true, false, false, false},
      {{"WorldTanMatrixX", "WorldTanMatrixY", "WorldTanMatrixZ"}, "vec3", true, true, false, false},
      {{"SkinUVST"}, "vec4", false, false, true, false},
      {{"SkinSilhouetteVec"}, "vec4", true, false, false, true},
  };
  return v;
}

}  // namespace

CorpusCase randomCorpusCase(uint32_t seed) {
  Pick r(seed);
  CorpusCase c;
  c.seed = seed;
  c.name = fmt::format("corpus-{}", seed);

  // Skinning.
  const int influences = r.percent(12) ? 0 : r.of(std::vector<int>{1, 2, 3, 4, 4, 4, 6, 8, 12, 16});
  int bones = 0;
  if (influences > 0) {
    switch (r.below(3)) {
      case 0: bones = 1 + int(r.below(16)); break;
      case 1: bones = 16 + int(r.below(112)); break;
      default: bones = 128 + int(r.below(173)); break;
    }
    bones = std::max(bones, influences);
  }
  const int targets = r.percent(50) ? 0 : 1 + int(r.below(60));
  const bool uniformScale = r.percent(30);

  // Attribute forms.
  const int normalForm = int(r.below(5));  // float32x3, float32x4+occlusion, snorm16, snorm8, octahedral
  const bool occlusion = normalForm == 1;
  const bool octahedral = normalForm == 4;
  const bool floatNormal = normalForm <= 1;
  const bool tangent = octahedral || r.percent(70);
  const bool morphNormal = targets > 0 && floatNormal && r.percent(60);
  const int uvForm = octahedral ? 4 : int(r.below(4));  // float32x2, unorm16x2, float16x2, Dawn's uvst, octahedral's
  const bool uv1 = uvForm == 3 || r.percent(50);

  std::string a;
  a += fmt::format("  position: {{ format: {} }}\n",
                   r.percent(70) ? "float32x3, provides: vertex.position" : "float16x4, provides: { vertex.position: xyz }");
  switch (normalForm) {
    case 0: a += "  normal: { format: float32x3, provides: vertex.normal }\n"; break;
    case 1: a += "  normal: { format: float32x4, provides: { vertex.normal: xyz, vertex.occlusion: w } }\n"; break;
    case 2: a += "  normal: { format: snorm16x4, provides: { vertex.normal: xyz } }\n"; break;
    case 3: a += "  normal: { format: snorm8x4, provides: { vertex.normal: xyz } }\n"; break;
    default: a += "  frame: { format: snorm16x4, provides: { vertex.normal_octahedral: xy, vertex.tangent_octahedral: zw } }\n";
  }
  if (tangent && !octahedral)
    a += fmt::format("  tangent: {{ format: {}, provides: {{ vertex.tangent: xyz, vertex.handedness: w }} }}\n",
                     r.of(std::vector<std::string>{"float32x4", "float16x4", "snorm10-10-10-2"}));
  switch (uvForm) {
    case 0: a += "  uv: { format: float32x2, provides: vertex.texcoord0 }\n"; break;
    case 1: a += "  uv: { format: unorm16x2, provides: vertex.texcoord0 }\n"; break;
    case 2: a += "  uv: { format: float16x2, provides: vertex.texcoord0 }\n"; break;
    case 3: a += "  uvst: { format: float32x4, provides: { vertex.texcoord0: xy, vertex.texcoord1: zw } }\n"; break;
    default: a += "  uv: { format: float16x4, provides: { vertex.texcoord0: xy, vertex.handedness: z } }\n";
  }
  if (uv1 && uvForm != 3)
    a += fmt::format("  uv1: {{ format: {}, provides: vertex.texcoord1 }}\n",
                     r.of(std::vector<std::string>{"float32x2", "snorm16x2", "snorm8x2"}));
  if (targets > 0) {
    a += "  coord_morph: { format: float32x3, per_target: true, provides: morph.position }\n";
    if (morphNormal)
      a += occlusion ? "  normal_morph: { format: float32x4, per_target: true, provides: { morph.normal: xyz, morph.occlusion: w } }\n"
                     : "  normal_morph: { format: float32x3, per_target: true, provides: morph.normal }\n";
  }
  const std::string joints = bones > 256 ? "uint16x4" : r.of(std::vector<std::string>{"uint8x4", "uint16x4"});
  for (int set = 0; set * 4 < influences; ++set) {
    a += fmt::format("  joints{}: {{ format: {}, provides: \"skin.joints[{}]\" }}\n", set, joints, set);
    a += fmt::format("  weights{}: {{ format: {}, provides: \"skin.weights[{}]\" }}\n", set,
                     r.of(std::vector<std::string>{"float32x4", "unorm16x4", "unorm8x4", "unorm10-10-10-2"}), set);
  }

  std::string u;
  if (influences > 0) u += "  bones: { type: mat4, array: bones, semantic: skin.bones }\n";
  if (targets > 0) u += "  morph_weight: { type: float, array: morph_targets, semantic: morph.weights }\n";
  if (influences == 0) u += "  model: { type: mat4, semantic: model.matrix }\n";
  u += "  cam_pos: { type: vec3, semantic: camera.position }\n";
  u += "  view: { type: mat4, semantic: camera.view }\n";
  u += "  projection: { type: mat4, semantic: camera.projection }\n";
  if (occlusion) u += "  dapple: { type: mat4, semantic: dapple.matrix }\n";

  std::string d;
  if (influences > 0) d += fmt::format("  bones: {}\n  influences: {}\n", bones, influences);
  if (targets > 0) d += fmt::format("  morph_targets: {}\n  morphs: [{}]\n", targets, morphNormal ? "position, normal" : "position");
  if (uniformScale) d += "  uniform_scale: 1\n";

  c.rigYaml = fmt::format("# A random rig of the calibration corpus (generator/measure/corpus.h), seed {}.\nrig: {}\n", seed, c.name);
  if (!d.empty()) c.rigYaml += "deformers:\n" + d;
  c.rigYaml += "attributes:\n" + a + "uniforms:\n" + u;

  // The request: each varying the rig can serve, with probability 1/2; at least one.
  std::vector<const Request*> chosen;
  for (const Request& q : vocabulary()) {
    const bool served = (!q.frame || tangent) && (!q.uv1 || uv1) && (!q.occlusion || occlusion);
    if (served && r.percent(50)) chosen.push_back(&q);
  }
  if (chosen.empty()) chosen.push_back(&vocabulary()[r.below(2)]);  // world_position or WorldEyeDir
  std::string ins, body;
  int location = 0;
  for (const Request* q : chosen)
    for (const auto& n : q->names) {
      ins += fmt::format("layout(location = {}) in {} {};\n", location++, q->type, n);
      body += std::string(q->type) == "vec3" ? fmt::format("  c.xyz += {};\n", n) : fmt::format("  c += {};\n", n);
    }
  c.fragment = fmt::format("#version 450\n// A random request of the calibration corpus, seed {}.\n{}"
                           "layout(location = 0) out vec4 color;\nvoid main() {{\n  vec4 c = vec4(0.0);\n{}  color = c;\n}}\n",
                           seed, ins, body);
  return c;
}

std::vector<CorpusCase> randomCorpus(size_t n, uint32_t seed) {
  std::vector<CorpusCase> out;
  std::mt19937 g(seed);
  for (size_t i = 0; i < n; ++i) out.push_back(randomCorpusCase(static_cast<uint32_t>(g())));
  return out;
}

CorpusFiles writeCorpusCase(const CorpusCase& c, const std::string& dir) {
  std::filesystem::create_directories(dir);
  CorpusFiles f{(std::filesystem::path(dir) / (c.name + ".rig.yaml")).string(),
                (std::filesystem::path(dir) / (c.name + ".frag")).string()};
  for (const auto& [path, text] : {std::pair{f.rig, c.rigYaml}, std::pair{f.fragment, c.fragment}}) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out << text;
    if (!out) throw std::runtime_error("cannot write " + path);
  }
  return f;
}

}  // namespace sg
