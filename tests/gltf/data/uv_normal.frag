#version 450
// Asks for the world normal: models without NORMAL (the Fox) must get a diagnostic
// naming vertex.normal.
layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_eye_dir;
layout(location = 2) in vec2 vertex_texcoord0;
layout(location = 3) in vec3 world_normal;
layout(set = 1, binding = 0) uniform sampler2D albedo;
layout(location = 0) out vec4 color;
void main() {
  float ndotv = abs(dot(normalize(world_normal), world_eye_dir));
  float fog = clamp(length(world_position) * 0.001, 0.0, 1.0);
  color = texture(albedo, vertex_texcoord0) * ndotv * (1.0 - fog);
}
