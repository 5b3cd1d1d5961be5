#version 450
// A random request of the calibration corpus, seed 794921487.
layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 WorldEyeDir;
layout(location = 2) in vec3 world_normal;
layout(location = 3) in vec4 SkinUVST;
layout(location = 0) out vec4 color;
void main() {
  vec4 c = vec4(0.0);
  c.xyz += world_position;
  c.xyz += WorldEyeDir;
  c.xyz += world_normal;
  c += SkinUVST;
  color = c;
}
