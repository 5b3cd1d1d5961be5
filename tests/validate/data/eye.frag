#version 450
// Test fragment shader: eye-space and dapple inputs by the name convention.
layout(location = 0) in vec4 eye_position;
layout(location = 1) in vec3 eye_normal;
layout(location = 2) in vec3 object_position;
layout(location = 3) in vec3 world_normal;
layout(location = 4) in float dapple_normal_z;
layout(location = 5) in vec3 frame_row_x;
layout(location = 6) in vec3 frame_row_y;
layout(location = 7) in vec3 frame_row_z;

layout(location = 0) out vec4 color;

void main() {
  vec3 n = vec3(dot(frame_row_x, eye_normal), dot(frame_row_y, eye_normal), dot(frame_row_z, eye_normal));
  color = vec4(n + 0.01 * object_position + world_normal * dapple_normal_z, eye_position.z);
}
