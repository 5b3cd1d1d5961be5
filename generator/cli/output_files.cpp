#include "cli/output_files.h"

#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace sg {

void writeFilesAtomically(const std::vector<PendingFile>& files) {
  std::vector<std::string> temps;
  auto cleanup = [&] {
    for (const auto& t : temps) std::remove(t.c_str());
  };
  for (const auto& f : files) {
    std::filesystem::path p(f.path);
    std::error_code ec;
    if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path(), ec);
    std::string tmp = fmt::format("{}.tmp.{}", f.path, getpid());
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) {
      cleanup();
      throw std::runtime_error(fmt::format("{}: error: cannot write: {}", f.path, std::strerror(errno)));
    }
    temps.push_back(tmp);
    out.write(f.contents.data(), static_cast<std::streamsize>(f.contents.size()));
    out.close();
    if (!out) {
      cleanup();
      throw std::runtime_error(fmt::format("{}: error: write failed", f.path));
    }
  }
  for (size_t i = 0; i < files.size(); ++i)
    if (std::rename(temps[i].c_str(), files[i].path.c_str()) != 0) {
      cleanup();
      throw std::runtime_error(fmt::format("{}: error: cannot rename into place: {}", files[i].path, std::strerror(errno)));
    }
}

std::string makeDepfile(const std::string& target, const std::vector<std::string>& deps) {
  auto esc = [](const std::string& s) {
    std::string o;
    for (char c : s) {
      if (c == ' ' || c == '#') o += '\\';
      if (c == '$') o += '$';
      o += c;
    }
    return o;
  };
  std::string out = esc(target) + ":";
  for (const auto& d : deps) out += " \\\n  " + esc(d);
  return out + "\n";
}

}  // namespace sg
