// Helpers shared by the core tests: temp directories and files.
#pragma once
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>

#include "common/diagnostics.h"

namespace sgtest {

// Runs `f` and returns the diagnostic of the InputError it throws; records a test failure
// (and returns an empty diagnostic) if it throws nothing or something else.
inline sg::Diagnostic errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const sg::InputError& e) {
    return e.diagnostic();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected sg::InputError, got another exception: " << e.what();
    return {};
  }
  ADD_FAILURE() << "expected sg::InputError, nothing was thrown";
  return {};
}

inline std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline void writeText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// A fresh directory per test (tests run as separate processes, possibly in parallel).
inline std::filesystem::path freshDir(const std::string& tag) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = std::string("sg_core_") + (info ? info->test_suite_name() : "x") + "_" +
                     (info ? info->name() : "x") + "_" + tag + "_" + std::to_string(::getpid());
  auto dir = std::filesystem::temp_directory_path() / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace sgtest
