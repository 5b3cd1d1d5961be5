#version 450
// A depth-only pass: no varyings, so its vertex shaders compute the clip position only.
layout(location = 0) out vec4 COLOR;
void main() { COLOR = vec4(0.0); }
