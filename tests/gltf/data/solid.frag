#version 450
// One flat colour, never the render's background: coverage tests compare pictures pixel by
// pixel (RecursiveSkeletons: positions only).
layout(location = 0) in vec3 world_position;
layout(location = 0) out vec4 color;
void main() { color = vec4(1.0, 0.5, 0.25 + 0.0 * world_position.x, 1.0); }
