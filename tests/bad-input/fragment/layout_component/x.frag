#version 450
layout(location = 0) in vec3 object_normal;
layout(location = 0, component = 3) in float vertex_occlusion;
layout(location = 0) out vec4 color;
void main() { color = vec4(object_normal, vertex_occlusion); }
