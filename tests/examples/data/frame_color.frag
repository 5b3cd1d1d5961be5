#version 450
// Asks for the tangent frame rows and a pass-through colour (names map to semantics).
layout(location = 0) in vec3 frame_row_x;
layout(location = 1) in vec3 frame_row_y;
layout(location = 2) in vec3 frame_row_z;
layout(location = 3) in vec4 vertex_color0;
layout(location = 4) in vec3 world_eye_dir;
layout(location = 0) out vec4 color;
void main() { color = vertex_color0 * vec4(frame_row_x + frame_row_y + frame_row_z + world_eye_dir, 1.0); }
