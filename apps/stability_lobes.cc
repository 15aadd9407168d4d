// stability-lobes: regenerative stability lobes (ZOA and/or first-order
// semi-discretization) of a tool tip given by the robot model at a
// posture, by a measured or predicted FRF file, or by a modal table.
#include <CLI/CLI.hpp>

#include <climits>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>

#include "cli_support.h"
#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/dynamics/tool_tip_frf.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/cut_file.h"
#include "robomach/io/number_format.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/robot_config.h"
#include "robomach/io/tip_dynamics_files.h"
#include "robomach/report/plot.h"
#include "robomach/stability/modal_fit.h"
#include "robomach/stability/semi_discretization.h"
#include "robomach/stability/tool_tip_model.h"
#include "robomach/stability/zoa_lobes.h"

namespace robomach::apps {
namespace {

// Speeds went rpm -> rad/s -> rpm; 1e-9 rpm is far below any meaningful
// speed and hides the last-bit residue (6000.000000000001).
double RoundRpm(double rpm) { return std::round(rpm * 1e9) / 1e9; }

constexpr char kTool[] = "stability-lobes";

// The tool-tip dynamics of one source, oriented into the cutting frame.
struct TipDynamics {
  std::string id;
  Eigen::VectorXd freq_hz;                  // grid of the FRF
  std::vector<Eigen::Matrix2cd> Phi_C;      // in-plane oriented FRF [m/N]
  stability::TipModalModel modes_C;         // for the semi-discretization
  bool modes_fitted{false};                 // fitted to an FRF (not given)
};

struct LobeRow {
  std::string id, method;
  stability::LobePoint point;
};

// FRF files, CSV or UFF58 by extension; reader warnings go to stderr.
std::vector<io::FrfSetOfPose> ReadFrfFile(const std::string& path) {
  std::vector<std::string> warnings;
  auto sets = io::ReadTipFrfs(path, "", &warnings);
  for (const std::string& w : warnings) Warn(kTool, w);
  return sets;
}

Eigen::Vector3d ParseVector(const std::string& option, const std::string& text) {
  std::stringstream ss(text);
  std::string item;
  std::vector<double> v;
  while (std::getline(ss, item, ',')) {
    double x = 0.0;
    if (!io::ParseFiniteNumber(item, &x)) break;
    v.push_back(x);
  }
  if (v.size() != 3 || Eigen::Vector3d(v[0], v[1], v[2]).norm() == 0.0) {
    throw std::invalid_argument(option + " " + text + ": expected a non-zero vector x,y,z");
  }
  return {v[0], v[1], v[2]};
}

int Run(int argc, char** argv) {
  CLI::App app{
      "stability-lobes: regenerative chatter stability lobes (spindle speed against critical\n"
      "axial depth) by the zero-order approximation (Altintas-Budak) and/or first-order\n"
      "semi-discretization (Insperger-Stepan), for the robot model at postures, a measured\n"
      "FRF file (formats.md §3) or a modal table (§4)."};
  app.footer(ExitCodeHelp());
  std::string robot_path, cut_path, postures_path, frf_path, modal_path, out_path, plot_path,
      method = "zoa", tool_axis_text = "0,0,1";
  std::vector<std::string> pose_ids;
  int speeds = 0, sd_speeds = 60, sd_steps = 0, sd_modes = 3, threads = 0, max_lobe = 30;
  double sd_max_depth_mm = 20.0;
  const stability::SdOptions sd_defaults;
  double sd_steps_per_mode = sd_defaults.steps_per_mode_period;
  app.add_option("--cut", cut_path, "cut file YAML (config/cut_demo.yaml): tool, immersion, coefficients, speed range")->required();
  app.add_option("--robot", robot_path, "robot config YAML; with --postures and --posture");
  app.add_option("--postures", postures_path, "posture file CSV: pose_id,q1_deg..q6_deg");
  app.add_option("--posture", pose_ids, "pose_id to analyse (repeatable); all postures of the file if omitted");
  app.add_option("--frf", frf_path, "tool-tip FRF file, CSV of formats.md §3 or UFF58 (.uff/.unv; receptance, mobility or accelerance)");
  app.add_option("--modal-table", modal_path, "modal table CSV (formats.md §4): freq_hz, damping_ratio, modal_mass_kg or modal_stiffness_N_per_m, ux,uy,uz");
  app.add_option("--tool-axis", tool_axis_text, "with --frf/--modal-table: tool axis from tip to spindle in the FRF frame, x,y,z")->capture_default_str();
  app.add_option("--method", method, "zoa, sd or both")->check(CLI::IsMember({"zoa", "sd", "both"}))->capture_default_str();
  app.add_option("--out", out_path, "lobes CSV (spindle_speed_rpm, critical_depth_mm, chatter_freq_hz, lobe_index, method); stdout if omitted");
  app.add_option("--plot", plot_path, "lobe diagram PNG (speed [rpm] against depth [mm])");
  app.add_option("--speeds", speeds, "ZOA: number of spindle speeds in the cut's range (default: the cut file's spindle_speed_count)");
  app.add_option("--max-lobe", max_lobe, "ZOA: highest lobe index traced")->capture_default_str();
  app.add_option("--sd-speeds", sd_speeds, "SD: number of spindle speeds in the cut's range")->capture_default_str();
  app.add_option("--sd-steps", sd_steps,
                 "SD: steps per tooth period at every speed; 0 = automatic (--sd-steps-per-mode-period steps per period of "
                 "the highest retained mode, at least " + std::to_string(sd_defaults.min_steps_per_period) +
                 " per tooth period, at most what keeps the monodromy matrix within " +
                 std::to_string(sd_defaults.max_monodromy_dimension) + " rows)")->capture_default_str();
  app.add_option("--sd-steps-per-mode-period", sd_steps_per_mode,
                 "SD, automatic steps: steps per period of the highest retained mode")->capture_default_str();
  app.add_option("--sd-modes", sd_modes, "SD: number of modes kept (largest in-plane compliance)")->capture_default_str();
  app.add_option("--sd-max-depth-mm", sd_max_depth_mm, "SD: largest depth searched [mm]")->capture_default_str();
  app.add_option("--threads", threads, "SD: worker threads, 0 = all cores")->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }

  return RunGuarded(kTool, [&]() -> int {
    const int sources = (!robot_path.empty()) + (!frf_path.empty()) + (!modal_path.empty());
    if (sources != 1) {
      throw std::invalid_argument("give exactly one tool-tip source: --robot (with --postures), --frf or --modal-table");
    }
    if (!robot_path.empty() && postures_path.empty()) throw std::invalid_argument("--robot needs --postures");
    if ((sd_steps != 0 && sd_steps < 2) || sd_speeds < 1 || sd_modes < 1 || !(sd_max_depth_mm > 0.0) || speeds < 0 ||
        max_lobe < 0) {
      throw std::invalid_argument(
          "expected --sd-steps 0 (automatic) or >= 2, --sd-speeds >= 1, --sd-modes >= 1, --sd-max-depth-mm > 0");
    }
    // Bounds that keep a typo from hours of work or an allocation failure.
    CheckOptionRange("--speeds", speeds, 0, 100000);
    CheckOptionRange("--sd-speeds", sd_speeds, 1, 10000);
    CheckOptionRange("--sd-steps", sd_steps, 0, 1000);
    CheckOptionRange("--sd-steps-per-mode-period", sd_steps_per_mode, 4.0, 1000.0);
    CheckOptionRange("--sd-modes", sd_modes, 1, 200);
    CheckOptionRange("--sd-max-depth-mm", sd_max_depth_mm, 1e-6, 1e4);
    CheckOptionRange("--threads", threads, 0, 256);
    CheckOptionRange("--max-lobe", max_lobe, 0, 1000);
    RequireReadableFile(cut_path, "cut file");
    CheckDistinctPaths({{"--cut", cut_path}, {"--robot", robot_path}, {"--postures", postures_path},
                        {"--frf", frf_path}, {"--modal-table", modal_path}},
                       {{"--out", out_path}, {"--plot", plot_path}});
    for (const auto& [p, what] : {std::pair{robot_path, "robot config"}, {postures_path, "posture file"},
                                  {frf_path, "FRF file"}, {modal_path, "modal table"}}) {
      if (!p.empty()) RequireReadableFile(p, what);
    }
    const io::CutSpec cut = io::ReadCutFile(cut_path);
    const bool do_zoa = method != "sd", do_sd = method != "zoa";
    const Eigen::VectorXd zoa_speeds = Eigen::VectorXd::LinSpaced(
        speeds > 0 ? speeds : cut.spindle_speed_count, cut.spindle_speed_min_rad_s, cut.spindle_speed_max_rad_s);
    const Eigen::VectorXd sd_speed_grid =
        Eigen::VectorXd::LinSpaced(sd_speeds, cut.spindle_speed_min_rad_s, cut.spindle_speed_max_rad_s);
    constexpr int kLines = 4000;  // log grid: ~ln(100)/4000 ≈ 1e-3 relative spacing, < ζ/10 for ζ ≥ 1 %

    std::vector<TipDynamics> tips;
    if (!robot_path.empty()) {
      const auto model = io::LoadRobotConfig(robot_path).Build();
      const auto postures = io::ReadPostureFile(postures_path, model->num_joints());
      std::vector<const io::Posture*> chosen;
      for (const std::string& id : pose_ids) {
        auto it = std::find_if(postures.begin(), postures.end(), [&](const auto& p) { return p.id == id; });
        if (it == postures.end()) {
          std::string known;
          for (const auto& p : postures) known += (known.empty() ? "" : ", ") + p.id;
          throw InputError({postures_path, 0, 0}, "no posture \"" + id + "\" in the file; it has " + known);
        }
        chosen.push_back(&*it);
      }
      if (chosen.empty()) for (const auto& p : postures) chosen.push_back(&p);
      dynamics::PostureEvaluator ev(model);
      for (const io::Posture* p : chosen) {
        const dynamics::PostureDynamics d = ev.Evaluate(p->q);
        if (d.near_singular) {
          Warn(kTool, postures_path + ":" + std::to_string(p->line) + ": posture " + p->id +
                          " is near a singularity; the tool-tip FRF (joint space) stays valid");
        }
        TipDynamics t;
        t.id = p->id;
        Eigen::Matrix3d R;
        try {
          R = stability::CuttingFrameAtPosture(d.X_BT, cut.feed_direction_B);
        } catch (const std::invalid_argument& e) {
          throw InputError({cut_path, cut.feed_line, cut.feed_column}, std::string("feed_direction: ") + e.what() + " at posture " + p->id);
        }
        const stability::TipModalModel modes = stability::ModalModelFromPosture(d);
        t.freq_hz = stability::LobeFrequencyGrid(modes, cut.process.teeth, cut.spindle_speed_max_rad_s, kLines);
        t.Phi_C = stability::OrientInCuttingPlane(dynamics::Receptance(d, t.freq_hz), R);
        t.modes_C = modes.Rotated(R);
        tips.push_back(std::move(t));
      }
    } else {
      const Eigen::Vector3d axis = ParseVector("--tool-axis", tool_axis_text);
      Eigen::Matrix3d R;
      try {
        R = stability::CuttingFrame(axis, cut.feed_direction_B);
      } catch (const std::invalid_argument& e) {
        throw InputError({cut_path, cut.feed_line, cut.feed_column}, std::string("feed_direction: ") + e.what() + " (--tool-axis " + tool_axis_text + ")");
      }
      if (!frf_path.empty()) {
        for (io::FrfSetOfPose& s : ReadFrfFile(frf_path)) {
          if (!pose_ids.empty() && std::find(pose_ids.begin(), pose_ids.end(), s.pose_id) == pose_ids.end()) continue;
          // Which base directions the cutting plane needs.
          std::vector<int> dirs;
          for (int a = 0; a < 3; ++a) {
            if (R.col(0).cwiseAbs()(a) > 1e-9 || R.col(1).cwiseAbs()(a) > 1e-9) dirs.push_back(a);
          }
          for (int a : dirs) {
            for (int b : dirs) {
              if (!s.present[a][b]) {
                if (a == b) {
                  throw InputError({frf_path, 0, 0}, "posture " + s.pose_id + ": the cutting plane needs FRF " +
                                                         "xyz"[a] + "xyz"[b] + ", which the file does not give");
                }
                Warn(kTool, frf_path + ": posture " + s.pose_id + ": no cross FRF " + "xyz"[a] + "xyz"[b] +
                                "; taken as zero");
              }
            }
          }
          TipDynamics t;
          t.id = s.pose_id;
          // Drop a 0 Hz line (the ZOA needs ω > 0).
          const Eigen::Index first = s.freq_hz.size() > 0 && s.freq_hz(0) == 0.0 ? 1 : 0;
          t.freq_hz = s.freq_hz.tail(s.freq_hz.size() - first);
          std::vector<Eigen::Matrix3cd> H(s.H.begin() + first, s.H.end());
          t.Phi_C = stability::OrientInCuttingPlane(H, R);
          if (do_sd) {
            t.modes_C = stability::FitModesPeakPicking(t.freq_hz, t.Phi_C, sd_modes);
            t.modes_fitted = true;
            if (t.modes_C.num_modes() == 0) {
              throw InputError({frf_path, 0, 0}, "posture " + s.pose_id + ": no resonance peak found to fit modes for --method sd");
            }
          }
          tips.push_back(std::move(t));
        }
      } else {
        for (const io::ModalTableEntry& e : io::ReadModalTable(modal_path)) {
          if (!pose_ids.empty() && std::find(pose_ids.begin(), pose_ids.end(), e.pose_id) == pose_ids.end()) continue;
          TipDynamics t;
          t.id = e.pose_id;
          t.freq_hz = stability::LobeFrequencyGrid(e.modes, cut.process.teeth, cut.spindle_speed_max_rad_s, kLines);
          t.Phi_C = stability::OrientInCuttingPlane(stability::ModalReceptance(e.modes, t.freq_hz), R);
          t.modes_C = e.modes.Rotated(R);
          tips.push_back(std::move(t));
        }
      }
      if (tips.empty()) {
        throw InputError({!frf_path.empty() ? frf_path : modal_path, 0, 0}, "none of the requested postures is in the file");
      }
    }

    std::vector<LobeRow> rows;
    bool flagged = false;
    for (const TipDynamics& t : tips) {
      if (do_zoa) {
        stability::ZoaOptions zo;
        zo.max_lobe_index = max_lobe;
        zo.min_spindle_speed_rad_s = cut.spindle_speed_min_rad_s;
        const auto lobes = stability::ComputeZoaLobes(t.freq_hz, t.Phi_C, cut.process, zo);
        for (const auto& p : lobes.At(zoa_speeds)) {
          rows.push_back({t.id, "zoa", p});
          flagged |= p.status != stability::LobeStatus::kOk;
        }
      }
      if (do_sd) {
        stability::SdOptions so;
        so.steps_per_period = sd_steps;
        so.steps_per_mode_period = sd_steps_per_mode;
        so.max_depth = MmToM(sd_max_depth_mm);
        const stability::TipModalModel m = stability::DominantModes(t.modes_C, sd_modes);
        // Say what discretisation is used, before the (possibly long) work.
        int k_lo = INT_MAX, k_hi = 0;
        bool capped = false;
        for (Eigen::Index i = 0; i < sd_speed_grid.size(); ++i) {
          bool c = false;
          const int k = stability::SdStepsPerPeriod(m, cut.process, sd_speed_grid(i), so, &c);
          k_lo = std::min(k_lo, k);
          k_hi = std::max(k_hi, k);
          capped |= c;
        }
        {
          std::ostringstream msg;
          msg << kTool << ": SD of " << t.id << ": " << m.num_modes() << " mode" << (m.num_modes() > 1 ? "s" : "")
              << " kept (highest " << io::FormatDouble(std::round(10.0 * RadPerSecToHz(m.omega_rad_s.maxCoeff())) / 10.0)
              << " Hz); steps per tooth period " << k_lo;
          if (k_hi != k_lo) msg << " to " << k_hi;
          if (sd_steps > 0) {
            msg << " (--sd-steps)";
          } else {
            msg << " (automatic: " << io::FormatDouble(sd_steps_per_mode) << " per period of the highest mode, at least "
                << so.min_steps_per_period << ")";
          }
          std::cerr << msg.str() << "\n";
        }
        if (capped) {
          Warn(kTool, "SD of " + t.id + ": at the lowest speeds the automatic steps per tooth period were capped "
                          "at " + std::to_string(k_hi) + " (monodromy matrix of " +
                          std::to_string(so.max_monodromy_dimension) + " rows), fewer than " +
                          io::FormatDouble(sd_steps_per_mode) + " per period of the highest mode: the lobes there "
                          "are less accurate (fewer modes, --sd-modes, or --sd-steps to force more steps)");
        }
        ProgressLine progress(kTool, "SD speeds of " + t.id, sd_speed_grid.size() >= 20 ? 1000 : 0);
        const auto pts = stability::SdLobes(m, cut.process, sd_speed_grid, so, threads,
                                            [&](long done, long total) { progress.Update(done * 1000 / total); });
        progress.Finish();
        for (const auto& p : pts) {
          rows.push_back({t.id, "sd", p});
          flagged |= p.status == stability::LobeStatus::kUnstableAtZero;
        }
      }
    }

    auto write = [&](std::ostream& os) {
      os << "pose_id,spindle_speed_rpm,critical_depth_mm,chatter_freq_hz,lobe_index,method,status,sd_steps\n";
      for (const LobeRow& r : rows) {
        const auto& p = r.point;
        os << r.id << ',' << io::FormatDouble(RoundRpm(RadPerSecToRpm(p.spindle_speed_rad_s))) << ','
           << (std::isfinite(p.critical_depth) ? io::FormatDouble(MToMm(p.critical_depth)) : "") << ','
           << (std::isfinite(p.chatter_freq_hz) ? io::FormatDouble(p.chatter_freq_hz) : "") << ','
           << (p.lobe_index >= 0 ? std::to_string(p.lobe_index) : "") << ',' << r.method << ','
           << stability::ToString(p.status) << ',' << (p.sd_steps > 0 ? std::to_string(p.sd_steps) : "") << '\n';
      }
    };
    if (out_path.empty()) {
      write(std::cout);
    } else {
      io::WriteFileAtomically(out_path, write);
    }
    if (!plot_path.empty()) {
      report::Figure fig(1, 1, 1000, 560);
      fig.title = "robomach stability-lobes: " + cut_path;
      report::Axes& ax = fig.at(0, 0);
      ax.title = std::to_string(cut.process.teeth) + " teeth, a_e/D = " + io::FormatDouble(cut.process.radial_immersion) +
                 (cut.process.direction == stability::MillingDirection::kUp ? ", up-milling" : ", down-milling");
      ax.x_label = "spindle speed [rpm]";
      ax.y_label = "critical axial depth [mm]";
      ax.y_min = 0.0;
      int color = 0;
      for (const TipDynamics& t : tips) {
        for (const char* m : {"zoa", "sd"}) {
          report::Series s;
          for (const LobeRow& r : rows) {
            if (r.id != t.id || r.method != m) continue;
            s.x.push_back(RadPerSecToRpm(r.point.spindle_speed_rad_s));
            s.y.push_back(r.point.status == stability::LobeStatus::kOk ? MToMm(r.point.critical_depth) : NAN);
          }
          if (s.x.empty()) continue;
          s.label = t.id + " " + (std::string(m) == "zoa" ? "ZOA" : "SD");
          s.color = report::PaletteColor(color++);
          s.markers = std::string(m) == "sd";
          ax.series.push_back(std::move(s));
        }
      }
      fig.SavePng(plot_path);
    }
    if (flagged) Warn(kTool, "some speeds have no boundary (status column): widen the FRF band or the lobe range");
    return flagged ? kExitFlagged : kExitOk;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
