#version 450
// Lit, two UV sets (MorphStressTest: base colour + a second set for a detail map).
layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_eye_dir;
layout(location = 2) in vec3 world_normal;
layout(location = 3) in vec2 vertex_texcoord0;
layout(location = 4) in vec2 vertex_texcoord1;
layout(set = 1, binding = 0) uniform sampler2D albedo;
layout(set = 1, binding = 1) uniform sampler2D detail;
layout(location = 0) out vec4 color;
void main() {
  vec3 n = normalize(world_normal);
  float ndotv = abs(dot(n, world_eye_dir));
  float fog = clamp(length(world_position) * 0.01, 0.0, 1.0);
  color = texture(albedo, vertex_texcoord0) * texture(detail, vertex_texcoord1) * ndotv * (1.0 - fog);
}
