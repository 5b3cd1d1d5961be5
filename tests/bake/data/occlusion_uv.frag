#version 450
// Skinned model without normals (the Fox, its normals derived from faces by the baker):
// albedo darkened by the baked occlusion.
layout(location = 0) in float occlusion;
layout(location = 1) in vec2 vertex_texcoord0;
layout(set = 1, binding = 0) uniform sampler2D albedo;
layout(location = 0) out vec4 color;
void main() {
  color = texture(albedo, vertex_texcoord0) * (1.0 - occlusion);
}
