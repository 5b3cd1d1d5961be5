#version 450
// Vertex colours and UVs on top of position and eye direction (synthetic skinned + morphing
// model with normalized colour/weight formats).
layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_eye_dir;
layout(location = 2) in vec2 vertex_texcoord0;
layout(location = 3) in vec4 vertex_color0;
layout(set = 1, binding = 0) uniform sampler2D albedo;
layout(location = 0) out vec4 color;
void main() {
  float fog = clamp(length(world_position) * 0.01, 0.0, 1.0);
  color = texture(albedo, vertex_texcoord0) * vertex_color0 * (1.0 - fog) + vec4(abs(world_eye_dir), 0.0) * fog;
}
