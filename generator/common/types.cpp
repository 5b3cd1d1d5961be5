#include "common/types.h"

#include <array>

namespace sg {
namespace {
struct TypeInfo {
  Type type;
  std::string_view name;
  int components;
  ScalarKind kind;
};
constexpr std::array<TypeInfo, 11> kTypes{{
    {Type::Float, "float", 1, ScalarKind::Float},
    {Type::Vec2, "vec2", 2, ScalarKind::Float},
    {Type::Vec3, "vec3", 3, ScalarKind::Float},
    {Type::Vec4, "vec4", 4, ScalarKind::Float},
    {Type::Int, "int", 1, ScalarKind::Int},
    {Type::IVec4, "ivec4", 4, ScalarKind::Int},
    {Type::UInt, "uint", 1, ScalarKind::UInt},
    {Type::UVec4, "uvec4", 4, ScalarKind::UInt},
    {Type::Mat3, "mat3", 9, ScalarKind::Float},
    {Type::Mat4, "mat4", 16, ScalarKind::Float},
    {Type::UVec2, "uvec2", 2, ScalarKind::UInt},  // a uint32x2, uint8x2 or uint16x2 attribute
}};
const TypeInfo& info(Type t) { return kTypes[static_cast<size_t>(t)]; }
}  // namespace

std::string_view glslName(Type t) { return info(t).name; }
int componentCount(Type t) { return info(t).components; }
ScalarKind scalarKind(Type t) { return info(t).kind; }
bool isMatrix(Type t) { return t == Type::Mat3 || t == Type::Mat4; }

std::optional<Type> parseType(std::string_view name) {
  for (const auto& i : kTypes)
    if (i.name == name) return i.type;
  return std::nullopt;
}

std::optional<Type> vectorType(ScalarKind kind, int n) {
  for (const auto& i : kTypes)
    if (i.kind == kind && i.components == n && !isMatrix(i.type)) return i.type;
  return std::nullopt;
}

}  // namespace sg
