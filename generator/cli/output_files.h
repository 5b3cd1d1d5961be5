// Writing outputs the way build tools need: all-or-nothing (temp file + rename),
// and Makefile depfiles listing every input read.
#pragma once
#include <string>
#include <vector>

namespace sg {

struct PendingFile {
  std::string path;
  std::string contents;
};

// Writes every file to "<path>.tmp.<pid>" first, then renames them all. If any write
// fails, removes the temporaries and leaves existing outputs untouched. Throws
// std::runtime_error naming the file.
void writeFilesAtomically(const std::vector<PendingFile>& files);

// "target: dep1 dep2 ..." with spaces escaped (Make/Ninja syntax).
std::string makeDepfile(const std::string& target, const std::vector<std::string>& deps);

}  // namespace sg
