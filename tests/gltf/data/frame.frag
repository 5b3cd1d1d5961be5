#version 450
// Bump mapping in world space: the transposed tangent frame (Dawn's WorldTanMatrixX/Y/Z),
// the eye direction and the world position (AnimatedMorphSphere: normals and tangents,
// morphed, no UVs).
layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_eye_dir;
layout(location = 2) in vec3 world_normal;
layout(location = 3) in vec3 frame_row_x;
layout(location = 4) in vec3 frame_row_y;
layout(location = 5) in vec3 frame_row_z;
layout(set = 1, binding = 0) uniform samplerCube environment;
layout(location = 0) out vec4 color;
void main() {
  vec3 bump = vec3(0.1, 0.05, 1.0);  // a constant tangent-space normal
  vec3 n = normalize(vec3(dot(bump, frame_row_x), dot(bump, frame_row_y), dot(bump, frame_row_z)));
  vec3 r = reflect(world_eye_dir, n);
  float fog = clamp(length(world_position) * 0.01, 0.0, 1.0);
  color = texture(environment, r) * abs(dot(normalize(world_normal), world_eye_dir)) * (1.0 - fog);
}
