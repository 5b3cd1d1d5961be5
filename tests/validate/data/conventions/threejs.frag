#version 450
// A MeshStandardMaterial-style fragment shader with three.js varying names
// (ShaderChunk normal_vertex / uv_vertex / worldpos_vertex): no --map needed.
layout(location = 0) in vec3 vNormal;        // view space
layout(location = 1) in vec3 vWorldPosition;
layout(location = 2) in vec2 vUv;
layout(location = 3) in vec2 vUv1;
layout(location = 0) out vec4 outColor;
void main() {
  vec3 n = normalize(vNormal);
  outColor = vec4(n * 0.5 + 0.5 + 0.001 * vWorldPosition, 1.0) + vec4(vUv, vUv1);
}
