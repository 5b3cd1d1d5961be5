// Loads the rig YAML (format documented in docs/rig-format.md).
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <set>

#include "common/yaml_util.h"
#include "rig/packed_fields.h"
#include "rig/rig.h"
#include "rig/vertex_encoding.h"

namespace sg {
namespace {

bool validSwizzle(const std::string& s, int components) {
  if (s.empty() || s.size() > 4) return false;
  static const std::string xyzw = "xyzw";
  for (char c : s) {
    auto p = xyzw.find(c);
    if (p == std::string::npos || static_cast<int>(p) >= components) return false;
  }
  return true;
}

bool validRigSemanticName(const std::string& s) {
  if (s.empty()) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.' || c == '[' || c == ']')) return false;
  return std::isalpha(static_cast<unsigned char>(s[0]));
}

// What validIdentifier accepts, for its errors.
constexpr const char* kIdentifierRule = "an ASCII letter or '_', then letters, digits and '_', not starting with 'gl_'";

bool validIdentifier(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return false;
  return s.rfind("gl_", 0) != 0;
}

}  // namespace

int64_t Rig::param(const std::string& key, int64_t fallback) const {
  auto it = params.find(key);
  return it == params.end() ? fallback : it->second;
}

Rig loadRigFile(const std::string& path) { return loadRigText(readInputFile(path), path); }

Rig loadRigText(const std::string& text, const std::string& fileName) {
  YamlCtx y{fileName};
  YAML::Node root = parseYaml(text, fileName);
  if (!root.IsDefined() || root.IsNull()) throw InputError(SourceLoc{fileName, 1, 1}, "empty rig file");
  y.expectMap(root, "a rig file");
  y.checkKeys(root, {"rig", "deformers", "attributes", "uniforms"});

  Rig rig;
  rig.file = fileName;
  rig.sourceFiles = {fileName};
  if (!root["rig"]) y.fail(root, "missing 'rig' (the rig's name)");
  rig.name = y.scalar(root["rig"], "'rig'");
  rig.nameLoc = locOf(root["rig"], fileName);
  // The name is quoted in generated comments and messages: printable text, one line.
  if (rig.name.empty() || rig.name.size() > kMaxRigNameBytes)
    y.fail(root["rig"], fmt::format("the rig's name must be 1..{} bytes of UTF-8", kMaxRigNameBytes));
  for (char c : rig.name)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
      y.fail(root["rig"], fmt::format("the rig's name contains control character 0x{:02x}", static_cast<unsigned char>(c)));

  rig.params = {{"bones", 0}, {"influences", 0}, {"morph_targets", 0}};
  if (auto d = root["deformers"]) {
    y.expectMap(d, "'deformers'");
    for (auto it = d.begin(); it != d.end(); ++it) {
      std::string key = y.scalar(it->first, "a deformer key");
      if (key == "morphs") {
        y.expectSeq(it->second, "'morphs'");
        YAML::Node morphs = it->second;  // a copy: it->second lives in a temporary proxy
        for (const auto& m : morphs) {
          std::string a = y.scalar(m, "a morphed attribute");
          if (a != "position" && a != "normal" && a != "tangent")
            y.fail(m, fmt::format("morph targets can move position, normal or tangent, not '{}'", a));
          rig.morphedAttributes.push_back(a);
        }
        continue;
      }
      if (!validIdentifier(key)) y.fail(it->first, fmt::format("'{}' is not a valid parameter name ({})", key, kIdentifierRule));
      long long v = y.integer(it->second, fmt::format("deformer '{}'", key).c_str());
      if (v < 0 || v > 65535) y.fail(it->second, fmt::format("deformer '{}' = {} is out of range 0..65535", key, v));
      rig.params[key] = v;
      rig.paramLocs[key] = locOf(it->second, fileName);
    }
  }
  if (rig.morphTargets() > kMaxMorphTargets)
    throw InputError(rig.paramLocs["morph_targets"], fmt::format("at most {} morph targets are supported", kMaxMorphTargets));
  if (rig.param("influences") > kMaxInfluences)
    throw InputError(rig.paramLocs["influences"],
                     fmt::format("at most {} bone influences per vertex are supported, got {} (kMaxInfluences)",
                                 kMaxInfluences, rig.param("influences")));
  if (rig.param("bones") > kMaxBones)
    throw InputError(rig.paramLocs["bones"], fmt::format("at most {} bones are supported, got {} (kMaxBones)",
                                                         kMaxBones, rig.param("bones")));

  if (!root["attributes"]) y.fail(root, "missing 'attributes'");
  y.expectMap(root["attributes"], "'attributes'");
  std::set<std::string> providedSemantics;
  for (auto it = root["attributes"].begin(); it != root["attributes"].end(); ++it) {
    if (rig.attributes.size() >= kMaxRigAttributes)
      y.fail(it->first, fmt::format("more than {} attributes", kMaxRigAttributes));
    RigAttribute a;
    a.name = y.scalar(it->first, "an attribute name");
    a.loc = locOf(it->first, fileName);
    if (!validIdentifier(a.name)) y.fail(it->first, fmt::format("'{}' is not a valid attribute name ({})", a.name, kIdentifierRule));
    YAML::Node body = it->second;  // a copy: it->second lives in a temporary proxy
    y.expectMap(body, "an attribute");
    y.checkKeys(body, {"format", "shader_type", "provides", "fields", "per_target", "doc"});
    if (!body["format"]) y.fail(body, fmt::format("attribute '{}' has no 'format'", a.name));
    std::string fmtName = y.scalar(body["format"], "'format'");
    if (!parseFormat(fmtName, a.format))
      y.fail(body["format"], fmt::format("unknown vertex format '{}' (expected one of: {})", fmtName, formatNames()));
    int n = formatComponents(a.format);
    a.shaderType = *vectorType(formatIsInteger(a.format) ? ScalarKind::UInt : ScalarKind::Float, n);
    if (body["shader_type"]) {
      // A vector wider than the format: the vertex input fills the components the format lacks
      // with 0, and w with 1 (Vulkan's vertex input extraction), so RGB colours read as RGBA.
      const std::string tn = y.scalar(body["shader_type"], "'shader_type'");
      const std::optional<Type> t = parseType(tn);
      if (formatIsInteger(a.format) || n == 4)
        y.fail(body["shader_type"], fmt::format("'shader_type' widens a float or normalized format of fewer than 4 "
                                                "components; {} is {}",
                                                fmtName, n == 4 ? "already 4 components" : "read as integers"));
      if (!t || scalarKind(*t) != ScalarKind::Float || isMatrix(*t) || componentCount(*t) <= n)
        y.fail(body["shader_type"],
               fmt::format("'shader_type: {}' must be a float vector of more components than {} ({}): the device fills "
                           "the missing ones (0, and 1 for w)",
                           tn, fmtName, n == 3 ? "vec4" : n == 2 ? "vec3 or vec4" : "vec2 to vec4"));
      a.shaderType = *t;
      a.widened = true;
      n = componentCount(*t);
    }
    if (body["per_target"]) a.perMorphTarget = y.boolean(body["per_target"], "'per_target'");
    // A part of the attribute (field -1, `what` "attribute") or of one of its fields.
    auto addPart = [&](const YAML::Node& semNode, const YAML::Node* swzNode, int field, VertexFormat format,
                       const YAML::Node& formatNode) {
      const int comps = field < 0 ? n : formatComponents(format);  // an attribute's: its shader type's
      const std::string what = field < 0 ? "attribute" : fmt::format("field ({})", formatName(format));
      ProvidedPart p;
      p.field = field;
      p.semantic = y.scalar(semNode, "a semantic name");
      if (!validRigSemanticName(p.semantic)) y.fail(semNode, fmt::format("'{}' is not a valid semantic name", p.semantic));
      if (swzNode) {
        p.swizzle = y.scalar(*swzNode, "a swizzle");
        if (!validSwizzle(p.swizzle, comps))
          y.fail(*swzNode, fmt::format("'{}' is not a valid swizzle of a {}-component {}", p.swizzle, comps, what));
      }
      if (!providedSemantics.insert(p.semantic).second)
        y.fail(semNode, fmt::format("semantic '{}' is provided twice", p.semantic));
      // An encoded value is decoded by its rule from the whole attribute, in a format
      // whose error is known (rig/vertex_encoding.h).
      if (const VertexEncoding* e = encodingOf(p.semantic);
          e && (!encodingMaxError(*e, format) ||
                (p.swizzle.empty() ? comps : static_cast<int>(p.swizzle.size())) != e->components))
        y.fail(swzNode ? *swzNode : formatNode,
               fmt::format("'{}' ({} {}) must be stored in {}, not {}{}", p.semantic, e->name, e->decodesText(),
                           encodingFormats(*e), formatName(format), p.swizzle.empty() ? "" : " ." + p.swizzle));
      if (const VertexEncoding* e = encodingOf(p.semantic); e && e->perTarget != a.perMorphTarget)
        y.fail(semNode, fmt::format("'{}' ({} {}) is {}stored per morph target: its attribute needs 'per_target: {}'",
                                    p.semantic, e->name, e->decodesText(), e->perTarget ? "" : "not ",
                                    e->perTarget ? "true" : "false"));
      a.provides.push_back(p);
    };
    auto addParts = [&](const YAML::Node& prov, int field, VertexFormat format, const YAML::Node& formatNode) {
      if (prov.IsScalar()) {
        addPart(prov, nullptr, field, format, formatNode);
      } else {
        y.expectMap(prov, "'provides'");
        for (auto p = prov.begin(); p != prov.end(); ++p) addPart(p->first, &p->second, field, format, formatNode);
      }
    };
    YAML::Node prov = body["provides"];
    YAML::Node fields = body["fields"];
    if (fields) {
      // Bit-packed: the fields provide, each from its place in the words (rig/packed_fields.h).
      if (!formatHoldsFields(a.format))
        y.fail(body["format"], fmt::format("attribute '{}' has 'fields', so its format must be uint32x4, uint32x2 or "
                                           "uint32 (the words its fields are packed into), not {}", a.name, fmtName));
      if (prov) y.fail(prov, fmt::format("attribute '{}' has 'fields': each field says what it provides, the "
                                         "attribute itself does not", a.name));
      if (a.perMorphTarget)
        y.fail(body["per_target"], fmt::format("attribute '{}': bit-packed attributes are not stored per morph target "
                                               "(pack each target's values into an attribute of its own)", a.name));
      y.expectSeq(fields, "'fields'");
      if (fields.size() == 0) y.fail(fields, fmt::format("attribute '{}' has no fields", a.name));
      std::vector<YAML::Node> fieldNodes;
      for (const auto& fn : fields) {
        YAML::Node f = fn;  // a copy: the iterator's node is a temporary
        y.expectMap(f, "a field");
        y.checkKeys(f, {"format", "provides", "doc"});
        if (!f["format"]) y.fail(f, "a field has no 'format'");
        const std::string name = y.scalar(f["format"], "'format'");
        PackedField pf;
        pf.loc = locOf(f, fileName);
        if (!parseFormat(name, pf.format))
          y.fail(f["format"], fmt::format("unknown vertex format '{}' (expected one of: {})", name, formatNames()));
        if (!f["provides"]) y.fail(f, "a field provides no semantic ('provides')");
        a.fields.push_back(pf);
        fieldNodes.push_back(f);
        addParts(f["provides"], static_cast<int>(a.fields.size()) - 1, pf.format, f["format"]);
      }
      if (!layoutFields(a.fields, n)) {
        for (size_t i = 0; i < a.fields.size(); ++i) {
          const PackedField& f = a.fields[i];
          const int end = 32 * f.word + f.bit + fieldBits(f.format);
          if (end > 32 * n)
            y.fail(fieldNodes[i], fmt::format("field {} ({}) would take bits {}..{}, past the {} bits of {} (fields are "
                                              "placed in order, each aligned to its component size)", i + 1,
                                              formatName(f.format), end - fieldBits(f.format), end - 1, 32 * n, fmtName));
        }
      }
    } else {
      if (!prov) y.fail(body, fmt::format("attribute '{}' provides no semantic ('provides')", a.name));
      addParts(prov, -1, a.format, body["format"]);
    }
    rig.attributes.push_back(std::move(a));
  }

  if (auto u = root["uniforms"]) {
    y.expectMap(u, "'uniforms'");
    for (auto it = u.begin(); it != u.end(); ++it) {
      if (rig.uniforms.size() >= kMaxRigUniforms) y.fail(it->first, fmt::format("more than {} uniforms", kMaxRigUniforms));
      RigUniform un;
      un.name = y.scalar(it->first, "a uniform name");
      un.loc = locOf(it->first, fileName);
      if (!validIdentifier(un.name)) y.fail(it->first, fmt::format("'{}' is not a valid uniform name ({})", un.name, kIdentifierRule));
      YAML::Node body = it->second;  // a copy: it->second lives in a temporary proxy
      y.expectMap(body, "a uniform");
      y.checkKeys(body, {"type", "semantic", "array", "doc"});
      if (!body["type"]) y.fail(body, fmt::format("uniform '{}' has no 'type'", un.name));
      std::string t = y.scalar(body["type"], "'type'");
      auto ty = parseType(t);
      if (!ty) y.fail(body["type"], fmt::format("unknown type '{}'", t));
      un.type = *ty;
      if (!body["semantic"]) y.fail(body, fmt::format("uniform '{}' has no 'semantic'", un.name));
      un.semantic = y.scalar(body["semantic"], "'semantic'");
      if (!validRigSemanticName(un.semantic)) y.fail(body["semantic"], fmt::format("'{}' is not a valid semantic name", un.semantic));
      if (!providedSemantics.insert(un.semantic).second)
        y.fail(body["semantic"], fmt::format("semantic '{}' is provided twice", un.semantic));
      if (body["array"]) {
        un.arraySizeParam = y.scalar(body["array"], "'array'");
        if (!rig.params.count(un.arraySizeParam))
          y.fail(body["array"], fmt::format("array size '{}' is not a deformer parameter of this rig", un.arraySizeParam));
        un.arraySize = static_cast<int>(rig.param(un.arraySizeParam));
      }
      rig.uniforms.push_back(std::move(un));
    }
  }
  // A code whose decode reads uniforms (bounds-relative positions) is useless without them.
  for (const RigAttribute& a : rig.attributes)
    for (const auto& p : a.provides)
      if (const VertexEncoding* e = encodingOf(p.semantic))
        for (const std::string& u : e->uniforms)
          if (!providedSemantics.count(u))
            throw InputError(a.loc, fmt::format("'{}' ({} {}) is decoded with the uniform '{}', which the rig does not "
                                                "declare (docs/rig-format.md, \"Encodings\")", p.semantic, e->name,
                                                e->decodesText(), u));
  // A unit direction or a morph delta is signed; an unsigned normalized format clamps its
  // negative components to 0 (a normal along -x reads as zero). Allowed, but almost surely
  // a slip for snorm: warned at the attribute (importDiagnostics: generate prints it).
  for (const RigAttribute& a : rig.attributes)
    for (const auto& p : a.provides) {
      static const std::set<std::string> kSigned = {"vertex.normal", "vertex.tangent", "vertex.binormal"};
      if (formatKind(partFormat(a, p)) != FormatKind::Unorm || (!kSigned.count(p.semantic) && !a.perMorphTarget)) continue;
      rig.importDiagnostics.push_back(Diagnostic{
          Severity::Warning, a.loc,
          fmt::format("attribute '{}' stores {} as {}, which clamps negative components to 0; a signed value wants "
                      "an snorm format",
                      a.name, p.semantic, formatName(partFormat(a, p))),
          ""});
    }
  checkRig(rig);
  return rig;
}

void checkRig(const Rig& rig) {
  std::set<std::string> names;
  int morphStreams = 0;
  for (const auto& a : rig.attributes) {
    if (!names.insert(a.name).second) throw InputError(a.loc, fmt::format("attribute '{}' is declared twice", a.name));
    if (a.perMorphTarget) {
      ++morphStreams;
      if (rig.morphTargets() == 0)
        throw InputError(a.loc, fmt::format("attribute '{}' is per morph target but the rig has morph_targets: 0", a.name));
    }
  }
  if (rig.morphTargets() > 0 && morphStreams == 0) {
    auto it = rig.paramLocs.find("morph_targets");
    throw InputError(it != rig.paramLocs.end() ? it->second : SourceLoc{rig.file, 1, 1},
                     "the rig has morph targets but no per_target attribute carries their deltas");
  }
  for (const auto& u : rig.uniforms) {
    if (!names.insert(u.name).second) throw InputError(u.loc, fmt::format("name '{}' is used twice", u.name));
    if (!u.arraySizeParam.empty() && u.arraySize <= 0)
      throw InputError(u.loc, fmt::format("uniform array '{}' has size {} ({} = 0)", u.name, u.arraySize, u.arraySizeParam));
  }
}

}  // namespace sg
