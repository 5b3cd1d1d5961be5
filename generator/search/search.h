// One entry point for every search engine (docs/search.md): the pipeline, explain and the
// benchmarks pick an engine and a heuristic by name.
#pragma once
#include <optional>
#include <string>

#include "search/astar.h"
#include "search/plan.h"
#include "search/problem.h"

namespace sg {

struct SearchOptions {
  // "auto": regression A* when the relevant rule graph is acyclic, else forward A*;
  // "regression", "forward": A* in that space; "ip": the GLPK integer program.
  std::string engine = "auto";
  std::string heuristic = "lmcut";  // blind, hmax, lmcut; "landmarks" (regression only)
  SearchLimits limits;
};

// Throws std::invalid_argument for an unknown engine or heuristic, or "regression" on a
// cyclic rule graph; SearchLimitError at a limit. nullopt: the goals are unreachable.
std::optional<Plan> findPlan(const Problem& p, const SearchOptions& opts, SearchStats* stats = nullptr);

// How the plan was found, as the shader's header and generate's plan line name it: "lmcut A*",
// or "integer program" (--search ip, or forward A*'s fallback under a roofline profile).
std::string searchMethod(const SearchStats& st);

// `generate --stats`: expansions, generated nodes, heuristic time, initial h vs cost.
std::string describeStats(const SearchStats& st);

}  // namespace sg
