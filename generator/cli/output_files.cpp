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
  namespace fs = std::filesystem;
  const int pid = static_cast<int>(getpid());
  std::vector<std::string> temps;
  auto removeTemps = [&] {
    for (const auto& t : temps) std::remove(t.c_str());
  };
  // 1. Every new file goes to "<path>.tmp.<pid>" next to its destination.
  for (const auto& f : files) {
    fs::path p(f.path);
    std::error_code ec;
    if (p.has_parent_path()) fs::create_directories(p.parent_path(), ec);
    std::string tmp = fmt::format("{}.tmp.{}", f.path, pid);
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) {
      int err = errno;
      removeTemps();
      throw std::runtime_error(fmt::format("cannot write '{}': {}", f.path, std::strerror(err)));
    }
    temps.push_back(tmp);
    out.write(f.contents.data(), static_cast<std::streamsize>(f.contents.size()));
    out.close();
    if (!out) {
      removeTemps();
      throw std::runtime_error(fmt::format("cannot write '{}': write failed", f.path));
    }
  }
  // 2. Keep a hard link (or copy) of every existing output, so that if a later rename
  //    fails the ones already replaced can be put back: all outputs change, or none.
  std::vector<std::string> backups(files.size());
  auto removeBackups = [&] {
    for (const auto& b : backups)
      if (!b.empty()) std::remove(b.c_str());
  };
  for (size_t i = 0; i < files.size(); ++i) {
    std::error_code ec;
    if (!fs::is_regular_file(files[i].path, ec)) continue;
    std::string bak = fmt::format("{}.bak.{}", files[i].path, pid);
    fs::remove(bak, ec);
    fs::create_hard_link(files[i].path, bak, ec);
    if (ec) fs::copy_file(files[i].path, bak, fs::copy_options::overwrite_existing, ec);
    if (ec) {
      removeTemps();
      removeBackups();
      throw std::runtime_error(fmt::format("cannot write '{}': {}", files[i].path, ec.message()));
    }
    backups[i] = bak;
  }
  // 3. Rename into place (atomic per file).
  for (size_t i = 0; i < files.size(); ++i) {
    if (std::rename(temps[i].c_str(), files[i].path.c_str()) == 0) continue;
    int err = errno;
    for (size_t j = 0; j < i; ++j) {
      if (!backups[j].empty()) {
        std::rename(backups[j].c_str(), files[j].path.c_str());
        backups[j].clear();
      } else {
        std::remove(files[j].path.c_str());  // did not exist before this run
      }
    }
    removeTemps();
    removeBackups();
    throw std::runtime_error(fmt::format("cannot write '{}': {}", files[i].path, std::strerror(err)));
  }
  removeBackups();
}

std::string makeDepfile(const std::vector<std::string>& targets, const std::vector<std::string>& deps) {
  auto esc = [](const std::string& s) {
    std::string o;
    for (char c : s) {
      if (c == ' ' || c == '#') o += '\\';
      if (c == '$') o += '$';
      o += c;
    }
    return o;
  };
  std::string out;
  for (const auto& t : targets) out += (out.empty() ? "" : " ") + esc(t);
  out += ":";
  for (const auto& d : deps) out += " \\\n  " + esc(d);
  return out + "\n";
}

}  // namespace sg
