#version 450
// MeshStandardMaterial with flatShading: true, for models without normals: three.js's
// normal_fragment_begin (FLAT_SHADED) takes the face normal from the derivatives of
// vViewPosition, so the vertex stage writes no vNormal.
layout(location = 0) in vec3 vViewPosition;  // -(modelViewMatrix * position).xyz
layout(location = 1) in vec2 vUv;
layout(location = 0) out vec4 outColor;

const vec3 kLightDir = normalize(vec3(0.4, 0.8, 0.6));  // view space, towards the light

void main() {
  vec3 v = normalize(vViewPosition);
  // The sign of the cross product follows the window's y direction (up in GL, down in
  // Vulkan): turn the normal towards the eye.
  vec3 n = normalize(cross(dFdx(vViewPosition), dFdy(vViewPosition)));
  n = faceforward(n, -v, n);
  vec3 base = mix(vec3(0.8, 0.55, 0.45), vec3(0.35, 0.4, 0.6), step(0.5, fract(8.0 * vUv.x)));
  float ndotl = max(dot(n, kLightDir), 0.0);
  float spec = pow(max(dot(n, normalize(kLightDir + v)), 0.0), 32.0);
  outColor = vec4(pow(base * (0.08 + ndotl) + vec3(0.04) * spec, vec3(1.0 / 2.2)), 1.0);
}
