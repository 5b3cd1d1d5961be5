#version 450
layout(location = 0) in vec3 world_position;
layout(location = 0) out vec4 c;
void main() { c = vec4(world_position, 1.0); }
