#pragma once

// Shared by the command-line tools: exit codes (style.md §2.13), the error
// boundary, progress lines and small parsing helpers. CLI11 stays out of
// this header so that only each app's own file pays its compile time.

#include <chrono>
#include <functional>
#include <map>
#include <optional>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "robomach/common/errors.h"
#include "robomach/common/messages.h"
#include "robomach/common/option_checks.h"
#include "robomach/common/run_status.h"
#include "robomach/dynamics/uncertainty.h"
#include "robomach/io/file_kind.h"
#include "robomach/io/robot_config.h"

namespace CLI {
class App;
class Validator;
}  // namespace CLI
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

namespace robomach::apps {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFlagged = 3;     // outputs written, result flagged
inline constexpr int kExitUsage = 64;      // EX_USAGE
inline constexpr int kExitDataError = 65;  // EX_DATAERR
inline constexpr int kExitNoInput = 66;    // EX_NOINPUT
inline constexpr int kExitSoftware = 70;   // EX_SOFTWARE
inline constexpr int kExitCantCreate = 73; // EX_CANTCREAT

/// kExitOk for RunStatus::kOk, kExitFlagged for kFlagged.
inline int ExitCodeFor(RunStatus s) { return s == RunStatus::kOk ? kExitOk : kExitFlagged; }

/// The exit-code table for --help footers.
std::string ExitCodeHelp();

/// A bad command line: an option's value, a missing option, options that
/// exclude each other. The only exception RunGuarded maps to exit 64.
class UsageError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Runs `parse` on an option's value (a library parser or check): its
/// std::invalid_argument becomes a UsageError naming the option (exit 64).
template <class F>
auto FromOption(const std::string& option, F&& parse) -> decltype(parse()) {
  try {
    return parse();
  } catch (const UsageError&) {
    throw;
  } catch (const std::invalid_argument& e) {
    throw UsageError(option + ": " + e.what());
  }
}

/// Where a field of a library options struct got its value, for
/// ValidateOptions: the command-line option ("--fmax-hz"), or an input file's
/// key with its place ("kr210.yaml:70:19: hammer_test.sample_rate_hz").
struct FieldSource {
  std::string field;         // as the library's messages name it: "fmax_hz"
  std::string name;          // what the user typed: "--fmax-hz"
  bool from_input{false};    // the value came from an input file, not the command line
};

/// Runs a library options check (`o.Validate()`, ...): the
/// one mechanism by which the tools validate their options. The library's
/// std::invalid_argument names the failing field first ("VirtualHammerOptions:
/// fmax_hz 500000: above the Nyquist frequency 2560 Hz of sample_rate_hz
/// 5120"); the struct's name is dropped and every field of `fields` is
/// written as its option ("--fmax-hz 500000: above the Nyquist frequency
/// 2560 Hz of --sample-rate-hz 5120"). The first field named decides: an
/// option makes it a UsageError (exit 64), an input file's key a
/// std::invalid_argument (bad input, 65, with the file's place). A message
/// that names none of `fields` is passed on as it came.
void ValidateOptions(const std::vector<FieldSource>& fields, const std::function<void()>& check);

/// Runs a library call and names its OptionError's fields as `fields` say
/// (ValidateOptions' mapping: "sets m6_kg=x: ..." -> "--set m6_kg=x: ...",
/// exit 64). Every other exception passes unchanged (a file's InputError
/// stays 65).
template <class F>
auto FromFields(const std::vector<FieldSource>& fields, F&& body) -> decltype(body()) {
  try {
    return body();
  } catch (const OptionError&) {
    ValidateOptions(fields, [] { throw; });
    throw;
  }
}

/// Runs `body` and maps exceptions to exit codes with one message on stderr
/// prefixed by the tool name: UsageError -> 64, NoInputError -> 66,
/// InputError -> 65, OutputError -> 73, anything else -> 70. A library's
/// std::invalid_argument that reaches it is not a command-line error (the
/// apps check their options and throw UsageError): it came from input data,
/// 65. Exit 64 means the command line and nothing else.
/// The run is all or nothing: `body` runs inside an io::OutputRun, so every
/// file written with io::WriteFileAtomically (and "-", stdout) is staged and
/// put into place only when `body` returns 0 or 3; otherwise, or when it
/// throws, nothing of the run appears. Write results to stdout with
/// io::WriteFileAtomically("-", ...), never with std::cout directly.
int RunGuarded(const std::string& tool, const std::function<int()>& body);

/// Puts the outputs written so far into place now, for the rare tool whose
/// error exit still leaves a diagnostic output (frf-estimate's --summary
/// when every hit was rejected). Later writes go straight to their files.
void CommitOutputsNow();

/// @throws InputError "path: no such file" if `path` is not a readable file;
/// RunGuarded maps it to 66.
/// A folder option (--report, --plot-dir): "-" is standard output, which
/// takes single files only. @throws UsageError (exit 64).
void RequireFolderOption(const std::string& option, const std::string& path);

void RequireReadableFile(const std::string& path, const std::string& what);

/// RequireReadableFile, then what the file is (io::RequireFileKind): a file
/// recognised as another kind than `accepted` is bad input (65) named with
/// the option, "kr210.yaml: this is a YAML file; --postures expects the
/// posture CSV of docs/formats.md §1". Unrecognised text passes.
void RequireInputFile(const std::string& option, const std::string& path, const std::string& what,
                      std::initializer_list<io::FileKind> accepted, const std::string& expected);

/// A missing input file (exit 66).
class NoInputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Progress on stderr: one line per ~10 % (or a \r-updated line on a TTY),
/// only for long jobs: `total` items, shown when there are at least
/// `min_total` (fewer items that are each slow, such as SD speeds, pass a
/// smaller `min_total`). The count printed is of the items themselves.
class ProgressLine {
 public:
  ProgressLine(std::string tool, std::string what, long total, long min_total = 200);
  void Update(long done);
  /// The same with a short text after the count (e.g. the best value so far).
  void Update(long done, const std::string& detail);
  void Finish();

 private:
  std::string tool_, what_;
  long total_;
  int last_decile_{-1};
  double last_draw_s_{0.0};
  bool tty_;
  bool active_;
  std::chrono::steady_clock::time_point start_;
};

/// A ProgressLine per stage of a library call that reports
/// (stage, done, total): a new stage finishes the line of the last, and so
/// does a message, so that it does not land in the middle of a line.
class StageProgressLines {
 public:
  explicit StageProgressLines(std::string tool) : tool_(std::move(tool)) {}
  std::function<void(const std::string&, long, long)> Callback() {
    return [this](const std::string& stage, long done, long total) {
      if (!line_ || stage != stage_) {
        Finish();
        stage_ = stage;
        const auto m = min_total_.find(stage);
        line_.emplace(tool_, stage, total, m == min_total_.end() ? 200 : m->second);
      }
      line_->Update(done);
    };
  }
  MessageSink Messages(MessageSink sink) {
    return [this, sink](const Message& m) {
      Finish();
      if (sink) sink(m);
    };
  }
  void Finish() {
    if (line_) line_->Finish();
    line_.reset();
  }
  /// The stage's line shows from this many items (ProgressLine's min_total;
  /// 200 unless set).
  void MinTotal(const std::string& stage, long min_total) { min_total_[stage] = min_total; }

 private:
  std::string tool_, stage_;
  std::optional<ProgressLine> line_;
  std::map<std::string, long> min_total_;
};

/// Prints "tool: warning: message" on stderr.
void Warn(const std::string& tool, const std::string& message);
/// Every message given to Warn() so far in this process, in order: the tools
/// put them in their summary and report (every warning a tool prints is
/// also there).
std::vector<std::string> WarningsGiven();
/// A tool's JSON summary as written (report::DumpJson) with `warnings`:
/// every message given to Warn() before it is written (WarningsGiven), so
/// that every warning printed is also in the summary (formats.md §4.1). A
/// summary that has its own `warnings` keeps them.
std::string SummaryText(const nlohmann::json& summary);
/// Writes a tool's --summary to `path` (io::WriteFileAtomically of
/// SummaryText) with the keys only the tool knows added: `tool` and
/// `exit_code`.
void WriteToolSummary(const std::string& path, const std::string& tool, nlohmann::json summary, int exit_code);
/// workflows::LoadRobotConfigChecked (the reader, then the joints'
/// plausibility) with its unit findings (RobotConfig::implausible,
/// docs/plausibility.md) given to Warn(): the tool flags its result (exit 3)
/// when the returned config's `implausible` is not empty.
io::RobotConfig LoadRobotConfigWarned(const std::string& tool, const std::string& path);
/// "tool: note: message" on stderr: what a reader inferred or skipped; not
/// a warning, and no reason for exit 3.
void Note(const std::string& tool, const std::string& message);

/// The known long option closest to `given` ("--fmax-hzz", "--fmax_hz",
/// "--depth-m=3"), with its dashes, or "" when none is close (ClosestName).
std::string SuggestOption(const std::string& given, const std::vector<std::string>& long_names);

/// Adds --version to `app`: prints "tool 0.1.0 (git <commit>)" and exits 0.
/// Also prefixes CLI11's command-line error messages with the tool's name.
void AddVersionFlag(CLI::App& app, const std::string& tool);

/// Checks a picture option's file name when the command line is parsed:
/// robomach draws PNG only, so another extension (x.svg, x.pdf) is a bad
/// command line (exit 64), before any work; a message names the option.
/// Use as app.add_option("--plot", path, "...")->check(PngFileName()).
std::function<std::string(const std::string&)> PngFileName();

/// Splits "NAME=VALUE"; @throws UsageError naming the option.
std::pair<std::string, double> ParseAssignment(const std::string& option, const std::string& text);

/// Refuses an output path that is also an input or another output (a user
/// typo that would silently destroy data). Empty paths are ignored; "-"
/// means stdout. @throws UsageError naming both options.
/// `folders` are the folder outputs (--report, --plot-dir): "-" is a bad
/// command line (UsageError), and they are checked against the inputs and
/// the other outputs as the files are.
/// Then, before any work, checks that every output can be written: the
/// nearest existing folder on its path must be a writable folder (a file in
/// the way, a read-only folder); a file output must not be an existing
/// folder, nor a folder output an existing file. @throws OutputError (exit
/// 73) naming the option and the path, so a long run does not fail at its
/// end.
void CheckDistinctPaths(const std::vector<std::pair<std::string, std::string>>& inputs,
                        const std::vector<std::pair<std::string, std::string>>& outputs,
                        const std::vector<std::pair<std::string, std::string>>& folders = {});

/// File-name stems for IDs used as file names in a folder output
/// (io::SafeFileStems): "tool: note: ..." on stderr for each ID whose file
/// name differs from it, naming `option` and the name used.
std::map<std::string, std::string> FileStemsForIds(const std::string& tool, const std::string& option,
                                                   const std::vector<std::string>& ids);

/// The library's messages (common/messages.h) on stderr under the tool's
/// name: warnings through Warn (so the summary lists them), notes through
/// Note, info lines as "tool: text".
MessageSink MessagePrinter(const std::string& tool);

/// The check of an option that takes one of `names` (CLI::IsMember with
/// its answer): an unknown value gets "expected a, b or c, got 'x'" and the
/// name meant, from `aliases` (a word users reach for: "zigzag" for
/// "parallel"; keys lower-case) or else the closest name (ClosestName:
/// "zoaa" -> "zoa").
CLI::Validator OneOf(std::vector<std::string> names, std::map<std::string, std::string> aliases = {});

/// The options of the tools that predict with a parameter uncertainty
/// (issue #37): --uncertainty FILE (repeatable), --confidence,
/// --uncertainty-method, --samples, --seed.
struct UncertaintyCli {
  std::vector<std::string> paths;
  dynamics::PropagationOptions propagation;
  std::string method{"auto"};
  /// propagation.method from `method`, the options checked (exit 64 naming
  /// the option) and each file of --uncertainty required as a YAML file (66
  /// when missing).
  void Finish();
  /// The files to use: --uncertainty's, else those the robot config names
  /// (`uncertainty:`).
  const std::vector<std::string>& PathsFor(const io::RobotConfig& config) const {
    return paths.empty() ? config.uncertainty_files : paths;
  }
};
/// Adds the options to `app`; `gains` says what the files add ("--modes and
/// --summary gain each mode's interval").
void AddUncertaintyOptions(CLI::App& app, UncertaintyCli* u, const std::string& gains);

/// Refuses options that do not go with the command line's mode (a tool's
/// other mode, a variant not asked for): the first of `names` given is a
/// UsageError (exit 64) NAME followed by `why` (" is for ...").
void RefuseOptions(const CLI::App& app, std::initializer_list<const char*> names, const std::string& why);

/// @throws UsageError unless lo <= value <= hi (and finite): the library's
/// robomach::CheckOptionRange (common/option_checks.h) worded for a tool.
void CheckOptionRange(const std::string& option, double value, double lo, double hi);

/// The sense checks of a typed option (docs/plausibility.md), the library's
/// (common/option_checks.h), so that a finding reads the same whether a tool
/// or a workflow makes it: the tool Warn()s it and flags its result (exit 3).
using robomach::ImplausibleOption;
using robomach::RadiansInDegreeOption;

/// "1,2.5,3" -> numbers; @throws UsageError naming the option.
std::vector<double> ParseNumberList(const std::string& option, const std::string& text);
/// "x,y,z" in millimetres -> metres, or nullopt for "tcp" (or empty).
std::optional<Eigen::Vector3d> ParsePointMm(const std::string& option, const std::string& text);

/// Applies `--add EFFECT` (with its default parameters; values already set
/// are kept) and then `--set NAME=VALUE` to a loaded robot config.
/// @throws UsageError for an unknown effect or parameter, or a
///   value outside its bounds.
void ApplyAddsAndSets(const std::vector<std::string>& adds, const std::vector<std::string>& sets,
                      io::RobotConfig* config);

}  // namespace robomach::apps
