#version 450
// G-buffer pass: world normal and texture coordinates, by the semantic-name convention.
layout(location = 0) in vec3 world_normal;
layout(location = 1) in vec2 vertex_texcoord0;
layout(location = 0) out vec4 NORMAL;
layout(location = 1) out vec4 UV;
void main() {
  NORMAL = vec4(normalize(world_normal) * 0.5 + 0.5, 1.0);
  UV = vec4(vertex_texcoord0, 0.0, 1.0);
}
