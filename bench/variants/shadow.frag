#version 450
// Shadow-map pass: like the depth pass it reads no varyings (its vertex shader is the
// depth pass's, byte for byte: the build keeps that SPIR-V once).
layout(location = 0) out float DEPTH;
void main() { DEPTH = gl_FragCoord.z; }
