// Writing outputs the way build tools need: all-or-nothing (temp file + rename),
// and Makefile depfiles listing every input read.
#pragma once
#include "emit/depfile.h"  // makeDepfile, for the commands that write outputs
#include <string>
#include <vector>

namespace sg {

struct PendingFile {
  std::string path;
  std::string contents;
};

// Writes every file to "<path>.tmp.<pid>" first, then renames them all into place. If any
// write or rename fails, existing outputs are left (or put back) as they were, new ones are
// removed, and no temporary (nor a directory this call created) is left behind. Throws
// std::runtime_error naming the file.
void writeFilesAtomically(const std::vector<PendingFile>& files);

// Refuses (throws InputError) before anything is written: an output that resolves to one
// of `inputs` (same path after resolving links and '..', or the same inode), two outputs
// naming one file, and an output that exists but is not a regular file (a device, a FIFO:
// renaming over it would replace it). `what` names each input in the message.
struct InputFile {
  std::string path;
  std::string what;  // "the rig", "a rules file", ...
};
void refuseClobbering(const std::vector<std::string>& outputs, const std::vector<InputFile>& inputs);

}  // namespace sg
