// `shadergen pack`: the vertex streams of the plan's inputs, from a model's float data in
// the formats the rig stores (validate/pack.h), and their layout.
#include <fmt/format.h>

#include <iostream>

#include "cli/commands.h"
#include "validate/gltf_scene.h"
#include "validate/pack.h"
#include "validate/validate.h"

namespace sg {
namespace {

struct PackCommand {
  CLI::App* cmd = nullptr;
  GenerateArgs args;
  std::string model;
  std::string mesh;
  std::string output;
  bool quiet = false;

  int run() {
    GenerateOptions o = args.resolve();
    const bool gltfRig = isGltfPath(o.rigPath);
    if (gltfRig && !model.empty()) refuseOption(*cmd, "--model", "to a glTF rig: its own model is packed");
    if (!mesh.empty() && (gltfRig || !model.empty()))
      refuseOption(*cmd, "--mesh", "with a model: the model's data is packed");
    const std::string source = gltfRig ? o.rigPath : model;
    if (source.empty() && mesh.empty())
      throw CLI::ValidationError("--model", "pack needs data: --model MODEL.glb#M/P (or a glTF rig), or --mesh head|limb|dawn");
    GenerateResult r = generate(o);
    // The model at its rest pose: vertex data does not depend on the pose.
    GltfSceneOptions so;
    so.read = o.gltf;
    // The model's files (its buffer files too) are inputs the outputs must not overwrite:
    // `-o M` beside M.gltf would write M.bin.
    std::vector<std::string> extra;
    ValidationScene scene;
    if (source.empty()) {
      scene = proceduralScene(r.in.rig, mesh, 1, 1);
    } else {
      GltfImport imp = importGltfRef(source, so.read);
      extra = imp.rig.sourceFiles;
      scene = gltfScene(imp, so);
    }
    PackedVertices packed = packVertices(r, scene.mesh);
    std::vector<PendingFile> files = {{output + ".bin", std::string(packed.bytes.begin(), packed.bytes.end())},
                                      {output + ".json", packed.layoutJson}};
    std::vector<std::string> outPaths = {files[0].path, files[1].path};
    refuseClobbering(outPaths, inputFiles(r.in, extra));
    writeFilesAtomically(files);
    for (const auto& n : r.in.notes) std::cerr << formatDiagnostic(n) << "\n";
    if (!quiet)
      std::cout << fmt::format("packed {} vertices of '{}' into {} streams{}, {} bytes: {}.bin, {}.json\n",
                               packed.vertexCount, scene.mesh.name, r.glsl.inputs.size(),
                               packed.storageBuffers ? fmt::format(" and {} storage buffers", packed.storageBuffers) : "",
                               packed.bytes.size(), output, output);
    return 0;
  }
};

}  // namespace

void registerPack(CLI::App& app, CliState& state) {
  auto c = std::make_shared<PackCommand>();
  CLI::App* sub = app.add_subcommand(
      "pack", "Write the vertex streams the generated program reads, from a model's float data, in the formats the "
              "rig stores (encoded semantics derived), with their layout (docs/rig-format.md, \"Packing\")");
  c->cmd = sub;
  c->args.add(*sub);
  sub->add_option("--model", c->model, "The data: a glTF primitive MODEL.glb#M/P (default: the rig, when it is one)");
  sub->add_option("--mesh", c->mesh, "Procedural data instead: head, limb or dawn")
      ->check(CLI::IsMember({"head", "limb", "dawn"}));
  sub->add_option("-o,--output", c->output, "Output stem: writes STEM.bin (the streams) and STEM.json (their layout)")
      ->required();
  sub->add_flag("-q,--quiet", c->quiet, "Do not print the summary (notes still go to stderr, as with generate -q)");
  sub->callback([c, &state] { state.run = [c] { return c->run(); }; });
}

}  // namespace sg
