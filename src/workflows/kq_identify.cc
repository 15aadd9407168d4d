#include "robomach/workflows/kq_identify.h"

#include <cmath>
#include <limits>
#include <iomanip>
#include <sstream>

#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/common/units.h"
#include "robomach/identification/load_case.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/dynamics/uncertainty.h"
#include "robomach/io/cut_file.h"
#include "robomach/io/kq_files.h"
#include "robomach/io/kq_yaml.h"
#include "robomach/io/number_format.h"
#include "robomach/stability/lobe_uncertainty.h"
#include "robomach/workflows/stability_lobes.h"
#include "robomach/workflows/robot_config.h"

namespace robomach::workflows {
namespace {

std::string Sci(double v, int digits = 3) {
  if (!std::isfinite(v)) return "inf";
  std::ostringstream s;
  s << std::scientific << std::setprecision(digits) << v;
  return s.str();
}

}  // namespace

void KqIdentifyOptions::Validate() const {
  if (robot_path.empty()) throw OptionError("robot_path", "robot_path: a robot config is required");
  if (tracker_path.empty()) throw OptionError("tracker_path", "tracker_path: a tracker file is required");
  if (!(noise_mm > 0.0) || !std::isfinite(noise_mm)) {
    throw OptionError("noise_mm", "noise_mm: expected a finite noise > 0 mm, got " + FormatNumber(noise_mm, 6));
  }
  if (!robust.empty()) {
    try {
      identification::ParseRobustLoss(robust);
    } catch (const std::invalid_argument& e) {
      throw OptionError("robust", std::string("robust: ") + e.what() + " (none: least squares)");
    }
  }
}

identification::JointStiffnessResult KqIdentifyResult::NotedFit() const {
  identification::JointStiffnessResult f = fit;
  f.advice.insert(f.advice.begin(), unit_findings.begin(), unit_findings.end());
  return f;
}

nlohmann::json KqIdentifyResult::Summary() const {
  nlohmann::json j = io::KqSummaryJson(NotedFit());
  j["flagged"] = flagged();
  return j;
}

std::vector<std::string> KqOutputHeader(const KqIdentifyOptions& o) {
  return {"kq-identify: joint stiffness identified from " + o.tracker_path + " with robot " + o.robot_path,
          "tracker noise " + io::FormatDouble(o.noise_mm) + " mm (1 sigma per coordinate); loss " +
              (o.robust.empty() ? std::string("least squares") : o.robust)};
}

std::string KqIdentifyResult::KqYamlText(const KqIdentifyOptions& o, bool as_parameters) const {
  io::KqYamlOptions ko;
  ko.as_parameters = as_parameters;
  ko.header_comments = KqOutputHeader(o);
  return io::JointStiffnessYaml(NotedFit(), ko);
}

std::string KqIdentifyResult::MergedConfigText(const KqIdentifyOptions& o, const std::string& out_path,
                                               const std::string& uncertainty_path) const {
  std::vector<std::string> h = KqOutputHeader(o);
  for (const std::string& a : NotedFit().advice) h.push_back("NOTE: " + a);
  return io::MergeJointStiffness(o.robot_path, fit.joint_stiffness, out_path, h, uncertainty_path);
}

dynamics::ParameterUncertainty KqIdentifyResult::Uncertainty(const KqIdentifyOptions& o) const {
  const std::vector<std::string> header = KqOutputHeader(o);
  return identification::StiffnessUncertainty(fit, header[0] + "; " + header[1]);
}

std::string KqIdentifyResult::IgnoredColumnsMessage(const KqIdentifyOptions& o) const {
  if (tracker.unknown_columns.empty()) return "";
  std::string cols;
  for (const std::string& c : tracker.unknown_columns) cols += (cols.empty() ? "" : ", ") + c;
  return o.tracker_path + ": ignored columns: " + cols;
}

KqIdentifyResult RunKqIdentify(const KqIdentifyOptions& o, const MessageSink& on_message,
                               const std::function<void(long, long)>& progress) {
  o.Validate();
  KqIdentifyResult r;
  r.config = workflows::LoadRobotConfigChecked(o.robot_path);
  for (const std::string& w : r.config.implausible) Tell(on_message, Message::Kind::kWarning, w);
  r.model = r.config.Build();
  if (!r.model->effects().empty()) {
    Tell(on_message, Message::Kind::kWarning,
         o.robot_path + " enables effects with their own compliance; the load-test model "
                        "D = J_T Kq^-1 J_L^T W has joint compliance only, so the identified stiffness absorbs theirs");
  }
  r.tracker = io::ReadTrackerFile(o.tracker_path, r.model->num_joints());
  // Unit mistakes in the file and in the noise: said, flagged, and kept
  // for the summary and the report.
  r.unit_findings = r.tracker.unit_warnings;
  if (const std::string w = io::TrackerNoiseUnitFinding(o.noise_mm_name, o.noise_mm); !w.empty()) {
    r.unit_findings.push_back(w);
  }
  for (const std::string& w : r.unit_findings) Tell(on_message, Message::Kind::kWarning, w);
  r.cases = identification::ToLoadCases(r.tracker.measurements);
  // Joints outside their limits: the first three cases named, the rest
  // counted (radians under _deg put every case outside: one line, not 72).
  int outside = 0;
  for (const identification::LoadCase& c : r.cases) {
    for (int j : r.model->chain().JointsOutsideLimits(c.q)) {
      if (++outside <= 3) {
        Tell(on_message, Message::Kind::kWarning,
             o.tracker_path + ":" + std::to_string(c.line) + ": case " + c.case_id + ": joint " +
                 std::to_string(j + 1) + " is outside its limits");
      }
    }
  }
  if (outside > 3) {
    Tell(on_message, Message::Kind::kWarning,
         o.tracker_path + ": " + std::to_string(outside - 3) + " more joints outside their limits (" +
             std::to_string(outside) + " in all)");
  }
  identification::IdentificationOptions opt;
  opt.tracker_noise = MmToM(o.noise_mm);
  opt.loss = identification::ParseRobustLoss(o.robust.empty() ? "none" : o.robust);  // Validate checked it
  r.fit = identification::IdentifyJointStiffness(*r.model, r.cases, opt, progress);
  return r;
}

std::vector<std::string> KqReportLines(const identification::JointStiffnessResult& r) {
  std::vector<std::string> out;
  std::ostringstream head;
  head << r.num_cases << " load cases, fit " << robomach::ToString(r.status) << " (" << r.iterations
       << " iterations): " << r.solver_message;
  out.push_back(head.str());
  out.push_back("joint  stiffness [N·m/rad]  std dev    rel.    95 % interval             determination");
  for (int j = 0; j < r.num_joints; ++j) {
    std::ostringstream rel, row;
    if (std::isfinite(r.relative_std(j))) rel << std::fixed << std::setprecision(1) << 100 * r.relative_std(j) << " %";
    else rel << "-";
    row << "  " << j + 1 << "    " << Sci(r.joint_stiffness(j)) << "          " << Sci(r.std_dev(j), 1) << "   "
        << std::setw(7) << rel.str() << "  [" << Sci(r.lower_95(j), 2) << ", " << Sci(r.upper_95(j), 2) << "]  "
        << identification::ToString(r.determination[j]);
    out.push_back(row.str());
  }
  std::ostringstream tail;
  tail << "RMS residual " << std::fixed << std::setprecision(4) << 1e3 * r.rms_residual << " mm (all cases "
       << 1e3 * r.rms_residual_all << " mm; displacement noise " << 1e3 * r.noise_sigma_displacement
       << " mm per coordinate), chi2/dof " << std::setprecision(2) << r.reduced_chi2
       << ", condition number of the scaled problem " << std::setprecision(1) << r.condition_number;
  out.push_back(tail.str());
  return out;
}

void KqPlanOptions::Validate() const {
  if (robot_path.empty()) throw OptionError("robot_path", "robot_path: a robot config is required");
  // 500 postures: about 15 s of planning.
  if (!(num_postures >= 1 && num_postures <= 500)) {
    throw OptionError("num_postures", "num_postures: expected a number of postures in [1, 500], got " +
                                          std::to_string(num_postures));
  }
  if (!(noise_mm > 0.0) || !std::isfinite(noise_mm)) {
    throw OptionError("noise_mm", "noise_mm: expected a finite noise > 0 mm, got " + FormatNumber(noise_mm, 6));
  }
  for (double m : masses_kg) {
    if (!(m > 0.0) || !std::isfinite(m)) {
      throw OptionError("masses_kg", "masses_kg: expected masses > 0 kg, got " + FormatNumber(m, 6));
    }
  }
  // A posture needs two rope directions (PlanOptions::directions_per_posture):
  // at 0 only the vertical one is left, and no posture is feasible.
  if (!(max_rope_angle_deg > 0.0 && max_rope_angle_deg < 90.0)) {
    throw OptionError("max_rope_angle_deg", "max_rope_angle_deg: expected a rope angle from vertical in (0, 90) deg "
                                            "(0 leaves only the vertical rope), got " +
                                                FormatNumber(max_rope_angle_deg, 6));
  }
  if (target_quantity != "frequency" && target_quantity != "safe-depth") {
    throw OptionError("target_quantity", "target_quantity: expected frequency or safe-depth, got '" +
                                             target_quantity + "'");
  }
  if (!target_postures_path.empty() && target_quantity == "safe-depth" && cut_path.empty()) {
    throw OptionError("cut_path", "cut_path: the safe depth needs the cut (a cut file)");
  }
  if (!(target_half_width >= 0.0 && target_half_width < 1.0)) {
    throw OptionError("target_half_width", "target_half_width: expected a relative half-width in [0, 1) (0.05 for "
                                           "±5 %), got " + FormatNumber(target_half_width, 6));
  }
  if (target_half_width > 0.0 && target_postures_path.empty()) {
    throw OptionError("target_half_width", "target_half_width: a band of what? give the target postures");
  }
}

namespace {

// The target quantity y at a posture with parameters p: the smallest ZOA
// critical depth over the cut's speeds, or the lowest natural frequency.
class TargetQuantity {
 public:
  TargetQuantity(const io::RobotConfig& config, const std::string& quantity, const std::string& cut_path)
      : config_(config) {
    if (quantity == "safe-depth") {
      const io::CutSpec cut = io::ReadCutFile(cut_path);
      StabilityLobesOptions so;
      so.ValidateSettings();
      lobes_ = MakeLobesOptions(cut, so);
      feed_ = cut.feed_direction_B;
    }
    po_.cartesian = false;
    po_.jacobian_condition = false;
  }
  double operator()(const dynamics::ParameterSet& p, const io::Posture& posture) const {
    double y = NAN;
    if (lobes_) {
      const Eigen::VectorXd d =
          stability::ZoaCriticalDepths(config_.description, p, posture.id, posture.q, feed_, *lobes_);
      y = std::numeric_limits<double>::infinity();
      for (Eigen::Index i = 0; i < d.size(); ++i) {
        if (std::isfinite(d(i))) y = std::min(y, d(i));
      }
    } else {
      const dynamics::PostureDynamics d =
          dynamics::EvaluatePosture(dynamics::RobotModel::Build(config_.description, p), posture.q, po_);
      if (!d.modes.empty()) y = d.modes.front().freq_hz;
    }
    if (!(y > 0.0) || !std::isfinite(y)) {
      throw std::invalid_argument("posture " + posture.id + ": the " +
                                  (lobes_ ? "ZOA lobes have no boundary" : "model has no mode") +
                                  ", so it cannot be a target");
    }
    return y;
  }
  // The parameters with kq_j (1-based) scaled by exp(step).
  dynamics::ParameterSet Scaled(int j, double step) const {
    const std::string name = "kq" + std::to_string(j) + "_Nm_per_rad";
    dynamics::ParameterSet p = config_.parameters;
    p.Set(name, config_.parameters.Get(name) * std::exp(step));
    return p;
  }

 private:
  const io::RobotConfig& config_;
  std::optional<stability::LobesOptions> lobes_;
  Eigen::Vector3d feed_{Eigen::Vector3d::UnitX()};
  dynamics::PostureOptions po_;
};

}  // namespace

Eigen::MatrixXd TargetGradients(const io::RobotConfig& config, const std::vector<io::Posture>& postures,
                                const std::string& quantity, const std::string& cut_path) {
  const int n = config.description.arm.num_joints();
  const TargetQuantity value(config, quantity, cut_path);
  constexpr double h = 1e-3;
  Eigen::MatrixXd G(n, static_cast<Eigen::Index>(postures.size()));
  for (size_t t = 0; t < postures.size(); ++t) {
    for (int j = 0; j < n; ++j) {
      G(j, static_cast<Eigen::Index>(t)) =
          (std::log(value(value.Scaled(j + 1, h), postures[t])) - std::log(value(value.Scaled(j + 1, -h), postures[t]))) /
          (2 * h);
    }
  }
  return G;
}

std::vector<TargetLinearity> CheckTargetLinearity(const io::RobotConfig& config,
                                                  const std::vector<io::Posture>& postures,
                                                  const std::string& quantity, const std::string& cut_path,
                                                  const Eigen::MatrixXd& gradients, const Eigen::VectorXd& relative_std,
                                                  const Eigen::VectorXd& target_relative_std, double z) {
  const TargetQuantity value(config, quantity, cut_path);
  std::vector<TargetLinearity> out;
  for (size_t t = 0; t < postures.size(); ++t) {
    TargetLinearity c;
    c.id = postures[t].id;
    const double ln_y0 = std::log(value(config.parameters, postures[t]));
    const double half = z * target_relative_std(static_cast<Eigen::Index>(t));
    for (Eigen::Index j = 0; j < relative_std.size(); ++j) {
      const double s = relative_std(j);
      if (!(s > 0.0) || !std::isfinite(s) || !(half > 0.0)) continue;
      for (double sign : {-1.0, 1.0}) {
        const double step = sign * z * s;  // ln k_j at the joint's own sigma point
        double departure = INFINITY;
        try {
          const double ln_y = std::log(value(value.Scaled(static_cast<int>(j) + 1, step), postures[t]));
          departure = std::abs(ln_y - (ln_y0 + gradients(j, static_cast<Eigen::Index>(t)) * step)) / half;
        } catch (const std::invalid_argument&) {
          // no boundary there: not linear either
        }
        if (!(departure <= c.departure)) {
          c.departure = departure;
          c.joint = static_cast<int>(j) + 1;
          c.step = step;
        }
      }
    }
    out.push_back(c);
  }
  return out;
}

namespace {

// The options' units, as kq-identify checks a tracker file's and
// tracker-synth its options (docs/plausibility.md): a plan is made before
// the campaign, and a wrong one wastes it. Findings go to
// r->option_findings.
void CheckOptionUnits(const KqPlanOptions& o, KqPlanResult* r) {
  if (std::string w = io::TrackerNoiseUnitFinding(o.noise_mm_name, o.noise_mm); !w.empty()) {
    r->option_findings.push_back(std::move(w));
  }
  for (double m : o.masses_kg) {
    if (m >= io::kMinPlausibleLoadMassKg && m <= io::kMaxPlausibleLoadMassKg) continue;
    r->option_findings.push_back("implausible (unit mistake?): " + o.masses_name + " " + FormatNumber(m, 7) +
                                 " kg is outside the " + FormatNumber(io::kMinPlausibleLoadMassKg, 3) + " to " +
                                 FormatNumber(io::kMaxPlausibleLoadMassKg, 3) + " kg of load-test masses (5 - 300 kg): " +
                                 (m > io::kMaxPlausibleLoadMassKg ? "a mass in g typed in the kg option, or a weight in N?"
                                                                  : "a mass in t typed in the kg option?"));
    break;
  }
  for (const auto& [name, point] : {std::pair{o.load_point_name, o.load_point_m}, std::pair{o.target_name, o.target_m}}) {
    // No load or target fits within 1 mm of the flange's origin but on it.
    if (point && point->norm() > 0.0 && point->norm() < 1e-3) {
      r->option_findings.push_back("implausible (unit mistake?): " + name + " " + FormatNumber(1e3 * point->x(), 4) +
                                   "," + FormatNumber(1e3 * point->y(), 4) + "," + FormatNumber(1e3 * point->z(), 4) +
                                   " mm is within 1 mm of the flange's origin: metres typed in the mm option? (" +
                                   FormatNumber(1e6 * point->norm(), 4) + " mm from the origin if so)");
    }
  }
}

// The planner's options (r->planner) from the workflow's, with the target
// postures' gradients for a targeted plan; returns the target postures
// (empty for a D-optimal plan).
std::vector<io::Posture> SetUpPlanner(const KqPlanOptions& o, const MessageSink& on_message, KqPlanResult* r) {
  identification::PlanOptions& p = r->planner;
  p.num_postures = o.num_postures;
  p.tracker_noise = MmToM(o.noise_mm);
  p.seed = o.seed;
  p.p_load_tip = o.load_point_m;
  p.p_target_tip = o.target_m;
  p.masses_kg = o.masses_kg;
  p.max_rope_angle = DegToRad(o.max_rope_angle_deg);
  std::vector<io::Posture> targets;
  if (!o.target_postures_path.empty()) {
    std::vector<std::string> units;
    targets = io::ReadPostureFile(o.target_postures_path, r->model->num_joints(), &units);
    for (const std::string& w : units) {
      Tell(on_message, Message::Kind::kWarning, w);
      r->config.implausible.push_back(w);  // flags the plan (exit 3) like the config's own findings
    }
    Tell(on_message, Message::Kind::kNote,
         "targeted plan: the " + std::string(o.target_quantity == "frequency" ? "lowest natural frequency"
                                                                                : "smallest ZOA critical depth") +
             " at " + std::to_string(targets.size()) + " postures");
    p.target_gradients = TargetGradients(r->config, targets, o.target_quantity, o.cut_path);
    r->target_quantity = o.target_quantity;
    p.target_half_width = o.target_half_width;
  }
  return targets;
}

// The plan's size and each joint's expected standard deviation, as lines.
void AddExpectedStdLines(const KqPlanOptions& o, KqPlanResult* r) {
  const identification::PlanOptions& p = r->planner;
  const int n = r->model->num_joints();
  std::ostringstream head;
  head << "plan of " << o.num_postures << " postures x " << p.directions_per_posture << " rope directions x "
       << o.masses_kg.size() << " masses = " << r->plan.cases.size()
       << " load cases; expected standard deviations for a tracker noise of " << o.noise_mm << " mm:";
  r->lines.push_back(head.str());
  for (int j = 0; j < n; ++j) {
    std::ostringstream rel, row;
    if (std::isfinite(r->plan.expected_relative_std(j))) {
      rel << std::fixed << std::setprecision(2) << 100 * r->plan.expected_relative_std(j) << " %";
    } else {
      rel << "not determined";
    }
    row << "  joint " << j + 1 << ": k = " << Sci(r->model->joint_stiffness()(j)) << " N·m/rad, std dev "
        << Sci(r->plan.expected_std_dev(j), 2) << " N·m/rad (" << rel.str() << ")";
    r->lines.push_back(row.str());
  }
}

// A warning for each target that bends within its band (r->target_linearity
// against the tolerance); r->band_uncertain where that puts the band asked
// for in doubt.
void WarnWhereTargetsBend(const KqPlanOptions& o, KqPlanResult* r) {
  for (size_t t = 0; t < r->target_linearity.size(); ++t) {
    const TargetLinearity& c = r->target_linearity[t];
    if (c.departure <= kTargetNonlinearityTolerance) continue;
    const bool frequency = o.target_quantity == "frequency";
    std::ostringstream w;
    // "target P2": the plan's own postures are P1..PN too.
    w << "target " << c.id << ": the " << (frequency ? "lowest natural frequency" : "smallest ZOA critical depth")
      << " bends within its band (at kq" << c.joint << " " << std::showpos << std::setprecision(3)
      << 100 * (std::exp(c.step) - 1.0) << std::noshowpos << " %, the edge of that joint's expected interval, it is "
      << (std::isfinite(c.departure) ? FormatNumber(100 * c.departure, 3) + " %" : std::string("an undefined amount"))
      << " of the half-width off the first-order prediction), so the promised ±"
      << FormatNumber(100 * r->target_half_widths[t].second, 3)
      << " % is first order only and the campaign's band there can be wider; check it after the campaign with "
      << (frequency ? "frf-predict --uncertainty" : "stability-lobes --uncertainty");
    // The band asked for is in doubt when the bend, in ln y, is more than
    // the tolerance's part of it (a bend of 86 % of a ±1 % promise does
    // not threaten a ±50 % band; one of 560 % of ±13.5 % threatens ±15 %).
    if (o.target_half_width > 0.0 &&
        c.departure * r->target_half_widths[t].second > kTargetNonlinearityTolerance * o.target_half_width) {
      r->band_uncertain = true;
      w << "; the bend is more than a tenth of the ±" << FormatNumber(100 * o.target_half_width, 3) << " % asked for ("
        << o.target_half_width_name << "), so the plan cannot promise that band here (exit 3)";
    }
    r->warnings.push_back(w.str());
  }
}

// A targeted plan's promise: the expected 95 % half-width at each target
// (against a D-optimal plan of the same size), where it is first order
// only, and how many postures reach the band asked for.
void ReportTargets(const KqPlanOptions& o, const std::vector<io::Posture>& targets, KqPlanResult* r) {
  const identification::PlanOptions& p = r->planner;
  std::ostringstream m;
  m << "expected 95 % half-width of the " << (o.target_quantity == "frequency" ? "lowest natural frequency"
                                                                             : "smallest ZOA critical depth")
    << ":";
  const double z = dynamics::NormalQuantile(0.5 * (1.0 + p.target_confidence));
  for (size_t t = 0; t < targets.size(); ++t) {
    const double hw = z * r->plan.expected_target_relative_std(static_cast<Eigen::Index>(t));
    r->target_half_widths.push_back({targets[t].id, hw});
    m << (t ? "," : "") << " target " << targets[t].id << " ±" << std::setprecision(3) << 100 * hw << " %";
  }
  {
    // The same targets with the D-optimal plan of the same size: what targeting gains.
    identification::PlanOptions d = p;
    d.design_for_targets = false;
    d.target_half_width = 0.0;
    const identification::TestPlan dp = identification::PlanLoadTests(*r->model, d);
    r->d_optimal_target_half_width = z * dp.expected_target_relative_std.maxCoeff();
    m << " (worst ±" << 100 * z * r->plan.expected_target_relative_std.maxCoeff() << " %; a D-optimal plan of "
      << o.num_postures << " postures: ±" << 100 * r->d_optimal_target_half_width << " %)";
  }
  r->lines.push_back(m.str());
  // The promise is first order: where a target bends within its band
  // (the smallest depth switching to another lobe or speed), the band of
  // the campaign will be wider.
  r->target_linearity = CheckTargetLinearity(r->config, targets, o.target_quantity, o.cut_path,
                                             p.target_gradients, r->plan.expected_relative_std,
                                             r->plan.expected_target_relative_std, z);
  WarnWhereTargetsBend(o, r);
  if (o.target_half_width > 0.0 && r->plan.postures_for_target_width > 0) {
    std::ostringstream w;
    w << "the first " << r->plan.postures_for_target_width << " postures of the plan ("
      << r->plan.postures_for_target_width * p.directions_per_posture * static_cast<int>(p.masses_kg.size())
      << " load cases) bring every target within ±" << 100 * o.target_half_width << " %"
      << (r->band_uncertain ? " to first order (not where a target bends: see the warnings)" : "");
    r->lines.push_back(w.str());
  }
}

// The planner's findings, and a warning for each joint the plan would
// determine only weakly where it matters.
void AddPlanWarnings(const KqPlanOptions& o, KqPlanResult* r) {
  const identification::PlanOptions& p = r->planner;
  const int n = r->model->num_joints();
  for (const Finding& f : r->plan.verdict.findings) {
    r->warnings.push_back(f.message + (f.input_index == n - 1 ? " (" + o.points_name + ")" : ""));
  }
  for (int j = 0; j < n; ++j) {
    if (r->plan.expected_determination[j] != identification::Determination::kWeak) continue;
    if (!identification::TargetsDependOnJoint(p, j)) continue;  // a targeted plan need not determine it
    std::ostringstream m;
    // Four digits: 10.02 % rounded to "10 %" read as the threshold it exceeds.
    m << "joint " << j + 1 << " would be weakly determined (±" << FormatNumber(100 * r->plan.expected_relative_std(j), 4)
      << " % at 1 sigma, over the 10 % of a determined joint): plan more postures (" << o.num_postures_name << ")"
      << (j == n - 1 ? " or put the load point and the target farther off the tool axis" : "");
    r->warnings.push_back(m.str());
  }
}

}  // namespace

KqPlanResult RunKqPlan(const KqPlanOptions& o, const MessageSink& on_message) {
  o.Validate();
  KqPlanResult r;
  r.config = workflows::LoadRobotConfigChecked(o.robot_path);
  for (const std::string& w : r.config.implausible) Tell(on_message, Message::Kind::kWarning, w);
  r.model = r.config.Build();
  CheckOptionUnits(o, &r);
  for (const std::string& w : r.option_findings) Tell(on_message, Message::Kind::kWarning, w);
  const std::vector<io::Posture> targets = SetUpPlanner(o, on_message, &r);
  try {
    r.plan = identification::PlanLoadTests(*r.model, r.planner);
  } catch (const std::invalid_argument& e) {
    // "PlanLoadTests: only 0 feasible postures found for 4 requested: lower
    // min_load_height or widen max_rope_angle": named as the options are.
    const std::string m = e.what();
    const size_t colon = m.find(": lower min_load_height");
    if (m.rfind("PlanLoadTests: only ", 0) != 0 || colon == std::string::npos) throw;
    throw std::invalid_argument(
        m.substr(15, colon - 15) + ": widen " + o.max_rope_angle_name + " (now " +
        FormatNumber(o.max_rope_angle_deg, 6) + " deg), or move the load point (" + o.load_point_name +
        ") where the robot holds it at least " + FormatNumber(r.planner.min_load_height, 3) +
        " m above the floor");
  }
  // A band the plan does not reach and narrower than 0.5 %: most likely a
  // fraction typed for a percentage (0.05 for 5 %); the finding says so.
  if (o.target_half_width > 0.0 && o.target_half_width < 0.005 && r.plan.postures_for_target_width == 0) {
    const std::string w = o.target_half_width_name + ": a band of ±" + FormatNumber(100 * o.target_half_width, 3) +
                          " % is not reached; was ±" + FormatNumber(1e4 * o.target_half_width, 3) +
                          " % meant (a fraction typed for a percentage)?";
    Tell(on_message, Message::Kind::kWarning, w);
    r.option_findings.push_back(w);
  }
  AddExpectedStdLines(o, &r);
  if (!targets.empty()) ReportTargets(o, targets, &r);
  AddPlanWarnings(o, &r);
  return r;
}

nlohmann::json KqPlanResult::Summary() const {
  nlohmann::json j;
  j["flagged"] = flagged();
  j["num_postures"] = planner.num_postures;
  j["num_load_cases"] = static_cast<int>(plan.cases.size());
  j["log_det_information"] = plan.log_det_information;
  nlohmann::json joints = nlohmann::json::array();
  for (Eigen::Index k = 0; k < plan.expected_std_dev.size(); ++k) {
    nlohmann::json jj;
    jj["joint"] = static_cast<int>(k) + 1;
    jj["stiffness_Nm_per_rad"] = model->joint_stiffness()(k);
    jj["expected_std_Nm_per_rad"] = plan.expected_std_dev(k);
    // JSON has no infinity: a joint the plan cannot determine is null.
    if (std::isfinite(plan.expected_relative_std(k))) jj["expected_relative_std"] = plan.expected_relative_std(k);
    else jj["expected_relative_std"] = nullptr;
    jj["determination"] = identification::ToString(plan.expected_determination[static_cast<size_t>(k)]);
    joints.push_back(jj);
  }
  j["joints"] = joints;
  if (!target_quantity.empty()) {
    nlohmann::json t;
    t["quantity"] = target_quantity;
    nlohmann::json targets = nlohmann::json::array();
    for (size_t i = 0; i < target_half_widths.size(); ++i) {
      nlohmann::json x;
      x["id"] = target_half_widths[i].first;
      x["half_width_95_pct"] = 100 * target_half_widths[i].second;
      if (i < target_linearity.size()) {
        const TargetLinearity& c = target_linearity[i];
        if (std::isfinite(c.departure)) x["departure_in_half_widths"] = c.departure;
        else x["departure_in_half_widths"] = nullptr;
        x["departure_joint"] = c.joint;
      }
      targets.push_back(x);
    }
    t["targets"] = targets;
    t["d_optimal_worst_half_width_95_pct"] = 100 * d_optimal_target_half_width;
    if (planner.target_half_width > 0.0) {
      t["band_pct"] = 100 * planner.target_half_width;
      t["postures_for_band"] = plan.postures_for_target_width;
      t["postures_for_band_estimate"] = plan.postures_for_target_width_estimate;
      t["band_uncertain"] = band_uncertain;
    }
    j["targets"] = t;
  }
  nlohmann::json w = nlohmann::json::array();
  for (const std::string& s : config.implausible) w.push_back(s);
  for (const std::string& s : option_findings) w.push_back(s);
  for (const std::string& s : warnings) w.push_back(s);
  j["warnings"] = w;
  return j;
}

io::LoadTestPlanHeader KqPlanResult::PlanHeader(const KqPlanOptions& o) const {
  io::LoadTestPlanHeader h;
  h.num_postures = o.num_postures;
  h.robot_config = config.path;
  h.tracker_noise_mm = o.noise_mm;
  h.masses_kg = o.masses_kg;
  h.load_point = planner.p_load_tip;
  h.target = planner.p_target_tip;
  if (!target_quantity.empty()) {
    const bool frequency = target_quantity == "frequency";
    h.design = std::string("load tests targeted at the ") +
               (frequency ? "lowest natural frequency" : "smallest ZOA critical depth") + " at the postures of " +
               o.target_postures_path;
    h.more.push_back({"target_postures", o.target_postures_path});
    h.more.push_back({"target_quantity", target_quantity});
    if (!frequency) h.more.push_back({"target_cut", o.cut_path});
    std::string widths;
    for (const auto& [id, hw] : target_half_widths) {
      widths += (widths.empty() ? "" : " ") + id + "=" + FormatNumber(100 * hw, 3);
    }
    h.more.push_back({"target_half_width_95_pct", widths});
    if (planner.target_half_width > 0.0) {
      h.more.push_back({"target_band_pct", FormatNumber(100 * planner.target_half_width, 6)});
      h.more.push_back({"postures_for_target_band", std::to_string(plan.postures_for_target_width)});
    }
  }
  return h;
}

}  // namespace robomach::workflows
