#include "robomach/io/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cassert>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <set>
#include <sstream>
#include <vector>

#include "robomach/common/errors.h"

namespace robomach::io {

namespace fs = std::filesystem;

namespace {

std::string Errno() { return std::strerror(errno); }

fs::path DirectoryOf(const fs::path& target) {
  return target.has_parent_path() ? target.parent_path() : fs::path(".");
}

// Writes `write`'s bytes to `tmp` and fsyncs them; removes `tmp` on failure.
void WriteAndSync(const std::string& path, const fs::path& tmp,
                  const std::function<void(std::ostream&)>& write) {
  try {
    {
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      if (!out) {
        throw OutputError(path + ": cannot create temporary file '" + tmp.string() + "': " + Errno());
      }
      write(out);
      out.flush();
      if (!out) throw OutputError(path + ": write failed: " + Errno());
    }
    SyncFile(tmp.string());
  } catch (...) {
    std::error_code ignore;
    fs::remove(tmp, ignore);
    throw;
  }
}

void RequireDirectory(const std::string& path, const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    if (fs::exists(dir, ec)) {
      throw OutputError(path + ": cannot write: '" + dir.string() + "' is not a directory");
    }
    throw OutputError(path + ": cannot write: directory '" + dir.string() + "' does not exist");
  }
  if (fs::is_directory(path, ec)) {
    throw OutputError(path + ": cannot write: a directory of that name exists");
  }
}

std::mutex g_mutex;                // guards g_active and the active run's state
OutputRun* g_active = nullptr;

}  // namespace

struct OutputRun::State {
  struct Staged {
    fs::path target, tmp;
  };
  std::vector<Staged> files;        // in the order of writing; a re-written target replaces its entry
  std::string stdout_text;          // the "-" outputs, concatenated
  int stdout_writes = 0;
  std::vector<fs::path> created_dirs;  // by EnsureDirectory, outermost first
  int serial = 0;
  bool done = false;

  fs::path TempFor(const fs::path& target) {
    return DirectoryOf(target) /
           ("." + target.filename().string() + ".robomach-" + std::to_string(::getpid()) + "-" +
            std::to_string(++serial) + ".tmp");
  }
  void RemoveAll() {
    std::error_code ignore;
    for (const Staged& s : files) fs::remove(s.tmp, ignore);
    files.clear();
    stdout_text.clear();
    for (auto it = created_dirs.rbegin(); it != created_dirs.rend(); ++it) {
      fs::remove(*it, ignore);  // only removes an empty directory
    }
    created_dirs.clear();
    done = true;
  }
};

void SyncFile(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw OutputError(path + ": cannot open for fsync: " + Errno());
  const int rc = ::fsync(fd);
  const std::string err = rc != 0 ? Errno() : "";
  ::close(fd);
  if (rc != 0) throw OutputError(path + ": fsync failed: " + err);
}

void SyncDirectory(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) throw OutputError(path + ": cannot open directory for fsync: " + Errno());
  const int rc = ::fsync(fd);
  const std::string err = rc != 0 ? Errno() : "";
  ::close(fd);
  // Some file systems do not support fsync on a directory (EINVAL); their
  // renames are as durable as they can be made.
  if (rc != 0 && err != std::strerror(EINVAL)) throw OutputError(path + ": fsync of the directory failed: " + err);
}

void WriteFileAtomically(const std::string& path,
                         const std::function<void(std::ostream&)>& write) {
  std::unique_lock<std::mutex> lock(g_mutex);
  OutputRun* run = g_active;
  if (path == "-") {
    if (run == nullptr) {
      lock.unlock();
      std::ostringstream text;
      write(text);
      std::cout << text.str();
      std::cout.flush();
      if (!std::cout) throw OutputError("cannot write to standard output");
      return;
    }
    lock.unlock();
    std::ostringstream text;
    write(text);  // outside the lock: a writer may take long
    lock.lock();
    if (g_active != run) throw OutputError("-: the output run ended while writing");
    // A run that is active is owned by the caller's scope; its state is ours.
    OutputRun::State* st = run->state_for_writers();
    st->stdout_text += text.str();
    ++st->stdout_writes;
    return;
  }
  const fs::path target(path);
  const fs::path dir = DirectoryOf(target);
  RequireDirectory(path, dir);
  if (run == nullptr) {
    lock.unlock();
    const fs::path tmp = dir / ("." + target.filename().string() + ".tmp" + std::to_string(::getpid()));
    WriteAndSync(path, tmp, write);
    std::error_code ec;
    fs::rename(tmp, target, ec);
    if (ec) {
      std::error_code ignore;
      fs::remove(tmp, ignore);
      throw OutputError(path + ": cannot rename temporary file into place: " + ec.message());
    }
    SyncDirectory(dir.string());
    return;
  }
  OutputRun::State* st = run->state_for_writers();
  const fs::path tmp = st->TempFor(target);
  lock.unlock();
  WriteAndSync(path, tmp, write);
  lock.lock();
  if (g_active != run) {
    std::error_code ignore;
    fs::remove(tmp, ignore);
    throw OutputError(path + ": the output run ended while writing");
  }
  for (auto& s : st->files) {
    std::error_code ec;
    if (s.target == target || fs::equivalent(s.target, target, ec)) {  // written twice: the later wins
      std::error_code ignore;
      fs::remove(s.tmp, ignore);
      s.tmp = tmp;
      return;
    }
  }
  st->files.push_back({target, tmp});
}

void WriteFileAtomically(const std::string& path, std::string_view content) {
  WriteFileAtomically(path, [&](std::ostream& out) { out.write(content.data(), content.size()); });
}

void EnsureDirectory(const std::string& path) {
  std::vector<fs::path> missing;  // innermost first
  {
    std::error_code ec;
    for (fs::path p = fs::absolute(path, ec).lexically_normal(); !p.empty() && !fs::exists(p, ec);
         p = p.parent_path()) {
      missing.push_back(p);
      if (p == p.parent_path()) break;
    }
  }
  std::error_code ec;
  fs::create_directories(path, ec);
  if (ec || !fs::is_directory(path)) {
    throw OutputError(path + ": cannot create directory: " +
                      (ec ? ec.message() : std::string("a file of that name exists")));
  }
  std::lock_guard<std::mutex> lock(g_mutex);
  if (g_active != nullptr) {
    OutputRun::State* st = g_active->state_for_writers();
    for (auto it = missing.rbegin(); it != missing.rend(); ++it) st->created_dirs.push_back(*it);
  }
}

OutputRun::OutputRun() : state_(std::make_unique<State>()) {
  std::lock_guard<std::mutex> lock(g_mutex);
  assert(g_active == nullptr && "only one OutputRun may be active at a time");
  g_active = this;
}

OutputRun::~OutputRun() {
  if (!state_->done) Discard();
  std::lock_guard<std::mutex> lock(g_mutex);
  if (g_active == this) g_active = nullptr;
}

OutputRun* OutputRun::Active() {
  std::lock_guard<std::mutex> lock(g_mutex);
  return g_active;
}

int OutputRun::staged_count() const {
  std::lock_guard<std::mutex> lock(g_mutex);
  return static_cast<int>(state_->files.size()) + state_->stdout_writes;
}

OutputRun::State* OutputRun::state_for_writers() { return state_.get(); }

void OutputRun::Discard() {
  std::lock_guard<std::mutex> lock(g_mutex);
  state_->RemoveAll();
  if (g_active == this) g_active = nullptr;
}

void OutputRun::Commit() {
  std::lock_guard<std::mutex> lock(g_mutex);
  if (state_->done) return;  // committed (or discarded) already
  State& st = *state_;
  if (g_active == this) g_active = nullptr;  // later writes are no longer staged
  struct Placed {
    fs::path target, backup;  // backup empty: the target did not exist before
  };
  std::vector<Placed> placed;
  auto roll_back = [&] {
    std::error_code ignore;
    for (auto it = placed.rbegin(); it != placed.rend(); ++it) {
      if (it->backup.empty()) fs::remove(it->target, ignore);
      else fs::rename(it->backup, it->target, ignore);
    }
    st.RemoveAll();
  };
  try {
    // A directory where a file must go fails every rename: find it first.
    for (const auto& s : st.files) {
      std::error_code ec;
      if (fs::is_directory(s.target, ec)) {
        throw OutputError(s.target.string() + ": cannot write: a directory of that name exists");
      }
    }
    std::set<std::string> dirs;
    for (const auto& s : st.files) {
      Placed p{s.target, {}};
      std::error_code ec;
      if (fs::exists(fs::symlink_status(s.target, ec))) {
        // Keep the previous content until the whole run is in place.
        fs::path backup = s.tmp;
        backup.replace_extension(".old");
        if (::link(s.target.c_str(), backup.c_str()) == 0) p.backup = backup;
      }
      fs::rename(s.tmp, s.target, ec);
      if (ec) {
        if (!p.backup.empty()) fs::remove(p.backup, ec);
        throw OutputError(s.target.string() + ": cannot rename the staged file into place: " + ec.message());
      }
      placed.push_back(p);
      dirs.insert(DirectoryOf(s.target).string());
    }
    for (const fs::path& d : st.created_dirs) dirs.insert(DirectoryOf(d).string());
    for (const std::string& d : dirs) SyncDirectory(d);
    if (!st.stdout_text.empty()) {
      std::cout << st.stdout_text;
      std::cout.flush();
      if (!std::cout) throw OutputError("cannot write the results to standard output");
    }
  } catch (...) {
    roll_back();
    throw;
  }
  std::error_code ignore;
  for (const Placed& p : placed) {
    if (!p.backup.empty()) fs::remove(p.backup, ignore);
  }
  st.files.clear();
  st.created_dirs.clear();
  st.stdout_text.clear();
  st.done = true;
}

}  // namespace robomach::io
