#version 450
layout(location = 0) in vec3 ShadergenUniforms;
layout(location = 0) out vec4 color;
void main() { color = vec4(ShadergenUniforms, 1.0); }
