// A variant manifest (`shadergen build MANIFEST.yaml`, docs/variants.md): named rigs,
// fragment shaders (passes) and rules, and variant axes whose product, minus the
// exclusions, is the set of vertex shaders to make.
#pragma once
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "common/glsl_compile.h"
#include "emit/cross_compile.h"
#include "interface/fragment_interface.h"
#include "pipeline/pin.h"

namespace sg {

struct ManifestPass {
  std::string name;
  std::string fragment;                  // path
  std::vector<VaryingOverride> maps;     // like --map
  std::vector<std::string> conventions;  // like --conventions (empty = all, where they agree)
  SourceLoc loc;
};

struct ManifestRig {
  // A whole model (`name: MODEL.glb#*`) becomes one rig per primitive, named
  // "<name>.<part name>" (rig/gltf_import.h gltfPartName: "robot.m2p1-Head"); a rig axis value
  // that names the model stands for all of them.
  std::string name;
  std::string path;  // YAML rig or MODEL.glb#m/p
  SourceLoc loc;
  // Rules its variants' search may not use, as `generate --ban` (`ban:`): a plan `bench` timed
  // faster on the device, pinned (docs/variants.md, "Pinning a plan").
  std::vector<std::string> bans;
  SourceLoc banLoc;
};

// One axis: `rig` and `pass` pick named rigs and passes; any other axis sets the rig
// deformer parameter of that name (morph_targets, influences, ...).
struct ManifestAxis {
  std::string name;
  std::vector<std::string> values;
  SourceLoc loc;
};

struct ManifestExclusion {
  std::map<std::string, std::string> match;  // axis -> value; a variant matching all is left out
  SourceLoc loc;
};

// `validate:` (docs/variants.md, "Validated variants"): how `build --validate` runs each
// variant, as the `validate` command's options say it for one shader.
struct ManifestValidation {
  bool enabled = false;        // the manifest asks for it (`build --validate` also turns it on)
  std::string mesh = "head";   // YAML rigs: procedural mesh (head, limb, dawn)
  uint32_t seed = 1;           // YAML rigs: seed of the random poses
  int poses = 2;               // YAML rigs: how many (1..100)
  std::vector<double> times;   // glTF rigs: animation times (empty: validate's default)
  std::string animation;       // glTF rigs: name or index ("" = the first)
  std::optional<double> morphWeight;  // glTF rigs: every morph target at this weight
  double toleranceAbs = 1e-6, toleranceRel = 1e-5;
  bool crossCheck = false;
  bool strict = false;
  bool floatCheck = true;
  bool validationLayers = true;
  std::string device;          // Vulkan device name (substring); "" = lavapipe
  SourceLoc loc;
};

struct Manifest {
  std::string file;
  std::string outputDir;               // relative paths resolved against the manifest
  std::vector<std::string> rules;
  std::string templates;               // "" = the default templates
  std::vector<ManifestRig> rigs;
  std::vector<std::string> wholeModelFiles;  // glTF files whose primitives became rigs (MODEL.glb#*)
  std::vector<ManifestPass> passes;
  std::vector<ManifestAxis> axes;      // in manifest order (the first varies slowest)
  std::vector<ManifestExclusion> exclude;
  std::string nameFormat;              // "{rig}-{pass}-m{morph_targets}"; default: every axis joined by '-'
  std::vector<std::string> emit{"glsl", "spv", "reflection"};
  TargetEnv targetEnv = TargetEnv::Vulkan1_0;
  bool optimize = false;
  std::string heuristic = "lmcut";
  // `max_error:` error budgets per encoded semantic, in its encodings' unit (GenerateOptions::maxError).
  std::map<std::string, double> maxError;
  std::string deviceProfile;  // `device_profile:` (docs/device-profiles.md); "" = instruction slots
  // `device_profile: [a, b, ...]`: the rest of the list, a portable plan across every profile
  // (GenerateOptions::portableProfilePaths); empty with one profile.
  std::vector<std::string> portableProfiles;
  // `mesh:` the procedural mesh (head, limb, dawn) whose workload YAML rigs are priced for
  // under the device profile; glTF rigs are measured on their own mesh. "" = unknown.
  std::string mesh;
  HlslOptions hlsl;           // `hlsl_shader_model:`, when emit has hlsl (docs/hlsl-msl.md)
  MslOptions msl;             // `msl_version:`, `msl_platform:`, when emit has msl
  ManifestValidation validate;  // `validate:`
  std::string cacheUrl;         // `cache_url:`, the shared cache (no credentials here)
  // `pins:` variant name -> its pin (`bench --pin-out`, pipeline/pin.h): that variant's plan is the
  // one a device timed fastest (docs/variants.md, "Pinning a plan"). Every name is a variant's.
  std::map<std::string, Pin> pins;
  std::string pinsDir;  // `pins: DIR`: each variant's DIR/<name>.pin.yaml, where it exists (bench --manifest --pin-out DIR)
  bool emits(const std::string& kind) const;
};

// One shader to make.
struct Variant {
  std::string name;  // unique; a safe file stem
  const ManifestRig* rig = nullptr;
  const ManifestPass* pass = nullptr;
  std::map<std::string, int64_t> params;           // deformer parameters set by axes
  std::vector<std::pair<std::string, std::string>> axes;  // axis -> value, in axis order
};

// Loads and checks a manifest; paths are made relative to the working directory.
// Throws InputError (file:line:col) on malformed input.
Manifest loadManifest(const std::string& path);
Manifest loadManifestText(const std::string& text, const std::string& file);

// The product of the axes minus the exclusions, in a stable order. Throws InputError for
// duplicate variant names, unknown rigs/passes, non-integer parameter values, names that
// are not safe file names, and an empty product.
std::vector<Variant> expandVariants(const Manifest& m);

}  // namespace sg
