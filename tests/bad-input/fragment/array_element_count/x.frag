#version 450
layout(location = 0) in vec3 normals[3];
layout(location = 0) out vec4 color;
void main() { color = vec4(normals[0] + normals[2], 1.0); }
