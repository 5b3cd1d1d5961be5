// The textures of listing 3-4 (Dawn's face fragment shader), made procedurally because the
// demo's art is not redistributable. docs/render.md describes each one. All are functions
// of a few parameters, so tests can move the light and check the image follows.
#pragma once
#include <glm/glm.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "runtime/vk_render.h"

namespace sg {

struct DawnLighting {
  glm::vec3 keyDirection{0.5f, 0.6f, 0.8f};   // towards the key light (world space), normalised on use
  glm::vec3 keyColor{3.2f, 2.9f, 2.6f};      // HDR: above 1 where the light is
  glm::vec3 rimDirection{-0.6f, 0.3f, -0.7f}; // the hilight cube's back/rim light
  glm::vec3 ambient{0.35f, 0.36f, 0.42f};
  uint32_t textureSize = 1024;  // 2D maps (size x size); fine enough that a close-up does not magnify them
  uint32_t cubeSize = 64;      // each cube face: 1.4-degree texels, small beside the cos^24 lobe (~14 degrees)
};

// One texture per sampler of listing 3-4, by the sampler's name:
// SkinColorFrontSpecMap, SkinNormSideSpecMap, SpecularColorShiftMap (2D) and
// DiffuseCubeMap, SpecularCubeMap, HilightCubeMap (cube). Binding is left 0 (the caller
// assigns it from the shader). Returns false if `sampler` is none of these.
bool dawnTexture(const std::string& sampler, bool cube, const DawnLighting& light, rt::Texture& out);

// The sampler names dawnTexture knows, in the listing's order.
const std::vector<std::string>& dawnSamplerNames();

// Unit direction of the centre of texel (x, y) of cube face `face` (Vulkan order +X, -X,
// +Y, -Y, +Z, -Z; Vulkan spec, "Cube Map Face Selection").
glm::vec3 cubeTexelDirection(int face, uint32_t x, uint32_t y, uint32_t size);

}  // namespace sg
