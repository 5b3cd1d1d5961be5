#version 450
// Dawn's face fragment shader (GPU Gems ch. 3, listing 3-4), ported from Cg to
// Vulkan GLSL 450. Its inputs are the v2fConnector of listing 3-2/3-3.
layout(location = 0) in vec3 WorldTanMatrixX;
layout(location = 1) in vec3 WorldTanMatrixY;
layout(location = 2) in vec3 WorldTanMatrixZ;
layout(location = 3) in vec3 WorldEyeDir;
layout(location = 4) in vec4 SkinUVST;
layout(location = 5) in vec4 SkinSilhouetteVec;

layout(set = 1, binding = 0) uniform sampler2D SkinColorFrontSpecMap;
layout(set = 1, binding = 1) uniform sampler2D SkinNormSideSpecMap;   // xyz normal map
layout(set = 1, binding = 2) uniform sampler2D SpecularColorShiftMap; // and spec map in "w"
layout(set = 1, binding = 3) uniform samplerCube DiffuseCubeMap;
layout(set = 1, binding = 4) uniform samplerCube SpecularCubeMap;
layout(set = 1, binding = 5) uniform samplerCube HilightCubeMap;

layout(location = 0) out vec4 COLOR;

void main() {
  vec4 normSideSpec = texture(SkinNormSideSpecMap, SkinUVST.xy);
  vec3 worldNormal;
  worldNormal.x = dot(normSideSpec.xyz, WorldTanMatrixX);
  worldNormal.y = dot(normSideSpec.xyz, WorldTanMatrixY);
  worldNormal.z = dot(normSideSpec.xyz, WorldTanMatrixZ);
  float nDotV = dot(WorldEyeDir, worldNormal);
  vec4 skinColor = texture(SkinColorFrontSpecMap, SkinUVST.xy);
  vec3 diffuse = skinColor.xyz * texture(DiffuseCubeMap, worldNormal).xyz;
  diffuse = diffuse * SkinSilhouetteVec.x;
  vec4 sideSpec = normSideSpec.w * texture(SpecularCubeMap, worldNormal);
  vec3 result = diffuse * SkinSilhouetteVec.y + sideSpec.xyz;
  vec3 hilite = 0.7 * SkinSilhouetteVec.x * SkinSilhouetteVec.y * texture(HilightCubeMap, WorldEyeDir).xyz;
  // The listing's "worldNormal * 2.0x" is the reflection vector's doubled term.
  vec3 reflVect = WorldEyeDir * nDotV - (worldNormal * 2.0);
  vec4 reflColor = SkinSilhouetteVec.w * texture(SpecularCubeMap, reflVect);
  result += (reflColor.xyz * 0.02);
  float hiLightAttenuator = texture(SpecularColorShiftMap, SkinUVST.xy).x;
  result += (hilite * hiLightAttenuator);
  float haze = reflColor.w * hiLightAttenuator;
  COLOR = vec4(result.xyz, haze);
}
