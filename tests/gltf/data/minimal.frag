#version 450
// Minimal request for models with positions only (SimpleSkin, SimpleMorph): the clip
// position (always), the world position and the eye direction.
layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_eye_dir;
layout(location = 0) out vec4 color;
void main() {
  float fog = clamp(length(world_position) * 0.01, 0.0, 1.0);
  color = vec4(abs(world_eye_dir) * (1.0 - fog), 1.0);
}
