#version 450
// A faithful hand port of listing 3-3 (Dawn's face vertex shader, GPU Gems ch. 3) from Cg
// to Vulkan GLSL 450, with the same interface as the shader shadergen generates for
// face.rig.yaml + face.frag, so the two can be compared instruction for instruction
// (bench/compare_plans.sh). Cg's mul(M, v) is M * v here; vecMul(M, v) is mat3(M) * v.
layout(location = 0) in vec3 a_coord;
layout(location = 1) in vec4 a_normal;
layout(location = 2) in vec4 a_tangent;
layout(location = 3) in vec3 a_coord_morph0;
layout(location = 4) in vec3 a_coord_morph1;
layout(location = 5) in vec3 a_coord_morph2;
layout(location = 6) in vec3 a_coord_morph3;
layout(location = 7) in vec3 a_coord_morph4;
layout(location = 8) in vec4 a_normal_morph0;
layout(location = 9) in vec4 a_normal_morph1;
layout(location = 10) in vec4 a_normal_morph2;
layout(location = 11) in vec4 a_normal_morph3;
layout(location = 12) in vec4 a_normal_morph4;
layout(location = 13) in vec4 a_bone_weight;
layout(location = 14) in uvec4 a_bone_index;
layout(location = 15) in vec4 a_skin_uvst;

layout(set = 0, binding = 0, std140) uniform ShadergenUniforms {
  mat4 u_bone_xf[98];
  float u_morph_weight[5];
  vec3 u_global_cam_pos;
  mat4 u_view_xf;
  mat4 u_proj_xf;
  mat4 u_dapple_xf;
};

layout(location = 0) out vec3 WorldTanMatrixX;
layout(location = 1) out vec3 WorldTanMatrixY;
layout(location = 2) out vec3 WorldTanMatrixZ;
layout(location = 3) out vec3 WorldEyeDir;
layout(location = 4) out vec4 SkinUVST;
layout(location = 5) out vec4 SkinSilhouetteVec;

vec3 vecMul(mat4 m, vec3 v) { return mat3(m) * v; }

void main() {
  // Shape blending between the five morph targets.
  vec4 objectCoord = vec4(a_coord, 1.0);
  objectCoord.xyz += u_morph_weight[0] * a_coord_morph0;
  objectCoord.xyz += u_morph_weight[1] * a_coord_morph1;
  objectCoord.xyz += u_morph_weight[2] * a_coord_morph2;
  objectCoord.xyz += u_morph_weight[3] * a_coord_morph3;
  objectCoord.xyz += u_morph_weight[4] * a_coord_morph4;
  // Transform the head by the bones.
  vec4 worldCoord = a_bone_weight.x * (u_bone_xf[a_bone_index.x] * objectCoord);
  worldCoord += a_bone_weight.y * (u_bone_xf[a_bone_index.y] * objectCoord);
  worldCoord += a_bone_weight.z * (u_bone_xf[a_bone_index.z] * objectCoord);
  worldCoord += a_bone_weight.w * (u_bone_xf[a_bone_index.w] * objectCoord);
  // Repeat on the surface normal.
  vec4 objectNormal = a_normal;
  objectNormal += u_morph_weight[0] * a_normal_morph0;
  objectNormal += u_morph_weight[1] * a_normal_morph1;
  objectNormal += u_morph_weight[2] * a_normal_morph2;
  objectNormal += u_morph_weight[3] * a_normal_morph3;
  objectNormal += u_morph_weight[4] * a_normal_morph4;
  objectNormal.xyz = normalize(objectNormal.xyz);
  vec3 worldNormal = a_bone_weight.x * vecMul(u_bone_xf[a_bone_index.x], objectNormal.xyz);
  worldNormal += a_bone_weight.y * vecMul(u_bone_xf[a_bone_index.y], objectNormal.xyz);
  worldNormal += a_bone_weight.z * vecMul(u_bone_xf[a_bone_index.z], objectNormal.xyz);
  worldNormal += a_bone_weight.w * vecMul(u_bone_xf[a_bone_index.w], objectNormal.xyz);
  worldNormal = normalize(worldNormal);
  // The orthonormalized surface tangent.
  vec4 objectTangent = a_tangent;
  objectTangent.xyz = normalize(objectTangent.xyz - dot(objectTangent.xyz, objectNormal.xyz) * objectNormal.xyz);
  vec4 worldTangent;
  worldTangent.xyz = a_bone_weight.x * vecMul(u_bone_xf[a_bone_index.x], objectTangent.xyz);
  worldTangent.xyz += a_bone_weight.y * vecMul(u_bone_xf[a_bone_index.y], objectTangent.xyz);
  worldTangent.xyz += a_bone_weight.z * vecMul(u_bone_xf[a_bone_index.z], objectTangent.xyz);
  worldTangent.xyz += a_bone_weight.w * vecMul(u_bone_xf[a_bone_index.w], objectTangent.xyz);
  worldTangent.xyz = normalize(worldTangent.xyz);
  worldTangent.w = objectTangent.w;
  // Binormal from the cross product.
  vec3 worldBinormal = worldTangent.w * normalize(cross(worldNormal, worldTangent.xyz));
  // The transposed tangent frame.
  WorldTanMatrixX = vec3(worldTangent.x, worldBinormal.x, worldNormal.x);
  WorldTanMatrixY = vec3(worldTangent.y, worldBinormal.y, worldNormal.y);
  WorldTanMatrixZ = vec3(worldTangent.z, worldBinormal.z, worldNormal.z);
  // Lighting values.
  vec4 worldEyePos = vec4(u_global_cam_pos, 1.0);
  WorldEyeDir = normalize(worldCoord.xyz - worldEyePos.xyz);
  vec4 eyespaceEyePos = vec4(0.0, 0.0, 0.0, 1.0);
  vec4 eyespaceCoord = u_view_xf * worldCoord;
  vec3 eyespaceEyeVec = normalize(eyespaceEyePos.xyz - eyespaceCoord.xyz);
  vec3 eyespaceNormal = vecMul(u_view_xf, worldNormal);
  float VdotN = abs(dot(eyespaceEyeVec, eyespaceNormal));
  float oneMinusVdotN = 1.0 - VdotN;
  SkinUVST = a_skin_uvst;
  SkinSilhouetteVec = vec4(objectNormal.w, oneMinusVdotN * oneMinusVdotN, oneMinusVdotN,
                           vecMul(u_dapple_xf, worldNormal.xyz).z);
  gl_Position = u_proj_xf * eyespaceCoord;
}
