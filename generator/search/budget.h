// Per-search budget (SearchLimits): every engine calls onExpansion once per expanded
// node; hitting a limit throws SearchLimitError naming it, so a search never hangs.
#pragma once
#include <fmt/format.h>

#include <chrono>
#include <cstdint>

#include "search/astar.h"

namespace sg {

class SearchBudget {
 public:
  using Clock = std::chrono::steady_clock;
  explicit SearchBudget(const SearchLimits& limits) : limits_(limits), start_(Clock::now()) {}

  void onExpansion(int64_t expanded) const {
    if (expanded > limits_.maxExpansions)
      throw SearchLimitError(fmt::format("search gave up: expansion limit of {} reached (--max-expansions)",
                                         limits_.maxExpansions));
    checkTime(expanded);
  }
  // Also called per generated node: one node can cost milliseconds (forward LM-cut on
  // thousands of rules) while reading the clock costs tens of nanoseconds.
  void checkTime(int64_t expanded) const {
    if (limits_.maxSeconds > 0 && seconds() > limits_.maxSeconds)
      throw SearchLimitError(fmt::format("search gave up: time limit of {} s reached after {} expansions "
                                         "(--search-time-limit)",
                                         limits_.maxSeconds, expanded));
  }
  double seconds() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

 private:
  SearchLimits limits_;
  Clock::time_point start_;
};

// Adds the time spent in `f` to `seconds` (heuristic time in SearchStats).
template <class F>
auto timed(double& seconds, F&& f) {
  auto t0 = SearchBudget::Clock::now();
  auto v = f();
  seconds += std::chrono::duration<double>(SearchBudget::Clock::now() - t0).count();
  return v;
}

}  // namespace sg
