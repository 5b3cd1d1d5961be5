#include "search/workload.h"

#include <fmt/format.h>

namespace sg {

std::string describeWorkload(const Workload& w) {
  if (!w.known()) return w.source.empty() ? "unknown (the profile's defaults)" : w.source;
  std::string s = w.verticesPerDraw > 0 ? fmt::format("{:g} vertices per draw", w.verticesPerDraw) : "vertices per draw unknown";
  s += w.jointsPerWarp > 0 ? fmt::format(", {:.2f} distinct joints per warp", w.jointsPerWarp) : ", joints per warp unknown (or unskinned)";
  if (w.paletteEntriesPerWarp > 0) s += fmt::format(" ({:.1f} over all its influences)", w.paletteEntriesPerWarp);
  s += w.activeMorphTargets >= 0 ? fmt::format(", {:g} active morph targets", w.activeMorphTargets)
                                 : ", active morph targets unknown (all)";
  s += w.invocationsPerVertex > 0 ? fmt::format(", {:.3f} shader invocations per vertex", w.invocationsPerVertex)
                                  : ", invocations per vertex unknown";
  if (w.fragmentsPerVertex > 0) s += fmt::format(", {:.2f} fragments per vertex", w.fragmentsPerVertex);
  if (!w.source.empty()) s += " (" + w.source + ")";
  return s;
}

}  // namespace sg
