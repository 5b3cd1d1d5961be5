#version 450
layout(location = 0) in vec3 a_position;
layout(location = 0) out vec4 color;
void main() { color = vec4(a_position, 1.0); }
