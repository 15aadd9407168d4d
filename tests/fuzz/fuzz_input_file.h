#pragma once

// The readers take a path: each fuzz input is written to a private scratch
// file first (the harnesses run one input at a time per process).
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace robomach::fuzz {

/// Writes `data` to a per-process scratch file with the given extension
/// (the readers dispatch on it) and returns its path.
inline std::string WriteInput(const uint8_t* data, size_t size, const std::string& extension) {
  static const std::string path =
      (std::filesystem::temp_directory_path() / ("robomach-fuzz-" + std::to_string(::getpid()) + extension)).string();
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

}  // namespace robomach::fuzz
