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
                                   const std::string& what) {
  static std::atomic<unsigned> serial{0};
  const std::string report =
      (std::filesystem::temp_directory_path() / fmt::format("shadergen-rig-{}-{}.json", ::getpid(), serial++)).string();
  std::vector<std::string> args = commandLine;
  args.insert(args.end(), {"--child-report", report});
  args.insert(args.end(), extra.begin(), extra.end());
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (int e = posix_spawn(&pid, "/proc/self/exe", nullptr, nullptr, argv.data(), environ); e != 0)
    throw std::runtime_error(fmt::format("shadergen: cannot start a process to time {}: {}", what, std::strerror(e)));
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) throw std::runtime_error(fmt::format("shadergen: lost the process timing {}: {}", what, std::strerror(errno)));
  std::string text;
  std::error_code ec;
  if (std::filesystem::exists(report, ec)) {
    text = readInputFile(report);
    std::filesystem::remove(report, ec);
  }
  if (text.empty()) {
    const std::string how = WIFSIGNALED(status) ? fmt::format("was ended by signal {}", WTERMSIG(status))
                                                : fmt::format("exited with status {}", WEXITSTATUS(status));
    throw std::runtime_error(fmt::format("shadergen: the process timing {} {} without a report", what, how));
  }
  return benchReportFromJson(text);  // an InputError the child wrote is thrown from here
}

void writeFreshProcessReport(const std::string& path, const std::function<GpuBenchReport()>& time) {
  std::signal(SIGINT, SIG_IGN);
  std::string text;
  try {
    text = benchReportJson(time());
  } catch (const InputError& e) {
    text = inputErrorJson(e);
  }
  writeFilesAtomically({{path, text}});
}

}  // namespace sg
