#version 450
// glTF Sample Viewer names (primitive.vert outputs): world position, world normal, the
// tangent frame as one mat3 (tangent, bitangent, normal columns) and texture coordinates.
layout(location = 0) in vec3 v_Position;
layout(location = 1) in vec3 v_Normal;
layout(location = 2) in mat3 v_TBN;
layout(location = 5) in vec2 v_texcoord_0;
layout(location = 6) in vec2 v_texcoord_1;
layout(location = 0) out vec4 g_finalColor;
void main() {
  vec3 n = normalize(v_TBN * vec3(0.0, 0.0, 1.0));
  g_finalColor = vec4(n + 0.001 * (v_Position + v_Normal), 1.0) + vec4(v_texcoord_0, v_texcoord_1);
}
