// The workload a program is priced for (docs/device-profiles.md, "Workload"): what the mesh it
// will draw looks like to the device. A device profile's term weights may depend on it; the
// search never reads a mesh. Measured from the mesh at generation time (measure/workload.h:
// a glTF rig's own primitive, `--mesh` for a YAML rig), or left unknown, when the profile's
// stated defaults price it. Plain data: the pipeline passes it through untouched.
#pragma once
#include <string>

namespace sg {

struct Workload {
  // Vertices per draw (0 = unknown: the profile's vertices_per_draw).
  double verticesPerDraw = 0;
  // Mean over groups of 32 consecutive shaded vertices and over influence slots of the number
  // of distinct joint indices the group reads: the addresses a warp's indexed palette load
  // touches (1 = every vertex of a group reads one joint). 0 = unknown or unskinned.
  double jointsPerWarp = 0;
  // Morph targets with a non-zero weight in a frame (-1 = unknown: every target).
  double activeMorphTargets = -1;
  // Vertex-shader invocations per vertex when the mesh is drawn in its index order through a
  // post-transform cache (1 = each vertex shaded once). 0 = unknown.
  double invocationsPerVertex = 0;
  // Where the figures come from, for reports: "mesh 'dawn' (180000 vertices)", "".
  std::string source;
  // Fragments one draw's triangles cover per vertex, as a device counts them (fragment shader
  // invocations over vertices; measure/workload.h: bench and calibrate count them, a generation
  // is told or does not know). 0 = unknown.
  double fragmentsPerVertex = 0;
  // Mean over jointsPerWarp's groups of the distinct joint indices a group reads over all its
  // influence slots together: the palette entries one warp's palette loads touch, its share
  // of the constant cache (docs/device-profiles.md, "The constant cache's capacity"): a profile
  // with a `constant_cache:` prices a warp past its capacity as missing. 0 = unknown or unskinned.
  double paletteEntriesPerWarp = 0;

  bool known() const {
    return verticesPerDraw > 0 || jointsPerWarp > 0 || activeMorphTargets >= 0 || invocationsPerVertex > 0 || fragmentsPerVertex > 0 ||
           paletteEntriesPerWarp > 0;
  }
};

// One line for reports (explain, bench): "180000 vertices per draw, 3.42 joints per warp, ...
// (procedural mesh 'dawn' (180000 vertices))", each unknown figure named as such.
std::string describeWorkload(const Workload& w);

}  // namespace sg
