#version 450
layout(location = 0) in vec3 u_view_proj;
layout(location = 0) out vec4 color;
void main() { color = vec4(u_view_proj, 1.0); }
