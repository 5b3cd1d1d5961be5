#version 450
// Filament material varyings (shaders/src/varyings.glsl): the tangent's handedness in
// vertex_worldTangent.w, both UV sets in vertex_uv01.
layout(location = 0) in vec3 vertex_worldPosition;
layout(location = 1) in vec3 vertex_worldNormal;
layout(location = 2) in vec4 vertex_worldTangent;
layout(location = 3) in vec4 vertex_uv01;
layout(location = 0) out vec4 fragColor;
void main() {
  vec3 b = vertex_worldTangent.w * cross(vertex_worldNormal, vertex_worldTangent.xyz);
  fragColor = vec4(b + 0.001 * vertex_worldPosition, 1.0) + vertex_uv01;
}
