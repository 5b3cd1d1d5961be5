#version 450
// A MeshStandardMaterial-style fragment shader with a normal map (three.js's USE_TANGENT
// path) that keeps three.js's varying names
// (ShaderLib/meshphysical.glsl.js, ShaderChunk/normal_vertex, uv_vertex): the naming
// convention 'threejs' (rules/conventions.yaml) maps every input, so no --map is needed.
// Lighting is done in view space, as three.js does: the eye is at the origin.
layout(location = 0) in vec3 vViewPosition;  // -(modelViewMatrix * position).xyz
layout(location = 1) in vec3 vNormal;        // normalize(normalMatrix * objectNormal)
layout(location = 2) in vec3 vTangent;       // view space (USE_TANGENT)
layout(location = 3) in vec3 vBitangent;     // cross(vNormal, vTangent) * tangent.w
layout(location = 4) in vec2 vUv;
layout(location = 0) out vec4 outColor;

const vec3 kLightDir = normalize(vec3(0.4, 0.8, 0.6));  // view space, towards the light
const vec3 kBaseColor = vec3(0.8, 0.55, 0.45);
const float kRoughness = 0.45;

// A procedural normal "map": ripples along the tangent frame.
vec3 perturbedNormal(vec3 n, vec3 t, vec3 b, vec2 uv) {
  vec2 slope = 0.15 * vec2(cos(40.0 * uv.x), cos(40.0 * uv.y));
  return normalize(n + slope.x * t + slope.y * b);
}

void main() {
  vec3 n = perturbedNormal(normalize(vNormal), normalize(vTangent), normalize(vBitangent), vUv);
  vec3 v = normalize(vViewPosition);  // towards the eye
  n = faceforward(n, -v, n);          // both sides lit, whatever the winding convention
  vec3 h = normalize(kLightDir + v);
  float ndotl = max(dot(n, kLightDir), 0.0);
  float ndoth = max(dot(n, h), 0.0);
  float a2 = pow(kRoughness, 4.0);
  float d = ndoth * ndoth * (a2 - 1.0) + 1.0;
  float ggx = a2 / (3.14159265 * d * d);  // GGX distribution, as BRDF_GGX
  vec3 color = kBaseColor * (0.08 + ndotl) + vec3(0.04) * ggx * ndotl;
  outColor = vec4(pow(color, vec3(1.0 / 2.2)), 1.0);
}
