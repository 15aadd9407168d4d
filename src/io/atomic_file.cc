#include "robomach/io/atomic_file.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "robomach/common/errors.h"

namespace robomach::io {

void WriteFileAtomically(const std::string& path,
                         const std::function<void(std::ostream&)>& write) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (!fs::is_directory(dir)) {
    throw OutputError(path + ": cannot write: directory '" + dir.string() + "' does not exist");
  }
  const fs::path tmp =
      dir / ("." + target.filename().string() + ".tmp" + std::to_string(::getpid()));
  try {
    {
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      if (!out) {
        throw OutputError(path + ": cannot create temporary file '" + tmp.string() +
                          "': " + std::strerror(errno));
      }
      write(out);
      out.flush();
      if (!out) throw OutputError(path + ": write failed: " + std::strerror(errno));
    }
    std::error_code ec;
    fs::rename(tmp, target, ec);
    if (ec) throw OutputError(path + ": cannot rename temporary file into place: " + ec.message());
  } catch (...) {
    std::error_code ignore;
    fs::remove(tmp, ignore);
    throw;
  }
}

void WriteFileAtomically(const std::string& path, std::string_view content) {
  WriteFileAtomically(path, [&](std::ostream& out) { out.write(content.data(), content.size()); });
}

void EnsureDirectory(const std::string& path) {
  std::error_code ec;
  std::filesystem::create_directories(path, ec);
  if (ec || !std::filesystem::is_directory(path)) {
    throw OutputError(path + ": cannot create directory: " + ec.message());
  }
}

}  // namespace robomach::io
