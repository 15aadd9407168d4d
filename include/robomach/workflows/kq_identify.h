#pragma once
// kq-identify as a library call (issue #36 §1): a robot config and a
// laser-tracker file -> the load cases -> the joint stiffness with its
// uncertainty and the verdict (RunKqIdentify). The tool parses its options
// into KqIdentifyOptions and writes what the call returns; the checks of
// the input and their messages live here. --plan N is RunKqPlan.

#include <memory>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "robomach/common/messages.h"
#include "robomach/common/run_status.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/dynamics/uncertainty.h"
#include "robomach/identification/joint_stiffness.h"
#include "robomach/identification/test_plan.h"
#include "robomach/io/kq_files.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/robot_config.h"
#include "robomach/io/tracker_file.h"

namespace robomach::workflows {

/// kq-identify's options when it identifies (the tool's option is the
/// field's name with dashes and without _path: robot_path is --robot).
struct KqIdentifyOptions {
  std::string robot_path;    // robot config YAML; its stiffness is the prior
  std::string tracker_path;  // tracker CSV (formats.md §2)
  double noise_mm{0.01};     // tracker noise, 1 sigma per coordinate [mm]
  std::string robust;        // "" or "none" (least squares), "cauchy" or "huber"
  /// How messages name noise_mm (the tool: "--noise-mm").
  std::string noise_mm_name{"noise_mm"};

  /// @throws OptionError naming the field: noise_mm not finite > 0, robust
  ///   neither "" nor an identification::ParseRobustLoss name (none,
  ///   huber, cauchy), a path empty.
  void Validate() const;
};

/// Everything kq-identify prints and writes.
struct KqIdentifyResult {
  io::RobotConfig config;  // as loaded (config.implausible: its unit findings)
  std::shared_ptr<const dynamics::RobotModel> model;
  io::TrackerFile tracker;  // (tracker.unknown_columns for --verbose)
  std::vector<identification::LoadCase> cases;
  /// The fit (its advice: the fit's own; a tool writing notes puts the
  /// unit findings in front).
  identification::JointStiffnessResult fit;
  /// Unit findings of the tracker file and of noise_mm ("implausible (unit
  /// mistake?): ..."), each also a warning message.
  std::vector<std::string> unit_findings;

  /// kq-identify's exit 3: the fit is flagged (identification's rule), or
  /// the config, the file or the noise has a unit finding.
  bool flagged() const { return fit.flagged() || !config.implausible.empty() || !unit_findings.empty(); }
  RunStatus status() const { return flagged() ? RunStatus::kFlagged : RunStatus::kOk; }
  /// kq-identify's --summary but for the keys only the tool knows (tool,
  /// exit_code, warnings, robomach_version): io::KqSummaryJson of the fit
  /// with the unit findings first in its advice, and `flagged`.
  nlohmann::json Summary() const;
  /// The fit with the unit findings in front of its advice: the notes of
  /// the kq.yaml and of the summary.
  identification::JointStiffnessResult NotedFit() const;
  /// kq-identify's --out: the kq.yaml block to paste into the robot config
  /// (io::JointStiffnessYaml of NotedFit, KqOutputHeader first; a
  /// `parameters:` block with `as_parameters`).
  std::string KqYamlText(const KqIdentifyOptions& options, bool as_parameters) const;
  /// kq-identify --merge: the robot config with the identified stiffness
  /// (io::MergeJointStiffness), to be written to `out_path`, with
  /// KqOutputHeader and every note of NotedFit as "NOTE: " comments; it
  /// names `uncertainty_path` (may be empty) as its uncertainty file.
  std::string MergedConfigText(const KqIdentifyOptions& options, const std::string& out_path,
                               const std::string& uncertainty_path) const;
  /// The fitted stiffnesses' estimates and covariance (formats.md §12),
  /// their source the two lines of KqOutputHeader.
  dynamics::ParameterUncertainty Uncertainty(const KqIdentifyOptions& options) const;
  /// "TRACKER: ignored columns: a, b" (what --verbose tells), or "" when
  /// the tracker file has no unknown column.
  std::string IgnoredColumnsMessage(const KqIdentifyOptions& options) const;
};

/// The comment lines kq-identify's outputs start with: where the stiffness
/// came from (tracker file and robot config), the tracker noise and the loss.
std::vector<std::string> KqOutputHeader(const KqIdentifyOptions& options);

/// Loads the config and the tracker file, checks them (the config's units,
/// effects the load-test model does not have, the file's and the noise's
/// units, joints outside their limits: each a kWarning message, in that
/// order),
/// and identifies the joint stiffness. `progress` is
/// called with (cases done, cases). The fit's advice is not sent as
/// messages (the caller prints the table first); it is in fit.advice.
/// @throws OptionError (Validate), io::MissingFileError, InputError for the
///   files.
KqIdentifyResult RunKqIdentify(const KqIdentifyOptions& options, const MessageSink& on_message = {},
                               const std::function<void(long, long)>& progress = {});

/// The table kq-identify prints for a fit, one line each (no tool name):
/// the fit's end, each joint's stiffness, standard deviation, 95 % interval
/// and determination, the residuals against the noise.
std::vector<std::string> KqReportLines(const identification::JointStiffnessResult& fit);

/// kq-identify --plan N (noise and masses in the command line's units).
struct KqPlanOptions {
  std::string robot_path;
  int num_postures{12};   // [1, 500]
  double noise_mm{0.01};  // tracker noise, 1 sigma per coordinate [mm], > 0
  unsigned seed{1};
  std::optional<Eigen::Vector3d> load_point_m, target_m;  // in the tip frame [m]; none: the TCP
  std::vector<double> masses_kg{10.0, 20.0, 30.0};          // each > 0
  double max_rope_angle_deg{45.0};  // rope from vertical [deg], in (0, 90): 0 leaves one direction
  /// How the warnings name the options to change (the tool: "--plan N" and
  /// "--load-point-mm, --target-mm").
  std::string num_postures_name{"num_postures"};
  std::string points_name{"load_point_m, target_m"};
  /// How the unit findings name the options (the tool: "--noise-mm",
  /// "--masses-kg", "--load-point-mm", "--target-mm", in their units).
  std::string noise_mm_name{"noise_mm"}, masses_name{"masses_kg"}, load_point_name{"load_point_m"},
      target_name{"target_m"};
  /// How the message of a robot with too few feasible postures names
  /// max_rope_angle_deg (the tool: "--max-rope-angle-deg").
  std::string max_rope_angle_name{"max_rope_angle_deg"};
  /// A targeted plan (issue #37 §5): the posture file (formats.md §1) of the work region whose
  /// `target_quantity` must be known well — "frequency" (the lowest natural
  /// frequency) or "safe-depth" (the ZOA lobes' smallest critical depth of
  /// the cut in `cut_path`, whose lower confidence bound is the safe depth)
  /// — and the relative half-width wanted at 95 % (0: none). Empty: a
  /// D-optimal plan.
  std::string target_postures_path;
  std::string target_quantity{"frequency"};
  std::string cut_path;
  double target_half_width{0.0};
  /// How the messages name target_half_width (the tool: "--target-band-pct").
  std::string target_half_width_name{"target_half_width"};

  /// @throws OptionError naming the field and its bound.
  void Validate() const;
};

/// ∂ ln y / ∂ ln k_j of the target quantity at each posture (columns), by
/// central differences (steps of 1e-3 in ln k_j) on the robot model:
/// PlanOptions::target_gradients of a targeted plan.
/// @throws std::invalid_argument if the quantity cannot be computed at a
///   posture (no lobe boundary, a mode that does not move the tip).
Eigen::MatrixXd TargetGradients(const io::RobotConfig& config, const std::vector<io::Posture>& postures,
                                const std::string& quantity, const std::string& cut_path);

/// How far a target departs from its first-order prediction within its
/// expected band: the quantity at each joint's own interval edges
/// ln k_j ± z σ_j (one joint at a time, σ_j the plan's expected relative
/// standard deviation), against ln y₀ + g_tj (± z σ_j), in units of the
/// target's expected half-width z σ_t. The check of dynamics::Propagate's
/// auto mode, on the plan's marginal intervals.
struct TargetLinearity {
  std::string id;
  double departure{0.0};  // the largest, in half-widths (inf: no value there)
  int joint{0};           // where it is largest (1-based; 0: none checked)
  double step{0.0};       // ln k_j step there
};
/// Above this, the target's band from the campaign will be wider than the
/// plan promises (the tolerance of PropagationOptions::nonlinearity_tolerance).
inline constexpr double kTargetNonlinearityTolerance = 0.1;

std::vector<TargetLinearity> CheckTargetLinearity(const io::RobotConfig& config,
                                                  const std::vector<io::Posture>& postures,
                                                  const std::string& quantity, const std::string& cut_path,
                                                  const Eigen::MatrixXd& gradients, const Eigen::VectorXd& relative_std,
                                                  const Eigen::VectorXd& target_relative_std, double z);

struct KqPlanResult {
  io::RobotConfig config;  // as loaded (config.implausible: its unit findings)
  std::shared_ptr<const dynamics::RobotModel> model;
  identification::PlanOptions planner;  // in SI, as planned
  identification::TestPlan plan;
  /// What the tool prints after writing the plan: the plan's size and each
  /// joint's expected standard deviation (no tool name).
  std::vector<std::string> lines;
  /// The plan's findings (a joint no plan can determine), then one per joint
  /// it would leave weakly determined with what to change.
  std::vector<std::string> warnings;
  /// With target postures: each target's expected relative half-width at
  /// 95 % with the whole plan, by posture id.
  std::vector<std::pair<std::string, double>> target_half_widths;
  std::string target_quantity;  // "frequency" or "safe-depth" with target postures, else empty
  /// The worst target's half-width with the D-optimal plan of the same size.
  double d_optimal_target_half_width{NAN};
  /// Each target's CheckTargetLinearity; a departure above
  /// kTargetNonlinearityTolerance is a warning.
  std::vector<TargetLinearity> target_linearity;
  /// --target-band-pct was asked and a target bends within its band by
  /// more than kTargetNonlinearityTolerance of the band asked for (in ln y):
  /// the plan's count of postures for the band cannot be trusted.
  bool band_uncertain{false};
  /// Options that look like a unit mistake (a band of 0.05 % meant as 5 %):
  /// warnings too, and they flag the plan.
  std::vector<std::string> option_findings;
  /// kq-identify --plan's exit 3: a joint not determinable, a target band
  /// not reached or not trustworthy, the config's unit findings, an option
  /// finding. A joint left weakly determined or a target that bends within
  /// its band (without a band asked for) is a warning only.
  bool flagged() const {
    return plan.verdict.flagged() || band_uncertain || !config.implausible.empty() || !option_findings.empty();
  }
  /// kq-identify --plan --summary (formats.md §4.1): the plan's size, each
  /// joint's expected standard deviation, the targets' promised half-widths
  /// and linearity, the warnings and `flagged`.
  nlohmann::json Summary() const;
  /// The plan file's header: how it was made (targets and promises included).
  io::LoadTestPlanHeader PlanHeader(const KqPlanOptions& options) const;
};

/// Loads the config (its unit findings are kWarning messages) and plans the
/// test (identification::PlanLoadTests); `warnings` are returned, not sent.
KqPlanResult RunKqPlan(const KqPlanOptions& options, const MessageSink& on_message = {});

}  // namespace robomach::workflows
