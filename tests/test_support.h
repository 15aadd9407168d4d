#pragma once

// Helpers shared by the tests: paths to the source tree and a scratch folder,
// and capture of an exception's message.

#include <filesystem>
#include <functional>
#include <string>

namespace robomach::testing {

inline std::string SourcePath(const std::string& relative) {
  return std::string(ROBOMACH_SOURCE_DIR) + "/" + relative;
}

/// A fresh scratch folder for one test.
inline std::string TempDir(const std::string& name) {
  const std::filesystem::path p = std::filesystem::path(ROBOMACH_TEST_TMP_DIR) / name;
  std::filesystem::remove_all(p);
  std::filesystem::create_directories(p);
  return p.string();
}

inline std::string WriteText(const std::string& path, const std::string& text);

/// The what() of the exception `f` throws, or "" if it throws none.
inline std::string CaptureError(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

}  // namespace robomach::testing

#include <fstream>
inline std::string robomach::testing::WriteText(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
  return path;
}
