#include "cli/output_files.h"

#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "common/diagnostics.h"

namespace sg {

namespace {

// The file a path names: resolved links and '..' (parents that do not exist yet are kept
// lexically), and its inode when it exists.
struct Identity {
  std::string path;
  bool exists = false;
  dev_t dev = 0;
  ino_t ino = 0;
};
Identity identify(const std::string& p) {
  Identity id;
  std::error_code ec;
  std::filesystem::path abs = std::filesystem::weakly_canonical(std::filesystem::absolute(p, ec), ec);
  id.path = ec ? std::filesystem::path(p).lexically_normal().string() : abs.string();
  struct stat st {};
  if (::stat(p.c_str(), &st) == 0) {
    id.exists = true;
    id.dev = st.st_dev;
    id.ino = st.st_ino;
  }
  return id;
}
bool same(const Identity& a, const Identity& b) {
  return a.path == b.path || (a.exists && b.exists && a.dev == b.dev && a.ino == b.ino);
}

}  // namespace

void refuseClobbering(const std::vector<std::string>& outputs, const std::vector<InputFile>& inputs) {
  std::vector<Identity> ins;
  for (const auto& i : inputs) ins.push_back(identify(i.path));
  std::vector<Identity> outs;
  for (const auto& o : outputs) {
    Identity id = identify(o);
    for (size_t i = 0; i < ins.size(); ++i)
      if (same(id, ins[i]))
        throw InputError(SourceLoc{},
                         fmt::format("output '{}' is {} ('{}'); refusing to overwrite an input", o, inputs[i].what,
                                     inputs[i].path));
    for (size_t j = 0; j < outs.size(); ++j)
      if (same(id, outs[j]))
        throw InputError(SourceLoc{}, fmt::format("outputs '{}' and '{}' are the same file", outputs[j], o));
    struct stat st {};
    if (::stat(o.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
      throw InputError(SourceLoc{}, fmt::format("output '{}' exists and is not a regular file ({})", o,
                                                S_ISDIR(st.st_mode) ? "a directory" : "a device, FIFO or socket"));
    outs.push_back(id);
  }
}

void writeFilesAtomically(const std::vector<PendingFile>& files) {
  namespace fs = std::filesystem;
  const int pid = static_cast<int>(getpid());
  std::vector<std::string> temps;
  std::vector<fs::path> createdDirs;  // parents first; removed again (when empty) on failure
  auto removeTemps = [&] {
    for (const auto& t : temps) std::remove(t.c_str());
    for (auto d = createdDirs.rbegin(); d != createdDirs.rend(); ++d) {
      std::error_code ec;
      fs::remove(*d, ec);  // only an empty directory: one this run created
    }
  };
  // 1. Every new file goes to "<path>.tmp.<pid>" next to its destination.
  for (const auto& f : files) {
    fs::path p(f.path);
    std::error_code ec;
    std::vector<fs::path> missing;
    for (fs::path d = p.parent_path(); !d.empty() && !fs::exists(d, ec); d = d.parent_path()) missing.push_back(d);
    createdDirs.insert(createdDirs.end(), missing.rbegin(), missing.rend());
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

}  // namespace sg
