#version 450
// in vec3 object_normal; (a comment, not the declaration)
layout(location = 0)
  in vec3 a_bad;
layout(location = 0) out vec4 color;
void main() { color = vec4(a_bad, 1.0); }
