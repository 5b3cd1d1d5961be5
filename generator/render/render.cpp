#include "render/render.h"

#include <fmt/format.h>
#include <glm/gtc/matrix_transform.hpp>
#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>

#include "common/content_hash.h"
#include "common/input_file.h"
#include "runtime/procedural.h"
#include "runtime/reference.h"

namespace sg {

std::vector<uint32_t> gridIndices(int rings, int segments) {
  std::vector<uint32_t> idx;
  idx.reserve(static_cast<size_t>(rings) * static_cast<size_t>(segments) * 6);
  const uint32_t row = static_cast<uint32_t>(segments + 1);
  for (uint32_t i = 0; i < static_cast<uint32_t>(rings); ++i)
    for (uint32_t j = 0; j < static_cast<uint32_t>(segments); ++j) {
      uint32_t a = i * row + j, b = a + 1, c = a + row, d = c + 1;
      idx.insert(idx.end(), {a, c, b, b, c, d});
    }
  return idx;
}

void frameCamera(const rt::Mesh& mesh, const rt::RigShape& shape, const RenderCamera& cam, float aspect, rt::Pose& pose) {
  // The bounding sphere of the posed mesh (world positions from the reference).
  std::vector<glm::vec3> world;
  for (const auto& p : rt::referenceValues("world.position", mesh, pose, shape)) world.emplace_back(p);
  frameCameraOn(world, cam, aspect, pose);
}

void frameCameraOn(const std::vector<glm::vec3>& world, const RenderCamera& cam, float aspect, rt::Pose& pose) {
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  for (const auto& p : world) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  const glm::vec3 centre = 0.5f * (lo + hi);
  float radius = 0;
  for (const auto& p : world) radius = std::max(radius, glm::length(p - centre));
  radius = std::max(radius, 1e-3f);
  const float fovY = glm::radians(std::clamp(cam.fovYDegrees, 5.0f, 150.0f));
  const float fitFov = aspect < 1.0f ? 2.0f * std::atan(std::tan(0.5f * fovY) * aspect) : fovY;
  const float distance = 1.05f * radius / std::sin(0.5f * fitFov) / std::max(cam.zoom, 0.01f);
  const float yaw = glm::radians(cam.yawDegrees), pitch = glm::radians(std::clamp(cam.pitchDegrees, -89.0f, 89.0f));
  const glm::vec3 dir(std::sin(yaw) * std::cos(pitch), std::sin(pitch), std::cos(yaw) * std::cos(pitch));
  pose.cameraPosition = centre + distance * dir;
  pose.view = glm::lookAt(pose.cameraPosition, centre, glm::vec3(0, 1, 0));
  const float nearZ = std::max(0.01f, distance - 2.0f * radius), farZ = distance + 2.0f * radius;
  pose.projection = glm::perspectiveRH_ZO(fovY, aspect, nearZ, farZ);
  pose.projection[1][1] *= -1.0f;  // Vulkan's clip-space Y points down
}

ModelPart modelPart(const RenderOptions& opts, const GltfPart& part) {
  RenderOptions o = opts;
  o.gen.rigPath = part.ref;
  o.gen.capture = false;
  ModelPart p;
  p.name = part.name;
  p.gen = generate(o.gen);
  p.scene = renderScene(p.gen.in.rig, o);
  // Other instances: every node of the scene that draws this mesh, with its own transform,
  // skin and morph weights (gltfInstances), under the one program.
  GltfImport model = importGltfRef(part.ref, opts.gen.gltf);
  GltfSceneOptions so;
  so.times = {opts.time};
  so.animation = opts.animation;
  so.morphWeight = opts.gltfMorphWeight;
  so.allInstances = true;
  GltfSceneInfo info;
  ValidationScene all = gltfScene(model, so, &info);
  p.instances.assign(all.poses.begin() + 1, all.poses.end());
  p.notes = info.notes;
  return p;
}

void frameModel(std::vector<ModelPart>& parts, const RenderCamera& cam, float aspect) {
  std::vector<glm::vec3> world;
  for (const auto& p : parts) {
    for (const auto& w : rt::referenceValues("world.position", p.scene.mesh, p.scene.pose, p.scene.shape))
      world.emplace_back(w);
    for (const auto& pose : p.instances)
      for (const auto& w : rt::referenceValues("world.position", p.scene.mesh, pose, p.scene.shape)) world.emplace_back(w);
  }
  for (auto& p : parts) {
    frameCameraOn(world, cam, aspect, p.scene.pose);
    for (auto& pose : p.instances) frameCameraOn(world, cam, aspect, pose);
  }
}

rt::Image mergeByDepth(const std::vector<rt::Image>& images) {
  if (images.empty()) throw std::logic_error("mergeByDepth: no images");
  rt::Image out = images.front();
  for (size_t i = 1; i < images.size(); ++i) {
    const rt::Image& im = images[i];
    if (im.width != out.width || im.height != out.height || im.depth.size() != out.depth.size())
      throw std::logic_error("mergeByDepth: images of different sizes");
    for (size_t px = 0; px < out.depth.size(); ++px)
      if (im.depth[px] < out.depth[px]) {
        out.depth[px] = im.depth[px];
        std::memcpy(&out.rgba[px * 4], &im.rgba[px * 4], 4);
      }
  }
  return out;
}

std::vector<uint32_t> triangleList(const std::vector<uint32_t>& indices, int mode, size_t vertexCount,
                                   const std::string& what) {
  std::vector<uint32_t> in = indices;
  if (in.empty())
    for (size_t i = 0; i < vertexCount; ++i) in.push_back(static_cast<uint32_t>(i));
  std::vector<uint32_t> out;
  if (mode == 4) {
    out.assign(in.begin(), in.begin() + static_cast<long>(in.size() / 3 * 3));
  } else if (mode == 5) {  // strip: every other triangle reversed to keep the winding
    for (size_t i = 0; i + 2 < in.size(); ++i)
      out.insert(out.end(), i % 2 ? std::initializer_list<uint32_t>{in[i + 1], in[i], in[i + 2]}
                                  : std::initializer_list<uint32_t>{in[i], in[i + 1], in[i + 2]});
  } else if (mode == 6) {
    for (size_t i = 1; i + 1 < in.size(); ++i) out.insert(out.end(), {in[0], in[i], in[i + 1]});
  } else {
    throw InputError(SourceLoc{what, 0, 0}, fmt::format("primitive mode {} has no triangles to draw (render draws "
                                                        "triangles, strips and fans)", mode));
  }
  if (out.empty()) throw InputError(SourceLoc{what, 0, 0}, "the primitive has no triangles");
  return out;
}

RenderScene renderScene(const Rig& rig, const RenderOptions& opts) {
  if (isGltfPath(opts.gen.rigPath)) {
    const std::string file = parseGltfRef(opts.gen.rigPath).file;
    GltfImport model = importGltfRef(opts.gen.rigPath, opts.gen.gltf);
    GltfSceneOptions so;
    so.times = {opts.time};
    so.animation = opts.animation;
    so.morphWeight = opts.gltfMorphWeight;
    if (!model.data.indicesError.empty()) throw InputError(SourceLoc{file, 0, 0}, model.data.indicesError);
    ValidationScene vs = gltfScene(model, so);
    RenderScene s;
    s.mesh = quantizeForRig(rig, vs.mesh);
    s.indices = triangleList(model.data.indices, model.data.mode, s.mesh.vertexCount, file);
    s.shape = vs.shape;
    s.pose = vs.poses.front();
    frameCamera(s.mesh, s.shape, opts.camera, float(opts.width) / float(opts.height), s.pose);
    return s;
  }
  // The grid sizes of validate's procedural meshes (proceduralScene).
  static const std::map<std::string, std::pair<int, int>> grids = {{"head", {40, 48}}, {"limb", {32, 24}}, {"dawn", {299, 599}}};
  auto grid = grids.find(opts.mesh);
  if (grid == grids.end()) throw InputError(SourceLoc{}, fmt::format("unknown mesh '{}' (head, limb, dawn)", opts.mesh));
  ValidationScene vs = proceduralScene(rig, opts.mesh, opts.poseSeed, 1);
  RenderScene s;
  s.mesh = quantizeForRig(rig, vs.mesh);
  s.indices = gridIndices(grid->second.first, grid->second.second);
  if (size_t(grid->second.first + 1) * size_t(grid->second.second + 1) != s.mesh.vertexCount)
    throw std::logic_error("render: procedural grid size does not match the mesh");
  s.shape = vs.shape;
  if (opts.poseSeed != 0) {
    s.pose = vs.poses.front();
  } else {
    s.pose = rt::makeRestPose(s.shape);
    std::fill(s.pose.morphWeights.begin(), s.pose.morphWeights.end(), opts.morphWeight);
  }
  frameCamera(s.mesh, s.shape, opts.camera, float(opts.width) / float(opts.height), s.pose);
  return s;
}

FragmentProgram compileFragmentFile(const std::string& path, TargetEnv env) {
  GlslShader s(GlslUnit{Stage::Fragment, readInputFile(path), path, {}}, env);
  if (!s.ok()) throwDiagnostics(s.diagnostics(), path, "the fragment shader does not compile");
  return FragmentProgram{path, s.spirv(), s.descriptors()};
}

std::vector<rt::Texture> texturesFor(const FragmentProgram& fragment, const DawnLighting& lighting) {
  const std::string& path = fragment.path;
  // Diagnostics point at the line that declares the sampler.
  auto where = [&](const std::string& name) {
    std::string text;
    if (tryReadInputFile(path, text)) {
      int line = 1;
      for (size_t pos = 0; pos < text.size();) {
        size_t end = text.find('\n', pos);
        std::string l = text.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
        size_t at = l.find(name);
        if (l.find("uniform") != std::string::npos && at != std::string::npos)
          return SourceLoc{path, line, static_cast<int>(at) + 1};
        if (end == std::string::npos) break;
        pos = end + 1;
        ++line;
      }
    }
    return SourceLoc{path, 0, 0};
  };
  std::vector<rt::Texture> out;
  for (const auto& s : fragment.descriptors) {
    if (s.kind != ShaderDescriptor::Kind::Sampler) continue;
    if (s.set != 1)
      throw InputError(where(s.name), fmt::format("sampler '{}' is in set {}; render binds textures in set 1 "
                                                  "(set 0 is the vertex shader's uniform block and storage buffers)", s.name, s.set));
    rt::Texture t;
    if (!dawnTexture(s.name, s.cube, lighting, t)) {
      std::string known;
      for (const auto& n : dawnSamplerNames()) known += (known.empty() ? "" : ", ") + n;
      throw InputError(where(s.name), fmt::format("no texture for {} '{}': render provides listing 3-4's ({})",
                                                  s.cube ? "samplerCube" : "sampler2D", s.name, known));
    }
    t.binding = s.binding;
    out.push_back(std::move(t));
  }
  return out;
}

RenderSession::RenderSession(const std::string& device, bool validationLayers) {
  rt::HarnessOptions ho;
  ho.deviceName = device;
  ho.validation = validationLayers;
  harness_ = std::make_unique<rt::Harness>(ho);
  renderer_ = std::make_unique<rt::Renderer>(*harness_);
}

RenderSession::~RenderSession() = default;

std::string RenderSession::deviceName() const { return harness_->deviceName(); }

rt::DrawRequest drawRequest(const GenerateResult& gen, const FragmentProgram& fragment,
                            const std::vector<rt::Texture>& textures, const RenderScene& scene) {
  rt::DrawRequest req;
  static_cast<rt::ProgramInputs&>(req) = programInputs(gen, scene.mesh, scene.pose);
  req.textures = textures;
  for (auto& d : declaredDescriptors(fragment.descriptors)) req.declared.push_back(std::move(d));
  req.vertexSpirv = gen.spirv.words;
  req.fragmentSpirv = fragment.spirv;
  req.indices = scene.indices;
  return req;
}

RenderResult RenderSession::render(const GenerateResult& gen, const FragmentProgram& fragment,
                                   const std::vector<rt::Texture>& textures, const RenderScene& scene,
                                   const RenderOptions& opts) {
  const size_t before = harness_->validationMessages().size();
  rt::DrawRequest req = drawRequest(gen, fragment, textures, scene);
  req.width = opts.width;
  req.height = opts.height;
  req.clearColor = opts.background;
  RenderResult r;
  r.image = renderer_->draw(req);
  r.device = harness_->deviceName();
  r.planCost = gen.plan.cost;
  for (int a : gen.plan.actions) r.rules.push_back(gen.in.problem.actions[a].name);
  const auto& msgs = harness_->validationMessages();
  r.validationMessages.assign(msgs.begin() + static_cast<long>(before), msgs.end());
  return r;
}

RenderResult RenderSession::renderModel(const std::vector<ModelPart>& parts, const FragmentProgram& fragment,
                                        const std::vector<rt::Texture>& textures, const RenderOptions& opts,
                                        std::vector<rt::Image>* partImages) {
  std::vector<rt::Image> images;
  RenderResult r;
  for (const auto& p : parts) {
    RenderScene scene = p.scene;
    for (size_t i = 0; i <= p.instances.size(); ++i) {
      if (i > 0) scene.pose = p.instances[i - 1];
      RenderResult one = render(p.gen, fragment, textures, scene, opts);
      images.push_back(std::move(one.image));
      if (i == 0) r.planCost += one.planCost;
      r.device = one.device;
      r.validationMessages.insert(r.validationMessages.end(), one.validationMessages.begin(),
                                  one.validationMessages.end());
    }
  }
  r.image = mergeByDepth(images);
  if (partImages) *partImages = std::move(images);
  return r;
}

RenderResult RenderSession::render(const RenderOptions& opts) {
  GenerateOptions g = opts.gen;
  g.capture = false;
  const std::string limits = applyDeviceLimits(g, opts.limits, *harness_);
  GenerateResult gen = generate(g);
  FragmentProgram frag = compileFragmentFile(g.fragmentPath, g.targetEnv);
  std::vector<rt::Texture> textures = texturesFor(frag, opts.lighting);
  RenderScene scene = renderScene(gen.in.rig, opts);
  RenderResult r = render(gen, frag, textures, scene, opts);
  r.limits = limits;
  r.notes = gen.in.notes;
  if (g.pin)
    if (auto changed = pinInputsChanged(*g.pin, sha256OfFiles(gen.pinnedInputs))) r.notes.push_back(*changed);
  return r;
}

// --- PNG ----------------------------------------------------------------------------------

namespace {

void onPngError(png_structp png, png_const_charp msg) {
  *static_cast<std::string*>(png_get_error_ptr(png)) = msg ? msg : "libpng error";
  png_longjmp(png, 1);
}
void onPngWarning(png_structp, png_const_charp) {}

}  // namespace

std::string encodePng(const rt::Image& image) {
  if (image.width == 0 || image.height == 0 || image.rgba.size() != size_t(image.width) * image.height * 4)
    throw std::logic_error("encodePng: the image has no pixels or the wrong size");
  std::string out, error;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &error, onPngError, onPngWarning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  std::vector<uint8_t> row(size_t(image.width) * 3);
  bool ok = png && info;
  if (ok && setjmp(png_jmpbuf(png)) == 0) {
    png_set_write_fn(
        png, &out,
        [](png_structp p, png_bytep data, size_t n) {
          static_cast<std::string*>(png_get_io_ptr(p))->append(reinterpret_cast<const char*>(data), n);
        },
        [](png_structp) {});
    png_set_IHDR(png, info, image.width, image.height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_compression_level(png, 9);  // fixed settings, no time chunk: same pixels, same bytes
    png_write_info(png, info);
    for (uint32_t y = 0; y < image.height; ++y) {
      const uint8_t* src = image.rgba.data() + size_t(y) * image.width * 4;
      for (uint32_t x = 0; x < image.width; ++x) std::memcpy(&row[size_t(x) * 3], src + size_t(x) * 4, 3);
      png_write_row(png, row.data());
    }
    png_write_end(png, nullptr);
  } else {
    ok = false;
  }
  png_destroy_write_struct(&png, &info);
  if (!ok) throw std::runtime_error("cannot encode the PNG: " + (error.empty() ? std::string("libpng failed") : error));
  return out;
}

rt::Image readPng(const std::string& path) {
  png_image img{};
  img.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&img, path.c_str()))
    throw InputError(SourceLoc{path, 0, 0}, fmt::format("cannot read the PNG: {}", img.message));
  img.format = PNG_FORMAT_RGBA;
  rt::Image out;
  out.width = img.width;
  out.height = img.height;
  out.rgba.resize(PNG_IMAGE_SIZE(img));
  if (!png_image_finish_read(&img, nullptr, out.rgba.data(), 0, nullptr)) {
    png_image_free(&img);
    throw InputError(SourceLoc{path, 0, 0}, fmt::format("cannot read the PNG: {}", img.message));
  }
  return out;
}

}  // namespace sg
