#version 450
// Skinned model with UVs but no normals (the Fox): position, eye direction and UVs.
layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_eye_dir;
layout(location = 2) in vec2 vertex_texcoord0;
layout(set = 1, binding = 0) uniform sampler2D albedo;
layout(location = 0) out vec4 color;
void main() {
  float fog = clamp(length(world_position) * 0.001, 0.0, 1.0);
  color = texture(albedo, vertex_texcoord0) * (1.0 - fog) + vec4(abs(world_eye_dir), 0.0) * fog;
}
