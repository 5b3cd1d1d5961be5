#version 450
// Lit, untextured: position, eye direction and world normal (models with normals but no
// UVs, e.g. RobotExpressive).
layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_eye_dir;
layout(location = 2) in vec3 world_normal;
layout(location = 0) out vec4 color;
void main() {
  vec3 n = normalize(world_normal);
  float ndotv = abs(dot(n, world_eye_dir));
  color = vec4(vec3(0.2 + 0.8 * ndotv), 1.0);
}
