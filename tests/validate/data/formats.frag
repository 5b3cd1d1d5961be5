#version 450
// Test fragment shader: world.frag's frame plus the raw attributes of every format of
// formats_*.rig.yaml (inputs named after their semantics).
layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 2) in vec3 world_tangent;
layout(location = 3) in vec3 world_binormal;
layout(location = 4) in vec2 vertex_texcoord0;
layout(location = 5) in vec2 vertex_texcoord1;
layout(location = 6) in vec4 vertex_color0;

layout(location = 0) out vec4 color;

void main() {
  vec3 n = normalize(world_normal + 0.1 * (world_tangent + world_binormal));
  color = vec4(n + 0.01 * world_position, vertex_texcoord0.x + vertex_texcoord1.y) * vertex_color0;
}
