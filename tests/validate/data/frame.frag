#version 450
// Test fragment shader: the world-space tangent frame, inputs named after their semantics.
layout(location = 0) in vec3 world_normal;
layout(location = 1) in vec3 world_tangent;
layout(location = 2) in vec3 world_binormal;
layout(location = 0) out vec4 color;
void main() { color = vec4(world_normal + world_tangent + world_binormal, 1.0); }
