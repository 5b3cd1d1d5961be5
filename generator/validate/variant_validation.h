// `shadergen build --validate`: every variant run on a Vulkan device (lavapipe by default)
// against the GLM reference, by the `validate` command's Validator, with the manifest's
// `validate:` settings (docs/variants.md, "Validated variants"). YAML rigs are posed on a
// procedural mesh, glTF primitives on their own mesh at the given animation times.
#pragma once
#include <map>
#include <memory>
#include <mutex>
#include <vector>

#include "validate/validate.h"
#include "variants/builder.h"

namespace sg {

class DeviceVariantValidator : public VariantValidator {
 public:
  // Opens the device (throws std::runtime_error when there is none such).
  explicit DeviceVariantValidator(const ManifestValidation& settings);
  ~DeviceVariantValidator() override;
  std::string identity() const override;
  ValidationResult validate(const Variant& v, const GenerateOptions& gen) override;
  const std::string& deviceName() const { return device_; }

 private:
  ValidateOptions options(const GenerateOptions& gen) const;
  std::shared_ptr<const ValidationScene> sceneOf(const std::string& rigPath, const std::map<std::string, int64_t>& params,
                                                 const GltfReadOptions& read);
  ManifestValidation settings_;
  std::string device_, driver_;
  std::mutex lock_;
  std::vector<std::unique_ptr<Validator>> idle_;  // one per worker at most, each its own device
  std::map<std::string, std::shared_ptr<const ValidationScene>> scenes_;  // by rig path and parameters
};

}  // namespace sg
