#version 450
// Test fragment shader: 16 vec4 inputs, 64 components, the most every Vulkan device's
// maxVertexOutputComponents allows. Each is mapped to a vec4 semantic by the test
// (VaryingOverride, as --map e<i>=eye.position); validation captures them and gl_Position.
layout(location = 0) in vec4 e0;
layout(location = 1) in vec4 e1;
layout(location = 2) in vec4 e2;
layout(location = 3) in vec4 e3;
layout(location = 4) in vec4 e4;
layout(location = 5) in vec4 e5;
layout(location = 6) in vec4 e6;
layout(location = 7) in vec4 e7;
layout(location = 8) in vec4 e8;
layout(location = 9) in vec4 e9;
layout(location = 10) in vec4 e10;
layout(location = 11) in vec4 e11;
layout(location = 12) in vec4 e12;
layout(location = 13) in vec4 e13;
layout(location = 14) in vec4 e14;
layout(location = 15) in vec4 e15;

layout(location = 0) out vec4 color;

void main() {
  color = e0 + e1 + e2 + e3 + e4 + e5 + e6 + e7 + e8 + e9 + e10 + e11 + e12 + e13 + e14 + e15;
}
