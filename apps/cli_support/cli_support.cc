#include "cli_support.h"

#include "robomach/common/closest_name.h"
#include "robomach/common/number_format.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <glog/logging.h>

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "robomach/common/errors.h"
#include "robomach/common/version.h"
#include "robomach/io/uncertainty_file.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/file_kind.h"
#include "robomach/io/file_names.h"
#include "robomach/report/json.h"
#include "robomach/workflows/frf_predict.h"
#include "robomach/workflows/option_text.h"
#include "robomach/workflows/robot_config.h"

namespace robomach::apps {

std::string ExitCodeHelp() {
  return "Exit codes: 0 success; 3 outputs written but the result is flagged (see stderr); "
         "64 bad command line; 65 bad input data; 66 input file missing or unreadable; "
         "70 internal error; 73 an output could not be written.";
}

int RunGuarded(const std::string& tool, const std::function<int()>& body) {
  // Ceres logs through glog ("E... covariance_impl.cc: Covariance matrix is
  // near rank deficient", "Terminating: ..."). The library reports the same
  // trouble as fit statuses and flags, which the tools print in their own
  // words, so glog's lines below FATAL are silenced.
  FLAGS_minloglevel = google::GLOG_FATAL;
  try {
    // Every output of the run is staged and appears only if the run ends
    // with 0 or 3 (docs/conventions.md: all or nothing); an exception or an
    // error exit destroys the run, which removes what it staged.
    io::OutputRun outputs;
    const int rc = body();
    if (rc == kExitOk || rc == kExitFlagged) outputs.Commit();
    // Results on stdout count as output: a full disk or closed pipe is an
    // error, not a silent success.
    std::cout.flush();
    if (!std::cout) {
      std::cerr << tool << ": cannot write the results to standard output\n";
      return kExitCantCreate;
    }
    return rc;
  } catch (const NoInputError& e) {
    // Every message escapes bytes that are not UTF-8 (a path or a header
    // quoted from a Latin-1 file): the terminal gets valid text.
    std::cerr << tool << ": " << EscapeInvalidUtf8(e.what()) << '\n';
    return kExitNoInput;
  } catch (const io::MissingFileError& e) {
    // A file named inside an input (a config's urdf:) that is not there.
    std::cerr << tool << ": " << EscapeInvalidUtf8(e.what()) << '\n';
    return kExitNoInput;
  } catch (const InputError& e) {
    std::cerr << tool << ": " << EscapeInvalidUtf8(e.what()) << '\n';
    return kExitDataError;
  } catch (const OutputError& e) {
    std::cerr << tool << ": " << EscapeInvalidUtf8(e.what()) << '\n';
    return kExitCantCreate;
  } catch (const UsageError& e) {
    std::cerr << tool << ": " << EscapeInvalidUtf8(e.what()) << '\n';
    return kExitUsage;
  } catch (const std::invalid_argument& e) {
    // The library refused a value the app passed on unchecked: every option
    // is checked by the app (UsageError), so this value came from the input.
    std::cerr << tool << ": bad input: " << EscapeInvalidUtf8(e.what()) << '\n';
    return kExitDataError;
  } catch (const std::exception& e) {
    std::cerr << tool << ": internal error: " << EscapeInvalidUtf8(e.what()) << '\n';
    return kExitSoftware;
  }
}

void CommitOutputsNow() {
  if (io::OutputRun* run = io::OutputRun::Active()) run->Commit();
}

void RequireFolderOption(const std::string& option, const std::string& path) {
  if (path == "-") {
    throw UsageError(option + " -: expected a folder; '-' (standard output) is for single-file outputs");
  }
}

void RequireReadableFile(const std::string& path, const std::string& what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) throw NoInputError(path + ": " + what + " not found");
  if (fs::is_directory(path, ec)) throw NoInputError(path + ": " + what + " is a directory, expected a file");
  std::ifstream in(path);
  if (!in) throw NoInputError(path + ": " + what + " cannot be read");
}

void RequireInputFile(const std::string& option, const std::string& path, const std::string& what,
                      std::initializer_list<io::FileKind> accepted, const std::string& expected) {
  RequireReadableFile(path, what);
  io::RequireFileKind(path, accepted, expected, option);
}

ProgressLine::ProgressLine(std::string tool, std::string what, long total, long min_total)
    : tool_(std::move(tool)),
      what_(std::move(what)),
      total_(total),
      tty_(::isatty(2) != 0),
      active_(total >= min_total),
      start_(std::chrono::steady_clock::now()) {}

void ProgressLine::Update(long done) { Update(done, ""); }

void ProgressLine::Update(long done, const std::string& detail) {
  if (!active_ || total_ <= 0) return;
  const int decile = static_cast<int>(10 * done / total_);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  // A log gets a line per tenth; a terminal also a redraw every second, so
  // that slow work (seconds a step) shows it moves.
  if (decile == last_decile_ && !(tty_ && s >= last_draw_s_ + 1.0)) return;
  last_decile_ = decile;
  last_draw_s_ = s;
  if (tty_) {
    std::cerr << '\r' << tool_ << ": " << what_ << ' ' << done << '/' << total_ << " (" << s << " s)"
              << (detail.empty() ? "" : " ") << detail << std::flush;
  } else {
    std::cerr << tool_ << ": " << what_ << ' ' << done << '/' << total_ << " (" << s << " s)"
              << (detail.empty() ? "" : " ") << detail << '\n';
  }
}

void ProgressLine::Finish() {
  if (active_ && tty_) std::cerr << '\n';
}

namespace {
std::mutex& WarningsMutex() {
  static std::mutex m;
  return m;
}
std::vector<std::string>& WarningsList() {
  static std::vector<std::string> w;
  return w;
}
}  // namespace

void Warn(const std::string& tool, const std::string& raw_message) {
  // Text quoted from a file header may hold Latin-1 bytes: escaped, so that
  // the terminal and the JSON summary (which lists every warning) get UTF-8.
  const std::string message = EscapeInvalidUtf8(raw_message);
  std::cerr << tool << ": warning: " << message << '\n';
  std::lock_guard<std::mutex> lock(WarningsMutex());
  WarningsList().push_back(message);
}

std::string SummaryText(const nlohmann::json& summary) {
  nlohmann::json j = summary;
  if (j.is_object() && !j.contains("warnings")) j["warnings"] = WarningsGiven();
  return report::DumpJson(j);
}

void WriteToolSummary(const std::string& path, const std::string& tool, nlohmann::json summary, int exit_code) {
  summary["tool"] = tool;
  summary["exit_code"] = exit_code;
  io::WriteFileAtomically(path, SummaryText(summary));
}

io::RobotConfig LoadRobotConfigWarned(const std::string& tool, const std::string& path) {
  io::RobotConfig cfg = workflows::LoadRobotConfigChecked(path);
  for (const std::string& w : cfg.implausible) Warn(tool, w);
  return cfg;
}

std::vector<std::string> WarningsGiven() {
  std::lock_guard<std::mutex> lock(WarningsMutex());
  return WarningsList();
}

std::function<std::string(const std::string&)> PngFileName() {
  return [](const std::string& path) -> std::string {
    const std::string ext = std::filesystem::path(path).extension().string();
    std::string low = ext;
    for (char& c : low) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (low == ".png") return "";
    return "expected a .png file name (robomach draws PNG pictures only), got \"" + path + "\"";
  };
}

std::string SuggestOption(const std::string& given, const std::vector<std::string>& long_names) {
  if (given.size() < 3 || given.rfind("--", 0) != 0) return "";
  const std::string name = given.substr(2, given.find('=') == std::string::npos ? std::string::npos : given.find('=') - 2);
  const std::string best = ClosestName(name, long_names);
  return best.empty() ? "" : "--" + best;
}

void AddVersionFlag(CLI::App& app, const std::string& tool) {
  app.set_version_flag("--version", tool + " " + Version(), "print the version (and git commit) and exit");
  // Command-line errors CLI11 reports (a --plot x.jpg, an unknown option)
  // start with the tool's name like every other message (issue #35); an
  // unknown option is answered with the closest known one.
  app.failure_message([tool](const CLI::App* a, const CLI::Error& e) {
    std::string message = tool + ": " + e.what() + "\n";
    std::vector<std::string> extras;
    if (dynamic_cast<const CLI::ExtrasError*>(&e) != nullptr) {
      // The unknown arguments as CLI11 lists them ("... not expected: 5 --fmax-hzz").
      const std::string what = e.what();
      const size_t colon = what.find(": ");
      std::istringstream words(colon == std::string::npos ? "" : what.substr(colon + 2));
      for (std::string w; words >> w;) extras.push_back(w);
    } else {
      // Another error found first ("--postures is required" for --postres):
      // the arguments left over so far.
      extras = a->remaining();
    }
    if (!extras.empty()) {
      std::vector<std::string> names;
      for (const CLI::Option* opt : a->get_options()) {
        for (const std::string& n : opt->get_lnames()) names.push_back(n);
      }
      for (const std::string& extra : extras) {
        const std::string hint = SuggestOption(extra, names);
        if (!hint.empty()) message += tool + ": " + extra.substr(0, extra.find('=')) + ": did you mean " + hint + "?\n";
      }
    }
    return message + "Run with --help for more information.\n";
  });
}

void Note(const std::string& tool, const std::string& message) {
  std::cerr << tool << ": note: " << EscapeInvalidUtf8(message) << '\n';
}

std::pair<std::string, double> ParseAssignment(const std::string& option, const std::string& text) {
  const size_t eq = text.find('=');
  double v = 0.0;
  if (eq == std::string::npos || eq == 0 || !io::ParseFiniteNumber(text.substr(eq + 1), &v)) {
    throw UsageError(option + " " + text + ": expected NAME=VALUE with a number, e.g. m6_kg=30");
  }
  return {text.substr(0, eq), v};
}

void CheckDistinctPaths(const std::vector<std::pair<std::string, std::string>>& inputs,
                        const std::vector<std::pair<std::string, std::string>>& outputs,
                        const std::vector<std::pair<std::string, std::string>>& folders) {
  namespace fs = std::filesystem;
  auto key = [](const std::string& p) {
    std::error_code ec;
    const fs::path c = fs::weakly_canonical(fs::path(p), ec);
    return ec ? fs::absolute(p).lexically_normal().string() : c.string();
  };
  // "-" is standard output, which takes single files only.
  for (const auto& [opt, path] : folders) RequireFolderOption(opt, path);
  // Files and folders alike: none may be an input or another output.
  struct Out {
    std::string opt, path;
    bool folder;
  };
  std::vector<Out> all;
  for (const auto& [opt, path] : outputs) all.push_back({opt, path, false});
  for (const auto& [opt, path] : folders) all.push_back({opt, path, true});
  for (size_t i = 0; i < all.size(); ++i) {
    const auto& [opt, path, folder] = all[i];
    if (path.empty() || path == "-") continue;
    for (const auto& [in_opt, in_path] : inputs) {
      if (!in_path.empty() && in_path != "-" && key(in_path) == key(path)) {
        throw UsageError(opt + " " + path + " is also the input of " + in_opt +
                         "; writing it would destroy the input");
      }
    }
    for (size_t j = 0; j < i; ++j) {
      if (!all[j].path.empty() && all[j].path != "-" && key(all[j].path) == key(path)) {
        throw UsageError(opt + " and " + all[j].opt + " name the same " + (folder || all[j].folder ? "path " : "file ") +
                         path);
      }
    }
  }
  // Writable before any work: the nearest existing ancestor of each output
  // (its folder, or the first folder to be created) must be a folder we may
  // write in. A file output that is an existing folder, and a folder output
  // that is an existing file, cannot be written either.
  for (const auto& [opt, path, folder] : all) {
    if (path.empty() || path == "-") continue;
    std::error_code ec;
    const fs::path p = fs::absolute(fs::path(path), ec).lexically_normal();
    if (ec) continue;
    const std::string what = folder ? "folder" : "file";
    if (fs::exists(p, ec) && fs::is_directory(p, ec) != folder) {
      throw OutputError(opt + " " + path + ": cannot be written: it is " +
                        (folder ? "a file; expected a folder (it is created if it does not exist)"
                                : "a folder; expected a file name"));
    }
    fs::path probe = folder && fs::is_directory(p, ec) ? p : p.parent_path();
    while (!probe.empty() && !fs::exists(probe, ec) && probe != probe.root_path()) probe = probe.parent_path();
    if (probe.empty()) continue;
    if (!fs::is_directory(probe, ec)) {
      throw OutputError(opt + " " + path + ": cannot be written: " + probe.string() + " is not a folder");
    }
    if (::access(probe.c_str(), W_OK | X_OK) != 0) {
      throw OutputError(opt + " " + path + ": cannot be written: the folder " + probe.string() + " is not writable");
    }
  }
}

void ValidateOptions(const std::vector<FieldSource>& fields, const std::function<void()>& check) {
  try {
    check();
  } catch (const UsageError&) {
    throw;
  } catch (const std::invalid_argument& e) {
    std::string msg = e.what();
    // "VirtualHammerOptions: fmax_hz ..." or "FrfEstimateOptions::fmax_hz = ...": drop the C++ name.
    size_t start = 0;
    if (!msg.empty() && std::isupper(static_cast<unsigned char>(msg[0]))) {
      size_t i = 0;
      while (i < msg.size() && (std::isalnum(static_cast<unsigned char>(msg[i])) || msg[i] == '_')) ++i;
      if (msg.compare(i, 2, "::") == 0) start = i + 2;
      else if (msg.compare(i, 2, ": ") == 0) start = i + 2;
    }
    const auto word = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
    std::string out;
    const FieldSource* first = nullptr;
    for (size_t i = start; i < msg.size();) {
      const FieldSource* hit = nullptr;
      if (i == start || !word(msg[i - 1])) {
        for (const FieldSource& f : fields) {
          const size_t n = f.field.size();
          if (msg.compare(i, n, f.field) == 0 && (i + n == msg.size() || !word(msg[i + n])) &&
              (!hit || n > hit->field.size())) {
            hit = &f;
          }
        }
      }
      if (!hit) {
        out += msg[i++];
        continue;
      }
      const bool leading = i == start;
      if (!first) first = hit;
      out += hit->name;
      i += hit->field.size();
      if (leading && msg.compare(i, 3, " = ") == 0) {  // "field = value: ..." -> "--option value: ..."
        out += ' ';
        i += 3;
      }
    }
    if (!first) throw;
    if (first->from_input) throw std::invalid_argument(out);
    throw UsageError(out);
  }
}

std::map<std::string, std::string> FileStemsForIds(const std::string& tool, const std::string& option,
                                                   const std::vector<std::string>& ids) {
  std::map<std::string, std::string> stems = io::SafeFileStems(ids);
  for (const auto& [id, stem] : stems) {
    if (stem != id) {
      Note(tool, option + ": posture \"" + id + "\" is not a safe file name; its files are named with \"" + stem +
                     "\" (docs/conventions.md, file names made from IDs)");
    }
  }
  return stems;
}

void RefuseOptions(const CLI::App& app, std::initializer_list<const char*> names, const std::string& why) {
  for (const char* name : names) {
    if (app.count(name) > 0) throw UsageError(name + why);
  }
}

void CheckOptionRange(const std::string& option, double value, double lo, double hi) {
  try {
    robomach::CheckOptionRange(option, value, lo, hi);
  } catch (const OptionError& e) {
    throw UsageError(e.what());
  }
}

MessageSink MessagePrinter(const std::string& tool) {
  return [tool](const Message& m) {
    switch (m.kind) {
      case Message::Kind::kWarning: Warn(tool, m.text); break;
      case Message::Kind::kNote: Note(tool, m.text); break;
      case Message::Kind::kInfo: {
        // Several lines (a modal fit's table): continuation lines, indented
        // by two blanks, go without the tool's name.
        std::istringstream lines(m.text);
        for (std::string line; std::getline(lines, line);) {
          std::cerr << (line.rfind("  ", 0) == 0 ? "" : tool + ": ") << line << '\n';
        }
        break;
      }
    }
  };
}

void AddUncertaintyOptions(CLI::App& app, UncertaintyCli* u, const std::string& gains) {
  app.add_option("--uncertainty", u->paths,
                 "parameter-uncertainty YAML (docs/formats.md §12, from kq-identify --uncertainty-out); repeatable, "
                 "files from different campaigns are taken as independent. Its estimates replace the config's "
                 "values; " + gains);
  app.add_option("--confidence", u->propagation.confidence, "two-sided confidence level of the intervals, in (0, 1)")
      ->capture_default_str();
  app.add_option("--uncertainty-method", u->method,
                 "auto (first order, Monte Carlo where the outputs bend within the interval), first-order or "
                 "monte-carlo")
      ->check(OneOf({"auto", "first-order", "monte-carlo"}))->capture_default_str();
  app.add_option("--samples", u->propagation.samples, "Monte Carlo samples per posture")->capture_default_str();
  app.add_option("--seed", u->propagation.seed, "Monte Carlo seed")->capture_default_str();
}

void UncertaintyCli::Finish() {
  // The method and options also serve a robot config's `uncertainty:` files.
  propagation.method = dynamics::ParsePropagationMethod(method);
  ValidateOptions({{"confidence", "--confidence"}, {"samples", "--samples"}},
                  [&] { propagation.Validate(); });
  for (const std::string& p : paths) {
    RequireInputFile("--uncertainty", p, "parameter-uncertainty file", {io::FileKind::kYaml},
                     io::kUncertaintyFileFormat);
  }
}

CLI::Validator OneOf(std::vector<std::string> names, std::map<std::string, std::string> aliases) {
  std::string list;
  for (size_t i = 0; i < names.size(); ++i) {
    list += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  }
  return CLI::Validator(
      [names, aliases, list](std::string& value) -> std::string {
        if (std::find(names.begin(), names.end(), value) != names.end()) return "";
        std::string low = value;
        for (char& c : low) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        std::string meant;
        if (const auto a = aliases.find(low); a != aliases.end()) {
          meant = a->second;
        } else {
          meant = ClosestName(value, names);
        }
        return "expected " + list + ", got '" + value + "'" + (meant.empty() ? "" : ": did you mean " + meant + "?");
      },
      "{" + list + "}");
}

// The library's parsers (workflows/option_text.h), worded for a tool: the
// option's name in the message, a UsageError (exit 64).
std::vector<double> ParseNumberList(const std::string& option, const std::string& text) {
  try {
    return workflows::ParseNumberList(option, text);
  } catch (const OptionError& e) {
    throw UsageError(e.what());
  }
}

std::optional<Eigen::Vector3d> ParsePointMm(const std::string& option, const std::string& text) {
  try {
    return workflows::ParsePointMm(option, text);
  } catch (const OptionError& e) {
    throw UsageError(e.what());
  }
}

void ApplyAddsAndSets(const std::vector<std::string>& adds, const std::vector<std::string>& sets,
                      io::RobotConfig* cfg) {
  ValidateOptions({{"adds", "--add"}, {"sets", "--set"}}, [&] { workflows::ApplyAddsAndSets(adds, sets, cfg); });
}

}  // namespace robomach::apps
