// Encoded vertex semantics: a value the application may store in a form other than itself,
// which a rule decodes on the GPU (rules/encodings.yaml). The host side is here: the exact
// encoder and decoder (validation derives the stored stream from the float data and feeds
// the reference the decode of what the device reads), and each encoding's worst error in
// a given vertex format, which error budgets compare against (--max-error).
#pragma once
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "common/diagnostics.h"
#include "rig/rig.h"
#include "rig/vertex_format.h"

namespace sg {

struct VertexEncoding {
  std::string encoded;  // the stored semantic: "vertex.normal_octahedral"
  std::string source;   // what it encodes: "vertex.normal"
  std::string name;     // "octahedral"
  std::string unit;     // the unit of its error: "deg" (an angle)
};

// Every encoding the standard vocabulary declares.
const std::vector<VertexEncoding>& vertexEncodings();
const VertexEncoding* encodingOf(const std::string& encodedSemantic);

// Octahedral unit vectors (Cigolle et al. 2014, "A Survey of Efficient Representations for
// Independent Unit Vectors", JCGT 3(2)): the direction projected onto the octahedron
// |x|+|y|+|z| = 1, the lower half folded over the diagonals, read as (x, y) in [-1, 1]^2.
// Encode of the zero vector is (0, 0) (which decodes to +z); decode returns a unit vector.
glm::dvec2 octahedralEncode(const glm::dvec3& v);
glm::dvec3 octahedralDecode(const glm::dvec2& e);

// The formats an encoding may be stored in, and its worst error there (in its unit), for
// any input. Octahedral, two components of snorm8 / snorm16 / float16 / float32 (x2, or two
// of x4, so a normal and a tangent share one location): a stored code is
// off by at most e per component (the format's rounding, vertex_format.h, plus the float32
// rounding of the code: 2^-24); on the octahedron's surface (on either side of a fold) that
// moves the point along a path of length <= sqrt(6) e, at least 1/sqrt(3) from the origin,
// so the direction turns by at most sqrt(18) e radians: snorm8 0.957 deg, snorm16 0.0037
// deg, float16 0.12 deg (the published maxima for 8 and 16 bits are 0.95 and 0.0037 deg).
// std::nullopt: the format cannot hold the encoding.
std::optional<double> encodingMaxError(const VertexEncoding& e, VertexFormat f);
// "snorm8x2, snorm16x2, float16x2, float32x2" for messages.
std::string encodingFormats(const VertexEncoding& e);

// The attribute that provides `semantic` (per-target streams excepted), or nullptr.
const RigAttribute* attributeProviding(const Rig& rig, const std::string& semantic);
// The rig without the parts that provide these semantics (an attribute left with no part
// goes too): how a stored form is taken out of the search's reach.
Rig withoutProvided(const Rig& rig, const std::set<std::string>& semantics);

// Error budgets (--max-error): the worst error allowed per source semantic, in the
// encodings' unit (degrees). The rig without the encoded parts over budget (an attribute
// left with no part goes too), so the search is never offered them; one note per removal.
// A budget naming no encoding's source is an InputError.
Rig withinErrorBudgets(const Rig& rig, const std::map<std::string, double>& budgets, std::vector<Diagnostic>& notes);

}  // namespace sg
