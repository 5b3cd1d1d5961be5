#version 450
layout(location = 0) in mat3 frame;
layout(location = 2) in vec3 object_normal;
layout(location = 0) out vec4 color;
void main() { color = vec4(frame[0] + object_normal, 1.0); }
