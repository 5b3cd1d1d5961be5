// `shadergen build`: every variant of a manifest in one process. Inputs are loaded once
// and shared; variants are searched and compiled on all cores; a content-addressed cache
// (key: every input's bytes, the options, the tool version) skips unchanged variants
// across builds; identical SPIR-V is kept once. The result is plain data: the files to
// write (the CLI writes them atomically) and an index of every variant.
#pragma once
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "rig/gltf_import.h"
#include "variants/manifest.h"

namespace sg {

struct BuildOptions {
  std::string cacheDir;  // "" = no cache
  unsigned jobs = 0;     // 0 = every hardware thread
  // Called (under a lock) as each variant finishes.
  std::function<void(size_t done, size_t total, const std::string& variant, bool cached)> progress;
  GltfReadOptions gltf;  // how glTF rigs are read (--no-normalize-weights, --Werror)
};

struct BuiltVariant {
  const Variant* variant = nullptr;
  bool ok = false;
  bool cached = false;                 // taken from the cache
  std::vector<Diagnostic> errors;      // when !ok: the generator's error (first) and related ones
  std::string key;                     // cache key (SHA-256)
  int64_t cost = 0;
  std::vector<std::string> rules;      // plan rules in order
  std::string glsl, spirv, reflection; // outputs (spirv: the module's bytes)
  std::string hlsl, msl;               // when the manifest emits them
  std::string spirvHash;               // SHA-256 of the SPIR-V
  std::vector<std::string> inputs;     // every file it was made from (depfile)
  std::string skinWeights;             // the rig's (Rig::skinWeights): recorded in the index
  std::map<std::string, std::string> outputs;  // kind -> path written
};

struct OutputFile {
  std::string path;
  std::string contents;
};

struct BuildReport {
  std::vector<BuiltVariant> variants;  // in manifest order
  std::vector<OutputFile> files;       // to write; deterministic order and bytes
  std::string indexPath;
  size_t cached = 0, generated = 0, failed = 0, sharedSpirv = 0;
  std::vector<Diagnostic> warnings;    // the glTF rigs' import diagnostics, once per rig
};

// Builds every variant. Throws InputError when a shared input (rig, rules, fragment shader,
// templates) cannot be loaded; per-variant failures are reported in BuiltVariant::errors
// and leave the index out of `files`.
BuildReport buildVariants(const Manifest& m, const std::vector<Variant>& variants, const BuildOptions& opts);

}  // namespace sg
