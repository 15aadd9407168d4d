#pragma once
// tracker-synth as one library call (issue #36): a robot config (its joint
// stiffness the truth) and postures (random, a posture file or a plan of
// kq-identify --plan) -> a simulated laser-tracker load-test campaign, with
// the checks of the options and the verdict. The tool parses its options
// into TrackerSynthOptions and writes the tracker file (formats.md §2) and
// the summary of the run.

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/common/messages.h"
#include "robomach/common/option_checks.h"
#include "robomach/common/run_status.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/identification/campaign_synth.h"
#include "robomach/io/robot_config.h"

namespace robomach::workflows {

/// tracker-synth's options (the tool's option for each field: robot_path is
/// --robot, postures_path --postures, plan_path --plan-file, sets --set,
/// pulley_mm --pulley-mm, ...). The points and masses are the texts the
/// tool's options take, in mm and kg, so that a finding quotes what was typed.
struct TrackerSynthOptions : FieldNames {
  std::string robot_path;     // robot config YAML; its joint stiffness is the truth
  std::string postures_path;  // posture file (formats.md §1); empty: random postures
  std::string plan_path;      // a plan of kq-identify --plan: its postures and pulleys
  int num_postures{12};       // random postures (without a posture file or plan)
  double min_reach_mm{1500.0};  // random postures: the load point's least distance from the base axis [mm]
  std::string masses_kg{"10,20,30"};  // "m1,m2,..." hung at every posture and pulley [kg]
  std::vector<std::string> pulley_mm{"1600,-1200,0", "1600,1200,0"};  // "x,y,z" in the base frame [mm]
  /// "x,y,z" in the tip frame [mm] or "tcp". Not given: the plan's, else
  /// kDefaultLoadPointMm and kDefaultTargetMm; given with a plan that has
  /// its own, a warning says it replaces the plan's.
  std::optional<std::string> load_point_mm, target_mm;
  double noise_mm{0.01};    // tracker noise, 1 sigma per coordinate [mm]
  int outliers{0};          // cases with a gross error
  double outlier_mm{1.0};   // size of that error [mm]
  std::string form{"rope"};  // load columns: rope (mass_kg + rope points) or force (fx_N..fz_N)
  unsigned seed{1};          // postures, noise, outliers
  std::vector<std::string> sets;  // "NAME=VALUE": parameters of the truth
  // names, Name(field): how the findings and warnings name the fields
  // (FieldNames; the tool: its options, "--noise-mm").

  /// The options alone, before any file is read.
  /// @throws OptionError naming the field: noise_mm outside [0, 1000],
  ///   outliers negative, num_postures under 1, outlier_mm outside
  ///   [0, 10000], min_reach_mm outside [0, 100000], form not rope or
  ///   force.
  void Validate() const;
};

inline constexpr char kDefaultLoadPointMm[] = "150,0,100";
inline constexpr char kDefaultTargetMm[] = "0,120,50";

struct TrackerSynthRun {
  io::RobotConfig config;  // as loaded, the sets applied (config.implausible: its unit findings)
  std::shared_ptr<const dynamics::RobotModel> model;
  identification::CampaignOptions campaign;  // as simulated, in SI
  std::string postures_source;  // "plan", "postures" or "random"
  std::vector<std::string> pose_ids;
  size_t rope_directions{0};  // per posture
  std::vector<identification::TrackerMeasurement> measurements;
  std::vector<int> outlier_cases;  // indices into measurements
  /// The options' unit findings (noise, masses, pulleys), each told as a
  /// warning.
  std::vector<std::string> unit_findings;

  /// Flagged on the config's unit findings or the options'.
  bool flagged() const { return !config.implausible.empty() || !unit_findings.empty(); }
  RunStatus status() const { return flagged() ? RunStatus::kFlagged : RunStatus::kOk; }
  /// The tracker file's header: generator, robot, seed, noise, the true
  /// joint stiffness and the outlier cases.
  std::vector<std::pair<std::string, std::string>> Metadata(const TrackerSynthOptions& options) const;
  /// tracker-synth --summary (formats.md §4.1) but for the keys only the
  /// tool knows (tool, out, warnings): the inputs, the load cases, the
  /// outliers, the true joint stiffness and the deflections.
  nlohmann::json Summary(const TrackerSynthOptions& options) const;
  /// "36 load cases (6 postures x 2 rope directions x 3 masses)[; outliers: ids]".
  std::string CountsLine() const;
};

/// Checks the options, tells the noise's unit finding, loads the config (its
/// unit findings are warnings), applies the sets, checks the masses, pulleys
/// and points (unit findings are warnings), gets the postures (a plan's load
/// point and target unless the options give them) and simulates the campaign.
/// @throws OptionError naming the field (Validate; plan_path with
///   postures_path; sets, masses_kg, pulley_mm, load_point_mm, target_mm
///   malformed or out of range; num_postures more than random postures can
///   reach); InputError for the files (a plan's malformed load_point_mm or
///   target_mm); std::invalid_argument for a parameter the config does not
///   have and a pulley not below the load point.
TrackerSynthRun RunTrackerSynth(const TrackerSynthOptions& options, const MessageSink& tell = {});

}  // namespace robomach::workflows
