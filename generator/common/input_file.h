// The one way every loader reads an input file: regular files only (a FIFO, a device such
// as /dev/zero or a directory is refused before any read, so nothing blocks or runs
// away), at most kMaxInputBytes, read in bounded chunks.
#pragma once
#include <cstddef>
#include <string>

namespace sg {

// Input files larger than this are rejected before parsing (docs/limits.md).
constexpr size_t kMaxInputBytes = 16u << 20;

// Reads a whole input file; throws InputError ("file: error: ...") if it is missing,
// not a regular file, unreadable or larger than kMaxInputBytes.
std::string readInputFile(const std::string& path);

// Same checks without throwing: false (and the reason in *why) if the file cannot be read.
bool tryReadInputFile(const std::string& path, std::string& out, std::string* why = nullptr);

// Line `line` (1-based) of a file, without its end of line; "" if unreadable or absent.
// Used to quote source lines in diagnostics, so it never blocks or reads without bound.
std::string inputFileLine(const std::string& path, int line);

}  // namespace sg
