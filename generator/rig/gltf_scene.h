// glTF scene and animation (docs/gltf.md): the node hierarchy (checked to be a forest), the
// default scene's roots, the node instantiating the mesh, the nodes' GPU instances
// (EXT_mesh_gpu_instancing), skins with their inverse bind matrices, and animation channels,
// as the plain data of GltfModelData.
#pragma once
#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "rig/gltf_accessor.h"
#include "rig/gltf_import.h"

namespace sg::gltf {

// Fills data.nodes, sceneRoots, meshNode, skins and animations; notes what it leaves out, and
// warns (`diagnostics`) of rotations that are not unit quaternions, in nodes, GPU instances
// and samplers.
void readScene(const tinygltf::Model& model, const std::string& file, int mesh, const std::string& meshDesc,
               Reader& reader, GltfModelData& data, std::vector<std::string>& notes,
               std::vector<Diagnostic>& diagnostics);

}  // namespace sg::gltf
