#version 450
// Eye-space pass with the dapple term (Dawn's skin detail).
layout(location = 0) in vec4 eye_position;
layout(location = 1) in vec3 eye_normal;
layout(location = 2) in float dapple_normal_z;
layout(location = 0) out vec4 color;
void main() { color = vec4(eye_normal * dapple_normal_z, eye_position.z); }
