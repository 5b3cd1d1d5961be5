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
  std::string encoded;               // the stored semantic: "vertex.normal_octahedral"
  std::vector<std::string> sources;  // what it encodes, each within its stated error: {"vertex.normal"}
  std::vector<std::string> exact;    // what it encodes exactly besides (a QTangent's vertex.handedness)
  std::string name;                  // "octahedral", "bounds", "qtangent"
  // The unit of its error: "deg" (an angle), "of the bounds diagonal", "of the target's scale" (fractions).
  std::string unit;
  int components = 2;  // of the stored code
  // Uniforms its decode reads, which the host derives from the mesh (bounds: min, extent;
  // per-target scales: one value per morph target).
  std::vector<std::string> uniforms;
  bool perTarget = false;  // a code per morph target, stored by a per_target attribute
  bool angular() const { return unit == "deg"; }
  // Every value its decode gives: sources, then exact.
  std::vector<std::string> decodes() const;
  // decodes() for messages: "vertex.normal", "vertex.normal, vertex.tangent, vertex.handedness".
  std::string decodesText() const;
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

// Bounds-relative positions (as KHR_mesh_quantization and Godot 4 store them): the code is
// the position's place in the mesh's axis-aligned box, (p - min) / extent in [0, 1]^3,
// which a unorm format holds; the decode is min + code * extent with min and extent as
// uniforms (mesh.bounds_min, mesh.bounds_extent). The bounds are float32 (what the
// uniforms carry): min is the smallest coordinate per axis (a float already), extent is
// max - min rounded up, so every code lies in [0, 1]; a flat axis has extent 0 and code 0.
// Non-finite coordinates are left out of the bounds and encode as 0.
struct PositionBounds {
  glm::vec3 min{0.0f};
  glm::vec3 extent{0.0f};
};
PositionBounds positionBounds(const std::vector<glm::vec4>& positions);
glm::dvec3 boundsEncode(const PositionBounds& b, const glm::dvec3& p);
glm::dvec3 boundsDecode(const PositionBounds& b, const glm::dvec3& code);

// Morph deltas relative to their target's scale (as Godot and gltfpack quantise them): the
// code of target i's delta d is d / scale_i in [-1, 1]^3, which a snorm format holds;
// the decode multiplies by scale_i, a uniform array over the targets
// (morph.position_scale), which the morph sum folds into the target's weight. scale_i is
// the largest |component| of the target's finite deltas, as a float32 rounded up so no
// code exceeds 1; a target that moves nothing has scale 0 and codes 0, and a non-finite
// component encodes as 0.
float deltaScale(const std::vector<glm::vec4>& deltas);
glm::dvec3 scaledEncode(float scale, const glm::dvec3& delta);
glm::dvec3 scaledDecode(float scale, const glm::dvec3& code);

// QTangents (Frey and Herzog, "Spherical Skinning with Dual-Quaternions and QTangents",
// SIGGRAPH 2011): the tangent frame as the unit quaternion q = (x, y, z, w) of the rotation
// whose columns are (tangent, cross(normal, tangent), normal), so the decode is
// tangent = q (1, 0, 0) q*, normal = q (0, 0, 1) q*. q and -q are the same rotation: the
// encoder picks the one whose w has the sign of the handedness (world.binormal =
// handedness * cross(normal, tangent)), and keeps |w| >= bias so the sign survives the
// format's rounding (bias: the format's smallest positive non-zero value, qtangentBias).
// The encoder first orthonormalises as object.tangent does (docs/semantics.md): the normal
// normalised (a zero or non-finite one becomes +z); the tangent made perpendicular to it by
// Gram-Schmidt, and where that leaves nothing (a zero, non-finite or parallel tangent:
// |g|^2 <= 1e-6 |t|^2) the tangent of Duff et al.'s orthonormal basis of the normal.
// A handedness < 0 is -1, anything else (0, NaN) +1.
struct QTangentFrame {
  glm::dvec3 normal{0.0};
  glm::dvec3 tangent{0.0};
  double handedness = 1;
};
glm::dvec4 qtangentEncode(const glm::dvec3& normal, const glm::dvec3& tangent, double handedness, double bias);
// The frame of a stored code (normalised first, as the rule does; a zero code has none: NaN).
QTangentFrame qtangentDecode(const glm::dvec4& code);
// The smallest |w| the encoder keeps in format f: one step of a snorm format, the smallest
// normal value of a float one (a flushed subnormal or a negative zero would lose the sign).
double qtangentBias(VertexFormat f);

// The formats an encoding may be stored in, and its worst error there (in its unit), for
// any input. Octahedral, two components of snorm8 / snorm16 / float16 / float32 (x2, or two
// of x4, so a normal and a tangent share one location): a stored code is
// off by at most e per component (the format's rounding, vertex_format.h, plus the float32
// rounding of the code: 2^-24); on the octahedron's surface (on either side of a fold) that
// moves the point along a path of length <= sqrt(6) e, at least 1/sqrt(3) from the origin,
// so the direction turns by at most sqrt(18) e radians: snorm8 0.957 deg, snorm16 0.0037
// deg, float16 0.12 deg (the published maxima for 8 and 16 bits are 0.95 and 0.0037 deg).
// Bounds, three components of unorm8x4 / unorm10-10-10-2 / unorm16x4 / float16x4 /
// float32x3/x4: a code is off by at most e per component (half a step of the format, plus
// the float32 rounding of the code), so each coordinate by e of its axis's extent and the
// point by at most e of the box's diagonal: unorm8 2.0e-3, 10-bit 4.9e-4, unorm16 7.6e-6.
// (The decode's own float arithmetic, min + code * extent, rounds as any float transform of
// the position does, and is not counted.)
// QTangent, four components of snorm8x4 / snorm16x4 / float16x4 / float32x4: each stored
// component is off by at most e (as for octahedral codes; float16 codes lie in [-1, 1],
// where its steps are <= 2^-11, so e = 2^-12 + 2^-24). The read code q' is then within a
// distance c of the unit quaternion q of the frame, and its direction within asin(c) of q;
// the decode normalises it, and the two rotations differ by twice that angle, which bounds
// how far any vector they rotate (the normal, the tangent) turns: 2 asin(c). Where the
// encoder left w alone (|w| >= bias), c <= |(e, e, e, e)| = 2e. Where it raised |w| from
// w0 < bias to the bias b (the code's w then is b exactly: one step, or a float value),
// that moved q by (xyz (s - 1), b - w0) with |xyz (s - 1)| <= 1 - sqrt(1 - b^2) <= b^2, and
// the rounding only moves xyz: c <= sqrt((sqrt(3) e + b^2)^2 + b^2). The larger of the two:
// snorm8 1.20 deg, snorm16 0.0046 deg, float16 0.056 deg, float32 1.4e-5 deg. The
// handedness is exact (|w| >= b reads back with its sign).
// Scaled morph deltas, three components of snorm8x4 / snorm10-10-10-2 / snorm16x4 /
// float16x4 / float32x3/x4: a code off by e per component (half a step of the format, plus
// the code's float32 rounding; float16 as for QTangents) moves the delta by e of the
// target's scale per component, so by at most sqrt(3) e of it: snorm8 6.8e-3, 10-bit
// 1.7e-3, snorm16 2.65e-5, float16 4.2e-4 of the target's largest |component|.
// std::nullopt: the format cannot hold the encoding.
std::optional<double> encodingMaxError(const VertexEncoding& e, VertexFormat f);
// The formats it may be stored in, for messages: "snorm8x2, snorm8x4, ... (2 components)".
std::string encodingFormats(const VertexEncoding& e);

// The attribute that provides `semantic` (per-target streams excepted), or nullptr.
const RigAttribute* attributeProviding(const Rig& rig, const std::string& semantic);
// The rig without the parts that provide these semantics (an attribute left with no part
// goes too): how a stored form is taken out of the search's reach.
Rig withoutProvided(const Rig& rig, const std::set<std::string>& semantics);

// The encodings of a source semantic ("vertex.normal"), or none (exact ones not counted:
// no budget applies to them).
std::vector<const VertexEncoding*> encodingsOf(const std::string& sourceSemantic);

// Error budgets (--max-error): the worst error allowed per source semantic, in its
// encodings' unit (degrees for a direction, a fraction of the bounds diagonal for a
// position, of the target's scale for a morph delta). The rig without the encoded parts over
// budget (an attribute left with no part goes too), so the search is never offered them; one
// note per removal. A budget naming no encoding's source is an InputError, and so is one
// that removes a morph delta's only stored form (its targets would silently stop moving it).
Rig withinErrorBudgets(const Rig& rig, const std::map<std::string, double>& budgets, std::vector<Diagnostic>& notes);
// A budget as written after "SEMANTIC=": an angle with "deg" or "rad" for a direction, a
// plain fraction for a position ("1e-4", of the bounds diagonal) or a morph delta (of its
// target's scale); the value in the encodings' unit, or std::nullopt
// with `why` set (also when the semantic has no encoding).
std::optional<double> parseErrorBudget(const std::string& semantic, const std::string& text, std::string& why);

}  // namespace sg
