#version 450
// Ambient term darkened by baked occlusion: needs object.occlusion (vertex.occlusion +
// the morph targets' occlusion deltas) and the world normal.
layout(location = 0) in float occlusion;
layout(location = 1) in vec3 world_normal;
layout(set = 1, binding = 0) uniform samplerCube irradiance;
layout(location = 0) out vec4 color;
void main() {
  color = texture(irradiance, normalize(world_normal)) * (1.0 - occlusion);
}
