// Helpers for the glTF tests: paths of the shared models and a builder for tiny glTF
// files (JSON text with one data-URI buffer) for cases the sample models do not cover.
#pragma once
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "gltf_builder.h"

namespace sg::test {

// The shared sample models sit next to the checkout (../shared); SHADERGEN_SHARED_DIR overrides.
inline std::string sharedDir() {
  const char* env = std::getenv("SHADERGEN_SHARED_DIR");
  return env && *env ? env : SG_SHARED_DIR;
}
inline std::string modelPath(const std::string& rel) { return sharedDir() + "/models/" + rel; }

// Without the shared models these tests cannot run: skip them all, loudly, rather than fail
// on a checkout placed elsewhere.
class SharedModelsEnvironment : public ::testing::Environment {
 public:
  void SetUp() override {
    if (!std::filesystem::exists(modelPath("README.md")))
      GTEST_SKIP() << "no sample models at " << modelPath("") << " (set SHADERGEN_SHARED_DIR)";
  }
};
inline ::testing::Environment* const kSharedModels = ::testing::AddGlobalTestEnvironment(new SharedModelsEnvironment);
inline std::string sourcePath(const std::string& rel) { return std::string(SG_SOURCE_DIR) + "/" + rel; }
inline std::string dataPath(const std::string& rel) { return std::string(SG_SOURCE_DIR) + "/tests/gltf/data/" + rel; }

}  // namespace sg::test
