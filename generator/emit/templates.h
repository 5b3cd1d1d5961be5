// The GLSL templates in templates/vertex.glsl: named sections with {{key}} holes.
#pragma once
#include <map>
#include <string>

namespace sg {

class TemplateSet {
 public:
  // Loads templates/vertex.glsl from `dir`. Throws InputError if missing or malformed.
  static TemplateSet load(const std::string& dir);
  static TemplateSet parse(const std::string& text, const std::string& file);
  // Fills section `name`; every {{key}} must be in `values` (throws std::logic_error).
  std::string fill(const std::string& name, const std::map<std::string, std::string>& values) const;
  const std::string& file() const { return file_; }

 private:
  std::string file_;
  std::map<std::string, std::string> sections_;
};

// Where templates live: $SHADERGEN_TEMPLATES, else <exe>/../share/shadergen/templates,
// else the source tree this binary was built from.
std::string defaultTemplateDir();

}  // namespace sg
