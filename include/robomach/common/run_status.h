#pragma once
// How a workflow of the library ended (issue #21: every workflow returns a
// Result with a status; Ceres' Solver::Summary is the model). A workflow
// that cannot run throws (InputError, std::invalid_argument, ...); one that
// ran returns its best answer with a status:
//   kOk       every check the workflow makes passed;
//   kFlagged  the result is there but doubtful, and its `verdict.findings`
//             (RunFindings below) say why, one sentence each (a posture
//             outside its joint limits, a fit that misses the data, a value
//             in an implausible unit, ...).
// The tools print each finding as a warning and exit 3 when flagged
// (apps/cli_support: ExitCodeFor).
#include <string>
#include <vector>

namespace robomach {

enum class RunStatus { kOk, kFlagged };

/// "ok", "flagged": the spelling of the tools' summaries and of Python.
const char* ToString(RunStatus s);
/// The inverse of ToString. @throws std::invalid_argument naming the two.
RunStatus ParseRunStatus(const std::string& name);

/// One reason a result is flagged.
struct Finding {
  std::string message;
  /// The input row it concerns (a posture of the posture file, ...), 0-based;
  /// -1 when it concerns the run as a whole. Callers that know where the row
  /// came from put the file and line in front of the message.
  int input_index{-1};
};

/// The verdict on a result: its findings and so its status. The one way to
/// carry findings (issue #36): a verdict is a value. A result that can be
/// flagged holds it as a member `RunFindings verdict;` (never as a base), with
/// `status()` forwarding to `verdict.status()` for its callers; a Judge*()
/// function returns a RunFindings, which the workflow stores in its
/// `verdict`. Code adds a finding with `result.verdict.Flag(...)` and reads
/// them in `result.verdict.findings`.
struct RunFindings {
  std::vector<Finding> findings;

  void Flag(std::string message, int input_index = -1) { findings.push_back({std::move(message), input_index}); }
  RunStatus status() const { return findings.empty() ? RunStatus::kOk : RunStatus::kFlagged; }
  bool flagged() const { return !findings.empty(); }
};

}  // namespace robomach
