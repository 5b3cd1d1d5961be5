#version 450
// A depth-only pass: the fragment shader reads no varyings, so the vertex shader only
// needs the clip position - no normals, tangents or view terms.
layout(location = 0) out vec4 COLOR;
void main() { COLOR = vec4(0.0); }
