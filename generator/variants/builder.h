// `shadergen build`: every variant of a manifest in one process. Inputs are loaded once
// and shared; variants are searched and compiled on all cores; a content-addressed cache
// (key: every input's bytes, the options, the tool version) skips unchanged variants
// across builds; identical SPIR-V is kept once. The result is plain data: the files to
// write (the CLI writes them atomically) and an index of every variant.
#pragma once
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "pipeline/generate.h"
#include "variants/cache_store.h"
#include "search/workload.h"
#include "rig/gltf_import.h"
#include "variants/manifest.h"

namespace sg {

// What validating a variant found. A passing result is cached (docs/variants.md,
// "Validated variants"), with the time it was made: a cache hit reproduces the index's bytes.
struct ValidationResult {
  bool pass = false;
  std::string device, driver;  // where it ran
  std::string tool;            // the shadergen version that made it
  std::string made;            // UTC, ISO 8601: when the result was made
  size_t runs = 0;             // plans run (with cross-check, every alternative too)
  std::string worstOutput;     // the output with the largest relative error, and its errors
  double maxAbsError = 0, maxRelError = 0;
  std::vector<Diagnostic> errors;  // when !pass: why, the variant's failing outputs
};

// Runs built variants on a device (validate/variant_validation.h implements it with the
// `validate` command's Validator): the variants stage only calls it.
class VariantValidator {
 public:
  virtual ~VariantValidator() = default;
  // Everything a result depends on besides the variant's inputs (its cache key): the
  // settings, the device and its driver, the tool version. Hashed into the result's key.
  virtual std::string identity() const = 0;
  // Validates the plan `gen` makes for `v` (the variant as built). Called from worker threads.
  virtual ValidationResult validate(const Variant& v, const GenerateOptions& gen) = 0;
};

struct BuildOptions {
  std::string cacheDir;  // "" = no local cache
  std::string cacheUrl;  // "" = no remote cache (cache_store.h); credentials from cacheAuth only
  std::string cacheAuth;
  std::function<void(const std::string&)> warn;  // cache warnings (under a lock)
  VariantValidator* validator = nullptr;         // validate every variant (nullptr = do not)
  unsigned jobs = 0;     // 0 = every hardware thread
  // false: the index is left out; each variant leaves its index entry instead (entryFiles),
  // for a build system that builds variants one by one and joins the entries (joinIndex).
  bool index = true;
  // Called (under a lock) as each variant finishes.
  std::function<void(size_t done, size_t total, const std::string& variant, bool cached)> progress;
  // The workload each variant is priced for, by variant name (measured by the caller,
  // measure/workload.h; absent: unknown). Part of the cache key when known.
  std::map<std::string, Workload> workloads;
  GltfReadOptions gltf;  // how glTF rigs are read (--no-normalize-weights, --Werror)
};

// What `generate` is given to make variant `v` (the build loads the files once and prepares
// from them; the validator regenerates the capture build from these; bench --manifest times the
// variant's candidates from them). opts: its workloads and glTF reading.
GenerateOptions generateOptionsOf(const Manifest& m, const Variant& v, const BuildOptions& opts);

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
  std::optional<ValidationResult> validation;  // when validated (passing, or why it failed)
  bool validationCached = false;                // the result came from the cache
  std::string entry;                   // its element of index.json's "variants" (when ok)
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
  size_t validated = 0, validationsCached = 0;  // validations run, and taken from the cache
  CacheStoreStats cache;
  std::vector<Diagnostic> warnings;    // the glTF rigs' import diagnostics, once per rig
};

// Builds every variant. Throws InputError when a shared input (rig, rules, fragment shader,
// templates) cannot be loaded; per-variant failures are reported in BuiltVariant::errors
// and leave the index out of `files`.
BuildReport buildVariants(const Manifest& m, const std::vector<Variant>& variants, const BuildOptions& opts);

// ---- one build edge per variant (docs/variants.md, "One build edge per variant") --------
// `build --variant NAME` is buildVariants() of that variant with index = false: its outputs
// and depfile as a whole build writes them, plus its entry (<output>/.shadergen-variants/
// NAME.entry: its index element and inputs) and the entry's depfile. `build --join` then
// writes index.json and index.json.d from every variant's entry, byte-identical to the
// whole build's.
struct VariantEntryFiles {
  std::string entry;    // <output>/.shadergen-variants/NAME.entry
  std::string depfile;  // NAME.entry.d: the entry depends on the manifest and every input
};
VariantEntryFiles entryFiles(const Manifest& m, const Variant& v);

// index.json and index.json.d from the entries of `variants`. Throws InputError naming a
// variant whose entry is missing or unreadable.
std::vector<OutputFile> joinIndex(const Manifest& m, const std::vector<Variant>& variants);

// Every file each variant reads (its depfile's inputs, less the manifest), in the order of
// `variants`, and the outputs named after it (kind -> path; the SPIR-V, named by its
// content, is not known before the build): what a build system needs to give each variant
// its own edge. Loads the inputs (rigs, rules, fragment shaders); generates nothing.
struct PlannedVariant {
  std::vector<std::string> inputs;
  std::map<std::string, std::string> outputs;
  // Changes when the manifest or the options change what the variant makes (its cache key
  // less the files' contents, its name and outputs): the build system reruns it then, and
  // not for every manifest edit (the inputs' contents are the depfile's business).
  // Its entry's depfile lists its inputs but not the manifest, in favour of this.
  std::string stamp;
};
std::vector<PlannedVariant> planVariants(const Manifest& m, const std::vector<Variant>& variants);

}  // namespace sg
