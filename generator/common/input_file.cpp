#include "common/input_file.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "common/diagnostics.h"

namespace sg {

bool tryReadInputFile(const std::string& path, std::string& out, std::string* why) {
  auto no = [&](std::string msg) {
    if (why) *why = std::move(msg);
    return false;
  };
  if (path.empty()) return no("empty file name");
  // O_NONBLOCK: opening a FIFO without a writer must not wait; fstat then refuses it.
  int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
  if (fd < 0) return no(fmt::format("cannot open file: {}", std::strerror(errno)));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0) return no(fmt::format("cannot read file: {}", std::strerror(errno)));
  if (S_ISDIR(st.st_mode)) return no("is a directory, not a file");
  if (!S_ISREG(st.st_mode)) {
    const char* kind = S_ISFIFO(st.st_mode) ? "a FIFO" : S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) ? "a device"
                       : S_ISSOCK(st.st_mode)                                                         ? "a socket"
                                                                                                      : "not a regular file";
    return no(fmt::format("is {}; inputs must be regular files", kind));
  }
  if (st.st_size < 0 || static_cast<unsigned long long>(st.st_size) > kMaxInputBytes)
    return no(fmt::format("file is {} bytes, larger than the {} byte limit for inputs",
                          static_cast<long long>(st.st_size), kMaxInputBytes));
  out.clear();
  out.reserve(static_cast<size_t>(st.st_size));
  char buf[65536];
  for (;;) {
    ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return no(fmt::format("cannot read file: {}", std::strerror(errno)));
    if (n == 0) break;
    // A file that grows while read is still held to the limit.
    if (out.size() + static_cast<size_t>(n) > kMaxInputBytes)
      return no(fmt::format("file is larger than the {} byte limit for inputs", kMaxInputBytes));
    out.append(buf, static_cast<size_t>(n));
  }
  return true;
}

std::string readInputFile(const std::string& path) {
  std::string text, why;
  if (!tryReadInputFile(path, text, &why)) throw InputError(SourceLoc{path, 0, 0}, why);
  return text;
}

std::string inputFileLine(const std::string& path, int line) {
  std::string text;
  if (line <= 0 || !tryReadInputFile(path, text)) return "";
  size_t start = 0;
  for (int i = 1; i < line; ++i) {
    size_t nl = text.find('\n', start);
    if (nl == std::string::npos) return "";
    start = nl + 1;
  }
  size_t end = text.find('\n', start);
  std::string l = text.substr(start, end == std::string::npos ? std::string::npos : end - start);
  if (!l.empty() && l.back() == '\r') l.pop_back();
  return l;
}

}  // namespace sg
