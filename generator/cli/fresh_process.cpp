#include "cli/fresh_process.h"

#include <fmt/format.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include "cli/output_files.h"
#include "common/diagnostics.h"
#include "common/input_file.h"
#include "measure/bench_report_json.h"

extern char** environ;

namespace sg {

GpuBenchReport benchInFreshProcess(const std::vector<std::string>& commandLine, const std::vector<std::string>& extra,
                                   const std::string& what, bool finishOnInterrupt) {
  static std::atomic<unsigned> serial{0};
  const std::string report =
      (std::filesystem::temp_directory_path() / fmt::format("shadergen-rig-{}-{}.json", ::getpid(), serial++)).string();
  std::vector<std::string> args = commandLine;
  args.insert(args.end(), {"--child-report", report});
  args.insert(args.end(), extra.begin(), extra.end());
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  if (finishOnInterrupt) {
    sigset_t blocked;
    sigemptyset(&blocked);
    sigaddset(&blocked, SIGINT);
    posix_spawnattr_setsigmask(&attr, &blocked);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK);
  }
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, "/proc/self/exe", nullptr, &attr, argv.data(), environ);
  posix_spawnattr_destroy(&attr);
  if (spawned != 0)
    throw std::runtime_error(fmt::format("cannot start a process to time {}: {}", what, std::strerror(spawned)));
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) throw std::runtime_error(fmt::format("lost the process timing {}: {}", what, std::strerror(errno)));
  std::string text;
  std::error_code ec;
  if (std::filesystem::exists(report, ec)) {
    text = readInputFile(report);
    std::filesystem::remove(report, ec);
  }
  if (text.empty()) {
    const std::string how = WIFSIGNALED(status) ? fmt::format("was ended by signal {}", WTERMSIG(status))
                                                : fmt::format("exited with status {}", WEXITSTATUS(status));
    throw std::runtime_error(fmt::format("the process timing {} {} without a report", what, how));
  }
  return benchReportFromJson(text);  // an InputError the child wrote is thrown from here
}

GpuBenchReport benchInFreshProcesses(const std::vector<std::string>& commandLine, const std::vector<std::string>& extra,
                                     const std::string& what, bool finishOnInterrupt, uint32_t processes,
                                     const std::atomic<bool>* stop) {
  std::vector<GpuBenchReport> runs{benchInFreshProcess(commandLine, extra, what, finishOnInterrupt)};
  while (runs.size() < processes && !(stop && stop->load())) runs.push_back(benchInFreshProcess(commandLine, extra, what, finishOnInterrupt));
  return runs.size() == 1 ? runs.front() : mergeProcessRuns(runs);
}

void writeFreshProcessReport(const std::string& path, const std::function<GpuBenchReport()>& time) {
  std::string text;
  try {
    text = benchReportJson(time());
  } catch (const InputError& e) {
    text = inputErrorJson(e);
  }
  writeFilesAtomically({{path, text}});
}

}  // namespace sg
