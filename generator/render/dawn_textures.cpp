#include "render/dawn_textures.h"

#include <glm/gtc/packing.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <mutex>
#include <utility>

namespace sg {
namespace {

constexpr float kTwoPi = 6.28318530718f;

// Deterministic value noise: a hash of the lattice point, smoothly interpolated. Written
// here (not std::hash or rand) so every platform makes the same texels.
float hash(int x, int y, int seed) {
  uint32_t h = static_cast<uint32_t>(x) * 374761393u + static_cast<uint32_t>(y) * 668265263u +
               static_cast<uint32_t>(seed) * 2246822519u;
  h = (h ^ (h >> 13)) * 1274126177u;
  h ^= h >> 16;
  return static_cast<float>(h & 0xFFFFFFu) / static_cast<float>(0xFFFFFF);
}

// Tileable in u (the head's longitude wraps): the lattice repeats every `period` cells.
float valueNoise(float u, float v, int period, int seed) {
  float x = u * static_cast<float>(period), y = v * static_cast<float>(period);
  int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  float fx = x - static_cast<float>(x0), fy = y - static_cast<float>(y0);
  auto s = [](float t) { return t * t * (3.0f - 2.0f * t); };
  auto at = [&](int i, int j) { return hash(((i % period) + period) % period, j, seed); };
  float a = at(x0, y0), b = at(x0 + 1, y0), c = at(x0, y0 + 1), d = at(x0 + 1, y0 + 1);
  return glm::mix(glm::mix(a, b, s(fx)), glm::mix(c, d, s(fx)), s(fy));
}

uint8_t unorm8(float x) { return static_cast<uint8_t>(std::lround(std::clamp(x, 0.0f, 1.0f) * 255.0f)); }

void putRgba8(std::vector<uint8_t>& data, const glm::vec4& c) {
  for (int i = 0; i < 4; ++i) data.push_back(unorm8(c[i]));
}
void putHalf4(std::vector<uint8_t>& data, const glm::vec4& c) {
  for (int i = 0; i < 4; ++i) {
    uint16_t h = glm::packHalf1x16(c[i]);
    data.push_back(static_cast<uint8_t>(h & 0xFF));
    data.push_back(static_cast<uint8_t>(h >> 8));
  }
}

// Skin albedo (rgb) and front specular (a): a warm base tone, low-frequency blotches, a
// flush on the cheeks (u = 0.15 and 0.35 around the front at u = 0.25), redder lips below
// the middle, and specular highest on the forehead/nose ("T-zone").
glm::vec4 skinColor(float u, float v) {
  glm::vec3 base(0.80f, 0.58f, 0.47f);
  float blotch = valueNoise(u, v, 24, 1) * 0.6f + valueNoise(u, v, 96, 2) * 0.4f;
  glm::vec3 c = base * (0.88f + 0.24f * blotch);
  auto bump = [](float du, float dv, float r) { return std::exp(-(du * du + dv * dv) / (r * r)); };
  float cheeks = bump(u - 0.17f, v - 0.55f, 0.06f) + bump(u - 0.33f, v - 0.55f, 0.06f);
  float lips = bump((u - 0.25f) * 0.6f, v - 0.68f, 0.025f);
  c = glm::mix(c, glm::vec3(0.85f, 0.42f, 0.38f), std::clamp(0.5f * cheeks + 0.8f * lips, 0.0f, 1.0f));
  float tzone = bump((u - 0.25f) * 2.0f, v - 0.4f, 0.2f);
  return glm::vec4(c, 0.35f + 0.45f * tzone);
}

// Tangent-space normal (signed xyz, the listing reads it without unpacking) with pores and
// fine wrinkles as height-field slopes, and side specular in w.
glm::vec4 normalSideSpec(float u, float v) {
  const float e = 1.0f / 512.0f;
  auto height = [](float a, float b) {
    return 0.6f * valueNoise(a, b, 128, 3) + 0.4f * valueNoise(a, b, 48, 4) + 0.03f * std::sin(kTwoPi * 40.0f * b);
  };
  float dx = (height(u + e, v) - height(u - e, v)) / (2.0f * e);
  float dy = (height(u, v + e) - height(u, v - e)) / (2.0f * e);
  glm::vec3 n = glm::normalize(glm::vec3(-0.0006f * dx, -0.0006f * dy, 1.0f));
  return glm::vec4(n, 0.25f + 0.2f * valueNoise(u, v, 16, 5));
}

// Hilight attenuation in x (the listing's "specular colour shift" map): oily areas shine.
glm::vec4 specularShift(float u, float v) {
  float a = 0.4f + 0.5f * valueNoise(u, v, 12, 6);
  return glm::vec4(a, a, a, 1.0f);
}

glm::vec3 unit(const glm::vec3& v) { return glm::normalize(v); }

// HDR environment lookups by direction d. Diffuse: the key light's cosine lobe (an
// irradiance map) plus a sky/ground ambient. Specular: a tight lobe around the key light and
// a dim environment; w is the "haze" the listing writes to alpha. Hilight: a rim light.
glm::vec4 diffuseEnv(const glm::vec3& d, const DawnLighting& l) {
  float key = std::max(0.0f, glm::dot(d, unit(l.keyDirection)));
  float sky = 0.5f + 0.5f * d.y;
  return glm::vec4(l.ambient * (0.6f + 0.8f * sky) + l.keyColor * key, 1.0f);
}
glm::vec4 specularEnv(const glm::vec3& d, const DawnLighting& l) {
  float cosKey = std::max(0.0f, glm::dot(d, unit(l.keyDirection)));
  float key = std::pow(cosKey, 24.0f), sheen = cosKey * cosKey * cosKey;
  float sky = 0.5f + 0.5f * d.y;
  // The broad lobe is warm: light that skin scatters back is reddened (section 3.2's look).
  glm::vec3 warm(1.0f, 0.74f, 0.62f);
  return glm::vec4(l.ambient * 0.6f * sky + l.keyColor * (0.9f * sheen * warm + 1.5f * key), 0.2f + 0.6f * key);
}
glm::vec4 hilightEnv(const glm::vec3& d, const DawnLighting& l) {
  float rim = std::pow(std::max(0.0f, glm::dot(d, unit(l.rimDirection))), 4.0f);
  return glm::vec4(glm::vec3(0.7f, 0.8f, 1.0f) * 1.5f * rim, 1.0f);
}

}  // namespace

glm::vec3 cubeTexelDirection(int face, uint32_t x, uint32_t y, uint32_t size) {
  float u = 2.0f * (static_cast<float>(x) + 0.5f) / static_cast<float>(size) - 1.0f;
  float v = 2.0f * (static_cast<float>(y) + 0.5f) / static_cast<float>(size) - 1.0f;
  glm::vec3 d;
  switch (face) {
    case 0: d = {1.0f, -v, -u}; break;
    case 1: d = {-1.0f, -v, u}; break;
    case 2: d = {u, 1.0f, v}; break;
    case 3: d = {u, -1.0f, -v}; break;
    case 4: d = {u, -v, 1.0f}; break;
    default: d = {-u, -v, -1.0f}; break;
  }
  return glm::normalize(d);
}

const std::vector<std::string>& dawnSamplerNames() {
  static const std::vector<std::string> names = {"SkinColorFrontSpecMap", "SkinNormSideSpecMap", "SpecularColorShiftMap",
                                                 "DiffuseCubeMap",        "SpecularCubeMap",     "HilightCubeMap"};
  return names;
}

bool dawnTexture(const std::string& sampler, bool cube, const DawnLighting& light, rt::Texture& out) {
  out = rt::Texture{};
  out.cube = cube;
  if (!cube) {
    glm::vec4 (*fn)(float, float) = nullptr;
    bool signedData = false;
    if (sampler == "SkinColorFrontSpecMap") fn = skinColor;
    else if (sampler == "SkinNormSideSpecMap") fn = normalSideSpec, signedData = true;
    else if (sampler == "SpecularColorShiftMap") fn = specularShift;
    else return false;
    const uint32_t n = std::max<uint32_t>(1, light.textureSize);
    out.size = n;
    out.format = signedData ? VK_FORMAT_R16G16B16A16_SFLOAT : VK_FORMAT_R8G8B8A8_UNORM;
    // The 2D maps depend on the sampler and the size only, and a 1024² map takes a good part
    // of a second to make: made once per process (a session renders many images).
    static std::mutex mutex;
    static std::map<std::pair<std::string, uint32_t>, std::vector<uint8_t>> made;
    std::lock_guard<std::mutex> lock(mutex);
    auto [it, isNew] = made.try_emplace({sampler, n});
    if (isNew) {
      std::vector<uint8_t>& data = it->second;
      data.reserve(size_t(n) * n * (signedData ? 8 : 4));
      for (uint32_t y = 0; y < n; ++y)
        for (uint32_t x = 0; x < n; ++x) {
          glm::vec4 c = fn((static_cast<float>(x) + 0.5f) / static_cast<float>(n), (static_cast<float>(y) + 0.5f) / static_cast<float>(n));
          if (signedData) putHalf4(data, c);
          else putRgba8(data, c);
        }
    }
    out.data = it->second;
    return true;
  }
  glm::vec4 (*fn)(const glm::vec3&, const DawnLighting&) = nullptr;
  if (sampler == "DiffuseCubeMap") fn = diffuseEnv;
  else if (sampler == "SpecularCubeMap") fn = specularEnv;
  else if (sampler == "HilightCubeMap") fn = hilightEnv;
  else return false;
  const uint32_t n = std::max<uint32_t>(1, light.cubeSize);
  out.size = n;
  out.format = VK_FORMAT_R16G16B16A16_SFLOAT;
  out.data.reserve(size_t(6) * n * n * 8);
  for (int f = 0; f < 6; ++f)
    for (uint32_t y = 0; y < n; ++y)
      for (uint32_t x = 0; x < n; ++x) putHalf4(out.data, fn(cubeTexelDirection(f, x, y, n), light));
  return true;
}

}  // namespace sg
