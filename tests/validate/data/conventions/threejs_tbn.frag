#version 450
// three.js's view-space frame (normal_vertex with USE_TANGENT, meshphysical's
// vViewPosition) without UVs: for models that have tangents but no texture coordinates.
layout(location = 0) in vec3 vViewPosition;
layout(location = 1) in vec3 vNormal;
layout(location = 2) in vec3 vTangent;
layout(location = 3) in vec3 vBitangent;
layout(location = 0) out vec4 outColor;
void main() {
  mat3 tbn = mat3(normalize(vTangent), normalize(vBitangent), normalize(vNormal));
  outColor = vec4(tbn * vec3(0.1, 0.2, 0.97) * 0.5 + 0.5 + 0.001 * vViewPosition, 1.0);
}
