#version 450
// A small valid fragment shader for the corpus.
layout(location = 0) in vec3 object_normal;
layout(location = 0) out vec4 color;
void main() { color = vec4(object_normal, 1.0); }
