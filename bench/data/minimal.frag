#version 450
// Baseline for bench_validate: no inputs, so the vertex shader only computes gl_Position.
layout(location = 0) out vec4 color;
void main() { color = vec4(1.0); }
