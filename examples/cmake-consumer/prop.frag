#version 450
// A minimal lit fragment shader for the prop: needs the world normal and one UV set.
layout(location = 0) in vec3 WorldNormal;
layout(location = 1) in vec2 UV;
layout(set = 1, binding = 0) uniform sampler2D Albedo;
layout(location = 0) out vec4 color;
void main() {
  float light = max(dot(normalize(WorldNormal), normalize(vec3(0.3, 1.0, 0.5))), 0.0);
  color = texture(Albedo, UV) * (0.2 + 0.8 * light);
}
