// GLSL value types used by semantics, vertex inputs, uniforms and varyings.
#pragma once
#include <optional>
#include <string>
#include <string_view>

namespace sg {

enum class Type { Float, Vec2, Vec3, Vec4, Int, IVec4, UInt, UVec4, Mat3, Mat4, UVec2 };

enum class ScalarKind { Float, Int, UInt };

std::string_view glslName(Type t);
std::optional<Type> parseType(std::string_view name);
int componentCount(Type t);  // scalars/vectors: 1..4; mat3: 9; mat4: 16
ScalarKind scalarKind(Type t);
bool isMatrix(Type t);
// The vector type with n components of the given kind (n in 1..4), if any.
std::optional<Type> vectorType(ScalarKind kind, int n);

}  // namespace sg
