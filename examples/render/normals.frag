#version 450
// The plain shading of `shadergen render` for any rig: the world-space normal as colour
// (x, y, z mapped from [-1, 1] to [0, 1]). Needs only world.normal from the vertex shader.
layout(location = 0) in vec3 world_normal;
layout(location = 0) out vec4 COLOR;
void main() { COLOR = vec4(normalize(world_normal) * 0.5 + 0.5, 1.0); }
