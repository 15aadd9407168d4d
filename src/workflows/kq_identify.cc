#include "robomach/workflows/kq_identify.h"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/common/units.h"
#include "robomach/identification/load_case.h"
#include "robomach/io/kq_files.h"

namespace robomach::workflows {
namespace {

void Tell(const MessageSink& sink, Message::Kind kind, const std::string& text) {
  if (sink) sink({kind, text});
}

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
  if (!robust.empty() && robust != "none" && robust != "cauchy" && robust != "huber") {
    throw OptionError("robust", "robust: expected cauchy or huber (or none for least squares), got " + robust);
  }
}

nlohmann::json KqIdentifyResult::Summary() const {
  identification::JointStiffnessResult f = fit;
  f.advice.insert(f.advice.begin(), unit_findings.begin(), unit_findings.end());
  nlohmann::json j = io::KqSummaryJson(f);
  j["flagged"] = flagged();
  return j;
}

KqIdentifyResult RunKqIdentify(const KqIdentifyOptions& o, const MessageSink& on_message,
                               const std::function<void(long, long)>& progress) {
  o.Validate();
  KqIdentifyResult r;
  r.config = io::LoadRobotConfig(o.robot_path);
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
  if (o.robust == "cauchy") opt.loss = identification::RobustLoss::kCauchy;
  if (o.robust == "huber") opt.loss = identification::RobustLoss::kHuber;
  r.fit = identification::IdentifyJointStiffness(*r.model, r.cases, opt, progress);
  return r;
}

std::vector<std::string> KqReportLines(const identification::JointStiffnessResult& r) {
  std::vector<std::string> out;
  std::ostringstream head;
  head << r.num_cases << " load cases, fit " << identification::ToString(r.status) << " (" << r.iterations
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
}

KqPlanResult RunKqPlan(const KqPlanOptions& o, const MessageSink& on_message) {
  o.Validate();
  KqPlanResult r;
  r.config = io::LoadRobotConfig(o.robot_path);
  for (const std::string& w : r.config.implausible) Tell(on_message, Message::Kind::kWarning, w);
  r.model = r.config.Build();
  identification::PlanOptions& p = r.planner;
  p.num_postures = o.num_postures;
  p.tracker_noise = MmToM(o.noise_mm);
  p.seed = o.seed;
  p.p_load_tip = o.load_point_m;
  p.p_target_tip = o.target_m;
  p.masses_kg = o.masses_kg;
  p.max_rope_angle = DegToRad(o.max_rope_angle_deg);
  r.plan = identification::PlanLoadTests(*r.model, p);
  const int n = r.model->num_joints();
  std::ostringstream head;
  head << "plan of " << o.num_postures << " postures x " << p.directions_per_posture << " rope directions x "
       << o.masses_kg.size() << " masses = " << r.plan.cases.size()
       << " load cases; expected standard deviations for a tracker noise of " << o.noise_mm << " mm:";
  r.lines.push_back(head.str());
  for (int j = 0; j < n; ++j) {
    std::ostringstream rel, row;
    if (std::isfinite(r.plan.expected_relative_std(j))) {
      rel << std::fixed << std::setprecision(2) << 100 * r.plan.expected_relative_std(j) << " %";
    } else {
      rel << "not determined";
    }
    row << "  joint " << j + 1 << ": k = " << Sci(r.model->joint_stiffness()(j)) << " N·m/rad, std dev "
        << Sci(r.plan.expected_std_dev(j), 2) << " N·m/rad (" << rel.str() << ")";
    r.lines.push_back(row.str());
  }
  for (const Finding& f : r.plan.findings) {
    r.warnings.push_back(f.message + (f.input_index == n - 1 ? " (" + o.points_name + ")" : ""));
  }
  for (int j = 0; j < n; ++j) {
    if (r.plan.expected_determination[j] != identification::Determination::kWeak) continue;
    std::ostringstream m;
    m << "joint " << j + 1 << " would be weakly determined (±" << std::fixed << std::setprecision(0)
      << 100 * r.plan.expected_relative_std(j) << " % at 1 sigma): plan more postures (" << o.num_postures_name << ")"
      << (j == n - 1 ? " or put the load point and the target farther off the tool axis" : "");
    r.warnings.push_back(m.str());
  }
  return r;
}

}  // namespace robomach::workflows
