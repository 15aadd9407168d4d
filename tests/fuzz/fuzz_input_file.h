#pragma once

// The readers take a path: each fuzz input is written to a private scratch
// file first (the harnesses run one input at a time per process), in memory
// (/dev/shm) where there is one: on a busy disk, truncating a file in /tmp
// now and then blocked for over a second, a false hang under -timeout=1.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

namespace robomach::fuzz {

/// Writes `data` to a per-process scratch file with the given extension
/// (the readers dispatch on it) and returns its path.
inline std::string WriteInput(const uint8_t* data, size_t size, const std::string& extension) {
  static const std::string stem = [] {
    std::error_code ec;
    const std::filesystem::path dir =
        std::filesystem::is_directory("/dev/shm", ec) ? std::filesystem::path("/dev/shm") : std::filesystem::temp_directory_path();
    return (dir / ("robomach-fuzz-" + std::to_string(::getpid()))).string();
  }();
  const std::string path = stem + extension;  // one file per extension
  // Removed when the process ends normally.
  static struct Scratch {
    std::set<std::string> paths;
    ~Scratch() {
      std::error_code ec;
      for (const std::string& p : paths) std::filesystem::remove(p, ec);
    }
  } scratch;
  scratch.paths.insert(path);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

/// Called with each rejected input's error: prints it when the environment
/// has ROBOMACH_FUZZ_PRINT (to triage an input: the fuzzer or the replay
/// executable with the input's path as argument).
inline void Rejected(const std::exception& e) {
  static const bool print = std::getenv("ROBOMACH_FUZZ_PRINT") != nullptr;
  if (print) std::fprintf(stderr, "rejected: %s\n", e.what());
}

}  // namespace robomach::fuzz
