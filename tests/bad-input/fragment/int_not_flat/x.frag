#version 450
layout(location = 0) in uvec4 skin_joints;
layout(location = 0) out vec4 color;
void main() { color = vec4(skin_joints); }
