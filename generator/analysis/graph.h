// `shadergen graph`: a plan as a Graphviz DOT graph — rig inputs, rule nodes with their
// costs (shared values highlighted), and the fragment shader's inputs — and SVG through
// Graphviz's `dot` when it is on PATH.
#pragma once
#include <string>

#include "search/astar.h"
#include "search/instance.h"
#include "search/plan.h"

namespace sg {

// Deterministic DOT text for `plan` (an optimal plan of in.problem).
std::string planToDot(const LoadedInputs& in, const Plan& plan);

// Full path of an executable found on PATH ("" if none).
std::string findOnPath(const std::string& program);

// Runs `dot -Tsvg` on `dotText`, writing `svgPath` atomically (temp file, rename).
// Throws std::runtime_error if dot is missing or fails.
void renderSvg(const std::string& dotText, const std::string& svgPath);

}  // namespace sg
