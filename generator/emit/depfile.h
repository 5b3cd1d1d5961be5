// Make/Ninja depfiles: the outputs of one generation and every file it read.
#pragma once
#include <string>
#include <vector>

namespace sg {

// "target1 target2: dep1 dep2 ..." with spaces, '#' and '$' escaped (Make/Ninja syntax).
// A path with a newline cannot be written in that syntax: throws InputError.
std::string makeDepfile(const std::vector<std::string>& targets, const std::vector<std::string>& deps);
inline std::string makeDepfile(const std::string& target, const std::vector<std::string>& deps) {
  return makeDepfile(std::vector<std::string>{target}, deps);
}

}  // namespace sg
