#version 450
layout(location = 0) in vec3 bogus;
layout(location = 0) out vec4 color;
void main() { color = vec4(bogus, 1.0); }
