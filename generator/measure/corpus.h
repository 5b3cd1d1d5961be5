// Training data that is not the test (issue 33): random but valid rigs and random requests,
// for `calibrate --corpus N --seed S` (docs/device-profiles.md, "Corpus"). Each case is a rig
// in the YAML format of docs/rig-format.md and a fragment shader requesting varyings from
// the vocabulary of examples/dawn/rules.yaml (over rules/standard.yaml), which the rig can
// serve. Deterministic per seed on every platform: std::mt19937's raw output, mapped here.
//
// What varies: skinning (unskinned with a model matrix, or 1-16 influences in sets of 4
// over a palette of 1-300 bones, joints as uint8x4/uint16x4, weights as float32x4,
// unorm16x4, unorm8x4 or unorm10-10-10-2), 0-60 morph targets moving the position (and the
// normal), the formats and encodings of position, normal (float, snorm, octahedral, with
// occlusion in w), tangent and texture coordinates, and uniform_scale. Whether a large
// palette or many targets are read from attributes, the uniform block or storage buffers
// is the search's choice (docs/buffers.md), so the corpus exercises both forms.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace sg {

struct CorpusCase {
  std::string name;      // "corpus-<seed>": the rig's name and the files' stem
  std::string rigYaml;   // a rig file's text
  std::string fragment;  // GLSL 450 fragment shader
  uint32_t seed = 0;
};

// One random case.
CorpusCase randomCorpusCase(uint32_t seed);
// n cases from seeds derived from `seed` (the first is randomCorpusCase of a mix of seed and 0).
std::vector<CorpusCase> randomCorpus(size_t n, uint32_t seed);

struct CorpusFiles {
  std::string rig, fragment;
};
// Writes <dir>/<name>.rig.yaml and <dir>/<name>.frag (dir created); returns the paths.
CorpusFiles writeCorpusCase(const CorpusCase& c, const std::string& dir);

}  // namespace sg
