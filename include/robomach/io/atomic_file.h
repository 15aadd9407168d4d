#pragma once

#include <functional>
#include <memory>
#include <ostream>
#include <string>
#include <string_view>

namespace robomach::io {

/// Writes a file completely or not at all (docs/formats.md §4, "Outputs"):
/// the content goes to a temporary file in the same directory, which is
/// flushed and fsync'ed, then renamed over `path`, and the directory is
/// fsync'ed, so the file survives a power loss whole or not at all. On any
/// failure the temporary file is removed and OutputError is thrown; an
/// exception thrown by `write` removes it too and propagates.
///
/// `path` "-" means standard output.
///
/// While an OutputRun is active (see below), the file is only staged: it is
/// written and fsync'ed under a temporary name and renamed into place by
/// OutputRun::Commit together with every other output of the run.
void WriteFileAtomically(const std::string& path,
                         const std::function<void(std::ostream&)>& write);
void WriteFileAtomically(const std::string& path, std::string_view content);

/// Creates a directory (and its parents) if it does not exist. While an
/// OutputRun is active, the directories this call creates belong to the run:
/// a run that does not commit removes them again (when empty).
/// @throws OutputError if that fails.
void EnsureDirectory(const std::string& path);

/// fsync(2) of a file's data, and of a directory (so that a rename or a new
/// entry in it is durable). @throws OutputError naming the path and errno.
void SyncFile(const std::string& path);
void SyncDirectory(const std::string& path);

/// All-or-nothing outputs of one run (issue 22): either every output of the
/// run appears, or none does.
///
///   io::OutputRun run;               // becomes the active run
///   io::WriteFileAtomically(a, ...); // staged: .a.robomach-<pid>-<n>.tmp, fsync'ed
///   io::WriteFileAtomically(b, ...); // staged
///   io::WriteFileAtomically("-", text);  // kept in memory for stdout
///   run.Commit();                    // renames a and b into place, fsyncs
///                                    // their directories, then prints "-"
///
/// Every output that goes through WriteFileAtomically (the io and report
/// writers, PNG pictures, JSON summaries) registers itself with the active
/// run; nothing else needs to know about staging. If the run is destroyed
/// without Commit (an exception, an error exit) or Commit fails, every
/// staged file and every directory the run created (if left empty) is
/// removed: no output of the run appears, and nothing is printed on stdout.
///
/// Commit first checks that no target is a directory, then renames the
/// staged files one by one; a target that already exists is kept as a hard
/// link until the end, so a rename that still fails puts back the earlier
/// targets' previous contents (or removes them if they are new). Standard
/// output is written last and flushed; if that fails the renamed files are
/// rolled back in the same way. On a file system without hard links, an
/// earlier target that existed keeps the new content after such a failure.
///
/// At most one run is active at a time (the command-line tools make one per
/// process, in apps/cli_support RunGuarded). Writes from several threads are
/// serialised.
class OutputRun {
 public:
  OutputRun();
  ~OutputRun();
  OutputRun(const OutputRun&) = delete;
  OutputRun& operator=(const OutputRun&) = delete;

  /// Puts every staged output into place (see above); the run ends, and
  /// later writes are no longer staged. A second call does nothing.
  /// @throws OutputError; then nothing of the run remains.
  void Commit();
  /// Removes every staged file and created directory; the run ends.
  void Discard();

  /// Number of outputs staged so far ("-" counts once per write).
  int staged_count() const;

  /// The active run, or nullptr.
  static OutputRun* Active();

  /// Internal: the staging state, for WriteFileAtomically and
  /// EnsureDirectory (called with the run's lock held).
  struct State;
  State* state_for_writers();

 private:
  std::unique_ptr<State> state_;
};

}  // namespace robomach::io
