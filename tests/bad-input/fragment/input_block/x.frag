#version 450
layout(location = 0) in Block { vec3 object_normal; } blk;
layout(location = 0) out vec4 color;
void main() { color = vec4(blk.object_normal, 1.0); }
