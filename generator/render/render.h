// Rendering: draws a rig with its generated vertex shader and a fragment shader into an
// image on a Vulkan device (lavapipe by default). The fragment shader's samplers are fed by
// name from the procedural textures of listing 3-4 (render/dawn_textures.h); a fragment
// shader without samplers (examples/render/normals.frag) works with any rig.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/generate.h"
#include "render/dawn_textures.h"
#include "runtime/vk_render.h"
#include "validate/gltf_scene.h"
#include "validate/validate.h"

namespace sg {

struct RenderCamera {
  float yawDegrees = 0;    // around +Y; 0 looks at the face (+Z side of the procedural head)
  float pitchDegrees = 0;  // positive looks from above
  float fovYDegrees = 35;
  float zoom = 1;          // > 1 moves closer than the framing distance
};

struct RenderOptions {
  GenerateOptions gen;            // capture is ignored (render builds never capture)
  std::string device;             // "" = lavapipe
  DeviceLimitsOptions limits;     // a named device's own limits for the search (validate/validate.h)
  bool validationLayers = true;
  uint32_t width = 512, height = 512;
  std::string mesh = "head";      // procedural mesh: head, limb, dawn (glTF rigs draw their own mesh)
  double time = 0;                // glTF rigs: animation time in seconds
  std::string animation;          // glTF rigs: animation name or index ("" = the first)
  uint32_t poseSeed = 0;          // 0 = rest pose (identity bones), else makeRandomPose(seed)
  float morphWeight = 0.5f;       // rest pose: every morph target's weight
  std::optional<double> gltfMorphWeight;  // glTF rigs: every target's weight instead of the animation's
  RenderCamera camera;
  DawnLighting lighting;
  std::array<float, 4> background{0.06f, 0.06f, 0.08f, 1.0f};
};

// A procedural mesh with its triangles, one pose and a camera framing the posed mesh.
struct RenderScene {
  rt::Mesh mesh;  // quantized to the rig's attribute formats
  std::vector<uint32_t> indices;
  rt::Pose pose;
  rt::RigShape shape;
};

// Triangles of a (rings + 1) x (segments + 1) vertex grid (row-major), two per quad.
std::vector<uint32_t> gridIndices(int rings, int segments);

// A procedural mesh, or for a glTF rig ("model.glb#m/p") the primitive's own vertices,
// triangles and pose at opts.time (posed as validation poses it).
RenderScene renderScene(const Rig& rig, const RenderOptions& opts);

// A glTF primitive's triangles as a list: `indices` (empty: 0..vertexCount-1) in `mode`
// (4 triangles, 5 strip, 6 fan). Throws InputError for points and lines.
std::vector<uint32_t> triangleList(const std::vector<uint32_t>& indices, int mode, size_t vertexCount,
                                   const std::string& what);

// Sets pose.cameraPosition/view/projection so the posed mesh (its reference world
// positions) fills the image.
void frameCamera(const rt::Mesh& mesh, const rt::RigShape& shape, const RenderCamera& cam, float aspect, rt::Pose& pose);
// Same for any set of world-space points (a whole model's primitives together).
void frameCameraOn(const std::vector<glm::vec3>& world, const RenderCamera& cam, float aspect, rt::Pose& pose);

// One primitive of a whole model (MODEL.glb#*): its own generated program (no capture) and
// its scene at opts.time, posed at its node (skinned: by its joints) as validation poses it.
struct ModelPart {
  std::string name;  // gltfPartName
  GenerateResult gen;
  RenderScene scene;
  // The primitive's other instances (gltfInstances: nodes drawing the mesh with their own
  // transform, skin or morph weights), one pose each: a mesh instanced by several nodes is
  // drawn at each.
  std::vector<rt::Pose> instances;
  std::vector<std::string> notes;  // instances not drawn, and why
};
ModelPart modelPart(const RenderOptions& opts, const GltfPart& part);
// One camera framing every part's posed world positions (instances too), set on every pose.
void frameModel(std::vector<ModelPart>& parts, const RenderCamera& cam, float aspect);
// Per pixel, the colour of the nearest surface among `images` (smallest depth; ties go to
// the earlier image), which is what drawing them all in one depth-tested pass writes for
// opaque surfaces. Every image has the same size; empty pixels keep the first's colour.
rt::Image mergeByDepth(const std::vector<rt::Image>& images);

// A fragment shader compiled from a file, with the descriptors it uses (glslang's reflection).
struct FragmentProgram {
  std::string path;
  std::vector<uint32_t> spirv;
  std::vector<ShaderDescriptor> descriptors;
};

struct RenderResult {
  rt::Image image;
  std::string device;
  std::vector<std::string> rules;  // the plan drawn
  int64_t planCost = 0;
  std::string limits;  // the device limits searched under (applyDeviceLimits; "" = the flags)
  std::vector<std::string> validationMessages;
  // Loading's notes (which stored form each plan reads, what error budgets removed).
  std::vector<Diagnostic> notes;
};

// Owns the device; renders any number of images.
class RenderSession {
 public:
  RenderSession(const std::string& device, bool validationLayers);
  ~RenderSession();
  std::string deviceName() const;
  const rt::Harness& harness() const { return *harness_; }

  // Generates (no capture), compiles the fragment shader, binds its samplers, draws.
  // Throws InputError for bad inputs (a sampler no texture serves: at its declaration).
  RenderResult render(const RenderOptions& opts);
  // Draws an already generated program over a scene.
  RenderResult render(const GenerateResult& gen, const FragmentProgram& fragment, const std::vector<rt::Texture>& textures,
                      const RenderScene& scene, const RenderOptions& opts);
  // A whole model: every part drawn with its own program under the parts' shared camera
  // (frameModel), merged by depth. `partImages`, when given, receives each draw's own image
  // (a part, then its instances).
  // planCost is the sum of the parts' costs.
  RenderResult renderModel(const std::vector<ModelPart>& parts, const FragmentProgram& fragment,
                           const std::vector<rt::Texture>& textures, const RenderOptions& opts,
                           std::vector<rt::Image>* partImages = nullptr);

 private:
  std::unique_ptr<rt::Harness> harness_;
  std::unique_ptr<rt::Renderer> renderer_;
};

// Compiles a fragment shader file (errors as InputErrors at their file:line).
FragmentProgram compileFragmentFile(const std::string& path, TargetEnv env);
// The textures for every sampler of the fragment shader (set 1 only); throws InputError at
// the sampler's declaration for one that is not in set 1 or has no texture.
std::vector<rt::Texture> texturesFor(const FragmentProgram& fragment, const DawnLighting& lighting);

// What a draw of program `gen` with `fragment` reads: programInputs over the scene plus the
// textures and the fragment shader's declared samplers.
rt::DrawRequest drawRequest(const GenerateResult& gen, const FragmentProgram& fragment,
                            const std::vector<rt::Texture>& textures, const RenderScene& scene);

// 8-bit RGB PNG bytes (alpha dropped: listing 3-4 writes "haze" there, not coverage). Fixed
// settings and no time chunk, so the bytes depend only on the pixels.
std::string encodePng(const rt::Image& image);
// Reads an 8-bit RGB/RGBA PNG (for reference-image tests); throws InputError on failure.
rt::Image readPng(const std::string& path);

}  // namespace sg
