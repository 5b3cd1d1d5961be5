// shadergen CLI: thin argument handling over the library (generator/pipeline).
// Exit status: 0 success, 1 input error, 2 usage error.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <filesystem>
#include <iostream>

#include "cli/commands.h"
#include "common/diagnostics.h"

int main(int argc, char** argv) {
  // glslc spells depfile flags -MD/-MF; CLI11 only has one-letter short flags.
  std::vector<std::string> args(argv, argv + argc);
  for (auto& a : args)
    if (a == "-MD" || a == "-MF" || a == "-Werror") a = "-" + a;  // glslc spells -Werror with one dash too
  std::vector<char*> cargs;
  for (auto& a : args) cargs.push_back(a.data());

  CLI::App app{"shadergen: generates the cheapest vertex shader that feeds a fragment shader from a character rig"};
  app.set_version_flag("--version", std::string("shadergen ") + sg::shadergenVersionString());
  app.require_subcommand(1);
  sg::CliState state;
  state.commandLine = args;
  sg::registerCommands(app, state);
  try {
    app.parse(static_cast<int>(cargs.size()), cargs.data());
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // Usage errors: "shadergen: error: ..." like glslc, exit status 2.
    std::cerr << "shadergen: error: " << e.what() << "\nRun 'shadergen --help' or 'shadergen <command> --help' for usage.\n";
    return 2;
  }
  try {
    return state.run();
  } catch (const CLI::ParseError& e) {  // option values checked after parsing (--map, --emit)
    std::cerr << "shadergen: error: " << e.what() << "\n";
    return 2;
  } catch (const sg::InputError& e) {
    std::cerr << sg::renderDiagnostic(e.diagnostic()) << "\n";
    size_t shown = 0;
    for (const auto& d : e.related) {
      if (++shown > 20) break;
      std::cerr << sg::renderDiagnostic(d) << "\n";
    }
    return 1;
  } catch (const std::filesystem::filesystem_error& e) {
    // "path: error: No such file or directory", not the library's "filesystem error: ..."
    std::string where = e.path1().empty() ? "shadergen" : e.path1().string();
    std::cerr << sg::formatDiagnostic(sg::Diagnostic{sg::Severity::Error, {where, 0, 0}, e.code().message()}) << "\n";
    return 1;
  } catch (const std::bad_alloc&) {
    std::cerr << "shadergen: error: out of memory\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "shadergen: error: " << e.what() << "\n";
    return 1;
  }
}
