#version 450
// A random request of the calibration corpus, seed 1562238070.
layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 2) in vec3 WorldTanMatrixX;
layout(location = 3) in vec3 WorldTanMatrixY;
layout(location = 4) in vec3 WorldTanMatrixZ;
layout(location = 0) out vec4 color;
void main() {
  vec4 c = vec4(0.0);
  c.xyz += world_position;
  c.xyz += world_normal;
  c.xyz += WorldTanMatrixX;
  c.xyz += WorldTanMatrixY;
  c.xyz += WorldTanMatrixZ;
  color = c;
}
