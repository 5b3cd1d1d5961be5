#version 450
// Test fragment shader for rigs without view or dapple uniforms: world-space inputs only.
layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 2) in vec3 world_eye_dir;
layout(location = 3) in vec3 frame_row_z;
layout(location = 4) in float view_one_minus_ndotv;

layout(location = 0) out vec4 color;

void main() {
  color = vec4(world_normal * view_one_minus_ndotv + world_eye_dir + frame_row_z + 0.01 * world_position, 1.0);
}
