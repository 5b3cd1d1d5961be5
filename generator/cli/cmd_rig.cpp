// `shadergen rig import MODEL.gltf|.glb [--mesh N] [--primitive P] [-o rig.yaml]`:
// derive the rig of one mesh primitive of a glTF model (docs/gltf.md); `MODEL.glb#* -o DIR`:
// of every primitive.
#include <fmt/format.h>

#include <filesystem>
#include <iostream>

#include "cli/commands.h"
#include "cli/output_files.h"
#include "cli/whole_model.h"
#include "rig/gltf_import.h"

namespace sg {
namespace {

// The model and its buffer files: `-o M.bin` beside M.gltf must not overwrite one.
std::vector<InputFile> modelFiles(const GltfImport& imp) {
  std::vector<InputFile> files;
  for (const auto& f : imp.rig.sourceFiles) files.push_back({f, "the glTF model"});
  return files;
}

struct RigImportCommand {
  std::string model;
  int mesh = -1;
  int primitive = -1;
  std::string output;
  bool quiet = false;
  bool packOcclusion = false;
  GltfReadOptions read;

  // The rig as YAML, with the import's findings as header comments; read back before it is
  // returned, so nothing is written that loadRigText would refuse.
  static std::string rigYaml(const GltfImport& imp, const std::string& file, const std::string& output) {
    std::vector<std::string> header{
        fmt::format("Imported by shadergen {} rig import from {}, mesh {} '{}', primitive {}.", shadergenVersion(),
                    file, imp.data.mesh, imp.data.meshName, imp.data.primitive),
        fmt::format("{} vertices; glTF attributes:", imp.data.vertexCount)};
    for (const auto& a : imp.attributes)
      header.push_back(fmt::format("  {:<11} {}{} {}{} -> {}", a.gltfName, a.normalized ? "normalized " : "",
                                   a.componentType, a.type, a.sparse ? " (sparse)" : "",
                                   a.rigAttribute.empty() ? std::string("(left out)")
                                                          : fmt::format("{} ({})", a.rigAttribute, a.format)));
    if (imp.morphTargets > 0) {
      header.push_back(fmt::format("{} morph target(s):", imp.morphTargets));
      for (size_t t = 0; t < imp.targetAttributes.size(); ++t) {
        std::string list;
        for (const auto& n : imp.targetAttributes[t]) list += (list.empty() ? "" : ", ") + n;
        header.push_back(fmt::format("  target {}: {}", t, list));
      }
    }
    for (const auto& n : imp.notes) header.push_back("note: " + n);
    for (const auto& d : imp.rig.importDiagnostics) header.push_back(formatDiagnostic(d));
    std::string yaml = rigToYaml(imp.rig, header);
    loadRigText(yaml, output.empty() ? "<stdout>" : output);
    return yaml;
  }

  int run() {
    if (auto parts = wholeModelParts(model)) return runModel(*parts);
    GltfRef ref = parseGltfRef(model);
    if (model.find('#') != std::string::npos && (mesh >= 0 || primitive >= 0))
      throw CLI::ValidationError(mesh >= 0 ? "--mesh" : "--primitive",
                                 fmt::format("does not apply: '{}' already names the mesh and primitive", model));
    GltfImportOptions o;
    o.mesh = mesh >= 0 ? mesh : ref.mesh;
    o.primitive = primitive >= 0 ? primitive : ref.primitive;
    o.packOcclusionInNormal = packOcclusion;
    o.read = read;
    GltfImport imp = importGltf(ref.file, o);
    std::string yaml = rigYaml(imp, ref.file, output);
    if (!quiet)
      for (const auto& n : imp.notes) std::cerr << fmt::format("{}: note: {}\n", ref.file, n);
    for (const auto& d : imp.rig.importDiagnostics) std::cerr << formatDiagnostic(d) << "\n";
    if (output.empty() || output == "-") {
      std::cout << yaml;
    } else {
      refuseClobbering({output}, modelFiles(imp));
      writeFilesAtomically({PendingFile{output, yaml}});
    }
    return 0;
  }

  // MODEL.glb#*: one rig per primitive into the directory -o, plus index.json; written only
  // when every primitive imports.
  int runModel(const std::vector<GltfPart>& parts) {
    if (mesh >= 0 || primitive >= 0)
      throw CLI::ValidationError(mesh >= 0 ? "--mesh" : "--primitive",
                                 fmt::format("does not apply: '{}' names every primitive", model));
    if (output.empty() || output == "-")
      throw CLI::ValidationError("-o", "is required with a whole model (" + model +
                                           "): it names the directory that gets one rig per primitive");
    const std::string file = parseGltfRef(model, true).file;
    std::vector<PendingFile> files;
    std::vector<InputFile> inputs{{file, "the glTF model"}};
    std::vector<nlohmann::ordered_json> entries(parts.size());
    std::vector<std::string> failed = forEachPart(parts, [&](const GltfPart& part) {
      GltfImportOptions o;
      o.mesh = part.mesh;
      o.primitive = part.primitive;
      o.packOcclusionInNormal = packOcclusion;
      o.read = read;
      GltfImport imp = importGltf(file, o);
      inputs = modelFiles(imp);  // the same for every part
      std::string path = (std::filesystem::path(output) / (part.name + ".yaml")).string();
      files.push_back({path, rigYaml(imp, file, path)});
      nlohmann::ordered_json& e = entries[static_cast<size_t>(&part - parts.data())];
      e["rig_name"] = imp.rig.name;
      e["file"] = part.name + ".yaml";
      e["vertices"] = imp.data.vertexCount;
      e["joints"] = imp.joints;
      e["morph_targets"] = imp.morphTargets;
      if (!quiet)
        for (const auto& n : imp.notes) std::cerr << fmt::format("{}: note: {}\n", part.ref, n);
      for (const auto& d : imp.rig.importDiagnostics) std::cerr << formatDiagnostic(d) << "\n";
    });
    failIfPartsFailed(model, parts.size(), failed);
    files.push_back({(std::filesystem::path(output) / "index.json").string(),
                     wholeModelIndex("rig import", model, parts, entries)});
    std::vector<std::string> outPaths;
    for (const auto& f : files) outPaths.push_back(f.path);
    refuseClobbering(outPaths, inputs);
    writeFilesAtomically(files);
    if (!quiet) std::cout << fmt::format("{}: {} rig(s) and index.json written to {}\n", model, parts.size(), output);
    return 0;
  }
};

}  // namespace

void registerRig(CLI::App& app, CliState& state) {
  CLI::App* rig = app.add_subcommand("rig", "Rig utilities");
  rig->require_subcommand(1);
  auto cmd = std::make_shared<RigImportCommand>();
  CLI::App* imp = rig->add_subcommand("import", "Derive the rig of a glTF mesh primitive and write it as YAML");
  imp->add_option("model", cmd->model, "glTF model (.gltf or .glb), optionally MODEL#MESH/PRIMITIVE, or MODEL#* (every primitive, -o DIR)")->required();
  imp->add_option("--mesh", cmd->mesh, "Mesh index (default 0)")->check(CLI::NonNegativeNumber);
  imp->add_option("--primitive", cmd->primitive, "Primitive index within the mesh (default 0)")
      ->check(CLI::NonNegativeNumber);
  imp->add_option("-o,--output", cmd->output, "Output rig YAML (default: standard output); for MODEL#*, the output directory");
  imp->add_flag("--pack-occlusion", cmd->packOcclusion,
                "Dawn's layout: baked _OCCLUSION in normal.w (float32x4) and its target deltas in the normal deltas' w");
  imp->add_flag("-q,--quiet", cmd->quiet, "Do not print warnings about attributes left out");
  addGltfReadOptions(*imp, cmd->read);
  imp->callback([cmd, &state] { state.run = [cmd] { return cmd->run(); }; });
}

}  // namespace sg
