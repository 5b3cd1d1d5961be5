#version 450
// Test fragment shader: inputs named after the semantics they want (world_eye_dir ->
// world.eye_dir), bound by the name convention over rules/standard.yaml.
layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 2) in vec3 world_tangent;
layout(location = 3) in vec3 world_binormal;
layout(location = 4) in vec3 world_eye_dir;
layout(location = 5) in float view_ndotv;
layout(location = 6) in float view_one_minus_ndotv_sq;
layout(location = 7) in vec2 vertex_texcoord0;

layout(location = 0) out vec4 color;

void main() {
  float rim = view_one_minus_ndotv_sq;
  vec3 n = normalize(world_normal + 0.1 * (world_tangent + world_binormal));
  color = vec4(n * view_ndotv + rim * world_eye_dir + 0.01 * world_position, vertex_texcoord0.x);
}
