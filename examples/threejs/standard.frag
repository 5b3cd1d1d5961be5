#version 450
// A MeshStandardMaterial-style fragment shader that keeps three.js's varying names
// (ShaderLib/meshphysical.glsl.js, ShaderChunk/normal_vertex, uv_vertex): the naming
// convention 'threejs' (rules/conventions.yaml) maps every input, so no --map is needed.
// Lighting is done in view space, as three.js does: the eye is at the origin.
layout(location = 0) in vec3 vViewPosition;  // -(modelViewMatrix * position).xyz
layout(location = 1) in vec3 vNormal;        // normalize(normalMatrix * objectNormal)
layout(location = 2) in vec2 vUv;
layout(location = 0) out vec4 outColor;

const vec3 kLightDir = normalize(vec3(0.4, 0.8, 0.6));  // view space, towards the light
const float kRoughness = 0.45;

void main() {
  vec3 n = normalize(vNormal);
  vec3 base = mix(vec3(0.8, 0.55, 0.45), vec3(0.35, 0.4, 0.6), step(0.5, fract(8.0 * vUv.x)));  // a checker "map"
  vec3 v = normalize(vViewPosition);  // towards the eye
  n = faceforward(n, -v, n);          // both sides lit, whatever the winding convention
  vec3 h = normalize(kLightDir + v);
  float ndotl = max(dot(n, kLightDir), 0.0);
  float ndoth = max(dot(n, h), 0.0);
  float a2 = pow(kRoughness, 4.0);
  float d = ndoth * ndoth * (a2 - 1.0) + 1.0;
  float ggx = a2 / (3.14159265 * d * d);  // GGX distribution, as BRDF_GGX
  vec3 color = base * (0.08 + ndotl) + vec3(0.04) * ggx * ndotl;
  outColor = vec4(pow(color, vec3(1.0 / 2.2)), 1.0);
}
