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

  bool known() const { return verticesPerDraw > 0 || jointsPerWarp > 0 || activeMorphTargets >= 0 || invocationsPerVertex > 0; }
};

// "180000 vertices per draw, 1.31 joints per warp, ..." (the known figures and the source).
inline std::string describeWorkload(const Workload& w) {
  std::string s;
  auto add = [&](const std::string& part) { s += (s.empty() ? "" : ", ") + part; };
  auto num = [](double v) {
    std::string t = std::to_string(v);
    while (t.size() > 1 && t.back() == '0') t.pop_back();
    if (!t.empty() && t.back() == '.') t.pop_back();
    return t;
  };
  if (w.verticesPerDraw > 0) add(num(w.verticesPerDraw) + " vertices per draw");
  if (w.jointsPerWarp > 0) add(num(w.jointsPerWarp) + " joints per warp");
  if (w.activeMorphTargets >= 0) add(num(w.activeMorphTargets) + " active morph targets");
  if (w.invocationsPerVertex > 0) add(num(w.invocationsPerVertex) + " invocations per vertex");
  if (s.empty()) s = "unknown";
  if (!w.source.empty()) s += " (" + w.source + ")";
  return s;
}

}  // namespace sg
