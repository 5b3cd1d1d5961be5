#version 450
// A forward-lit pass: world-space frame, eye direction and N.V terms.
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
  vec3 n = normalize(world_normal + 0.1 * (world_tangent + world_binormal));
  color = vec4(n * view_ndotv + view_one_minus_ndotv_sq * world_eye_dir + 0.01 * world_position, vertex_texcoord0.x);
}
