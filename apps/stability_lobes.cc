// stability-lobes: regenerative stability lobes (ZOA and/or first-order
// semi-discretization) of a tool tip given by the robot model at a
// posture, by a measured or predicted FRF file, or by a modal table.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <climits>
#include <cstdio>
#include <cmath>
#include <filesystem>
#include <functional>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>

#include "cli_support.h"
#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/dynamics/tool_tip_frf.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/cut_file.h"
#include "robomach/io/number_format.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/prediction_files.h"
#include "robomach/io/robot_config.h"
#include "robomach/io/tip_dynamics_files.h"
#include "robomach/report/modal_fit_plot.h"
#include "robomach/report/plot.h"
#include "robomach/report/posture_json.h"
#include "robomach/stability/measured_tip_model.h"
#include "robomach/stability/semi_discretization.h"
#include "robomach/stability/tool_tip_model.h"
#include "robomach/stability/zoa_lobes.h"

namespace robomach::apps {
namespace {

// Speeds went rpm -> rad/s -> rpm; 1e-9 rpm is far below any meaningful
// speed and hides the last-bit residue (6000.000000000001).
double RoundRpm(double rpm) { return std::round(rpm * 1e9) / 1e9; }

constexpr char kTool[] = "stability-lobes";

// The modal fit of one direct FRF of a measured file.
struct DirectionFit {
  std::string label;  // "P1 Hxx", for messages and the plot
  stability::DirectFrfFit fit;
};

// The tool-tip dynamics of one source, oriented into the cutting frame.
struct TipDynamics {
  std::string id;
  Eigen::VectorXd freq_hz;                  // grid of the FRF
  std::vector<Eigen::Matrix2cd> Phi_C;      // in-plane oriented FRF [m/N]
  stability::TipModalModel modes_C;         // for the semi-discretization
  bool modes_fitted{false};                 // fitted to an FRF (not given)
  bool no_modes{false};                     // fitted, but no mode: no SD
  std::vector<DirectionFit> fits;           // measured FRFs: one per direct FRF fitted
  Eigen::Matrix3d R_BC{Eigen::Matrix3d::Identity()};  // frame of the modal table written
};

struct LobeRow {
  std::string id, method;
  stability::LobePoint point;
};

// FRF files, CSV or UFF58 by extension; reader warnings go to stderr, and
// so do receptances outside the plausible range (counted: exit 3).
int g_implausible_frfs = 0;
std::vector<io::FrfSetOfPose> ReadFrfFile(const std::string& path) {
  std::vector<std::string> warnings;
  auto sets = io::ReadTipFrfs(path, "", &warnings);
  for (const std::string& w : warnings) Warn(kTool, w);
  for (const std::string& f : io::ReceptanceUnitFindings(sets)) {
    Warn(kTool, "implausible (unit mistake?): " + f);
    ++g_implausible_frfs;
  }
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
    throw UsageError(option + " " + text + ": expected a non-zero vector x,y,z");
  }
  return {v[0], v[1], v[2]};
}

// The shown id of a posture of an FRF file: an FRF without a posture
// (pose_id "") is shown as the file's stem.
std::string ShownId(const std::string& pose_id, const std::string& path) {
  return pose_id.empty() ? std::filesystem::path(path).stem().string() : pose_id;
}

// The direct FRFs a file's posture gives, and how many FRFs it gives.
std::vector<int> DirectFrfs(const io::FrfSetOfPose& s, int* total) {
  std::vector<int> d;
  *total = 0;
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) *total += s.present[a][b];
    if (s.present[a][a]) d.push_back(a);
  }
  return d;
}

// One direct FRF of a posture as an Frf (all lines, 0 Hz included).
dynamics::Frf DirectFrf(const io::FrfSetOfPose& s, int a) {
  Eigen::VectorXcd h(s.freq_hz.size());
  for (Eigen::Index k = 0; k < h.size(); ++k) h(k) = s.H[k](a, a);
  return dynamics::Frf::FromSamples(s.freq_hz, h);
}

// Noise model and modal fit of one direct FRF, reported on stderr.
DirectionFit FitOne(const std::string& label, const dynamics::Frf& frf) {
  DirectionFit d{label, stability::FitDirectFrf(frf)};
  std::ostringstream m;
  m << kTool << ": " << label << ": noise " << d.fit.noise.description << "\n" << kTool << ": " << label
    << ": modal fit: " << d.fit.fit.message;
  for (const calibration::FittedMode& fm : d.fit.fit.modes) {
    m << "\n  " << io::FormatDouble(std::round(fm.freq_hz * 10.0) / 10.0) << " Hz, damping ratio "
      << io::FormatDouble(std::round(fm.damping_ratio * 1e4) / 1e4) << ", modal mass "
      << (fm.modal_constant.real() > 0.0 ? FormatNumber(1.0 / fm.modal_constant.real()) + " kg"
                                          : std::string("none (Re A <= 0: not a driving-point mode, left out)"));
  }
  if (std::isfinite(d.fit.noise_rms)) {
    m << "\n  rms misfit " << io::FormatDouble(std::round(d.fit.noise_rms * 100.0) / 100.0) << " x the noise";
  }
  std::cerr << m.str() << "\n";
  return d;
}

// The tool tips of a measured FRF file (and of --frf-y): the in-plane FRF
// for the ZOA, and (if `fit`) the modal model of the direct FRFs for the SD.
std::vector<TipDynamics> FrfTips(const std::string& frf_path, const std::string& frf_y_path,
                                 const std::vector<std::string>& pose_ids, const std::string& tool_axis_text,
                                 const io::CutSpec& cut, const std::string& cut_path, bool fit, int sd_modes) {
  std::vector<io::FrfSetOfPose> sets = ReadFrfFile(frf_path);
  std::vector<io::FrfSetOfPose> ysets;
  if (!frf_y_path.empty()) ysets = ReadFrfFile(frf_y_path);
  // The cutting frame, needed only when the file's FRFs are oriented.
  auto frame = [&]() {
    const Eigen::Vector3d axis = ParseVector("--tool-axis", tool_axis_text);
    try {
      return stability::CuttingFrame(axis, cut.feed_direction_B);
    } catch (const std::invalid_argument& e) {
      throw InputError({cut_path, cut.feed_line, cut.feed_column},
                       std::string("feed_direction: ") + e.what() + " (--tool-axis " + tool_axis_text + ")");
    }
  };
  auto only_direct = [](const io::FrfSetOfPose& s, const std::string& path, const std::string& id,
                        const std::string& option) {
    int total = 0;
    const std::vector<int> d = DirectFrfs(s, &total);
    if (d.size() != 1 || total != 1) {
      throw InputError({path, 0, 0}, "posture " + id + ": with --frf-y, " + option + " must give exactly one direct FRF; it gives " +
                                         std::to_string(total) + " FRFs, " + std::to_string(d.size()) + " of them direct");
    }
    return d[0];
  };
  std::vector<TipDynamics> tips;
  bool noted = false;
  for (io::FrfSetOfPose& s : sets) {
    const std::string id = ShownId(s.pose_id, frf_path);
    if (!pose_ids.empty() && std::find(pose_ids.begin(), pose_ids.end(), id) == pose_ids.end()) continue;
    int total = 0;
    const std::vector<int> direct = DirectFrfs(s, &total);
    TipDynamics t;
    t.id = id;
    // Drop a 0 Hz line (the ZOA needs ω > 0); the fit keeps every line.
    const Eigen::Index first = s.freq_hz.size() > 0 && s.freq_hz(0) == 0.0 ? 1 : 0;
    t.freq_hz = s.freq_hz.tail(s.freq_hz.size() - first);
    auto diagonal = [&](const Eigen::VectorXcd& hx, const Eigen::VectorXcd& hy) {
      t.Phi_C.assign(t.freq_hz.size(), Eigen::Matrix2cd::Zero());
      for (Eigen::Index k = 0; k < t.freq_hz.size(); ++k) {
        t.Phi_C[k](0, 0) = hx(k + first);
        t.Phi_C[k](1, 1) = hy(k + first);
      }
    };
    const Eigen::Vector3d ex = Eigen::Vector3d::UnitX(), ey = Eigen::Vector3d::UnitY();
    if (!ysets.empty()) {
      // Two files, one direct FRF each: along the feed (x_C) and normal to it (y_C).
      const int a = only_direct(s, frf_path, id, "--frf");
      const io::FrfSetOfPose* y = nullptr;
      for (const io::FrfSetOfPose& c : ysets) {
        if (ShownId(c.pose_id, frf_y_path) == id || (c.pose_id == s.pose_id)) y = &c;
      }
      if (!y && sets.size() == 1 && ysets.size() == 1) y = &ysets.front();
      if (!y) throw InputError({frf_y_path, 0, 0}, "no posture " + id + " in the file (--frf-y)");
      const int b = only_direct(*y, frf_y_path, id, "--frf-y");
      if (y->freq_hz.size() != s.freq_hz.size() || y->freq_hz != s.freq_hz) {
        throw InputError({frf_y_path, 0, 0}, "posture " + id + ": the FRF of --frf-y uses another frequency grid than "
                                                 "the one of --frf; both must use the same lines");
      }
      const dynamics::Frf hx = DirectFrf(s, a), hy = DirectFrf(*y, b);
      diagonal(hx.receptance(), hy.receptance());
      if (fit) {
        t.fits.push_back(FitOne(id + " H" + std::string(2, "xyz"[a]) + " (feed, x of the cut)", hx));
        t.fits.push_back(FitOne(id + " H" + std::string(2, "xyz"[b]) + " (normal to the feed, y of the cut)", hy));
        t.modes_C = stability::Concatenate(
            {stability::DominantModes(stability::ModesAlong(t.fits[0].fit.fit, ex), sd_modes),
             stability::DominantModes(stability::ModesAlong(t.fits[1].fit.fit, ey), sd_modes)});
      }
      t.R_BC = frame();
    } else if (direct.size() == 1 && total == 1) {
      // One direct FRF: a symmetric tool (issue #18).
      const int a = direct[0];
      const dynamics::Frf h = DirectFrf(s, a);
      diagonal(h.receptance(), h.receptance());
      if (!noted) {
        std::cerr << kTool << ": note: " << id << " has one direct FRF (H" << "xyz"[a] << "xyz"[a]
                  << "): the tool is taken as symmetric, this FRF in both in-plane directions of the cut and no "
                     "cross terms; --tool-axis does not apply\n";
        noted = true;
      }
      if (fit) {
        t.fits.push_back(FitOne(id + " H" + std::string(2, "xyz"[a]), h));
        const stability::TipModalModel mx = stability::DominantModes(stability::ModesAlong(t.fits[0].fit.fit, ex), sd_modes);
        const stability::TipModalModel my = stability::DominantModes(stability::ModesAlong(t.fits[0].fit.fit, ey), sd_modes);
        t.modes_C = stability::Concatenate({mx, my});
      }
      // The modal table is written for the default tool axis (z) unless one is given.
      try {
        t.R_BC = frame();
      } catch (const InputError&) {
        t.R_BC = Eigen::Matrix3d::Identity();
      }
    } else {
      // Several FRFs in the base frame: oriented by --tool-axis.
      const Eigen::Matrix3d R = frame();
      t.R_BC = R;
      std::vector<int> dirs;
      for (int a = 0; a < 3; ++a) {
        if (R.col(0).cwiseAbs()(a) > 1e-9 || R.col(1).cwiseAbs()(a) > 1e-9) dirs.push_back(a);
      }
      for (int a : dirs) {
        for (int b : dirs) {
          if (!s.present[a][b]) {
            if (a == b) {
              throw InputError({frf_path, 0, 0}, "posture " + id + ": the cutting plane (--tool-axis " + tool_axis_text +
                                                     ") needs FRF " + "xyz"[a] + "xyz"[b] +
                                                     ", which the file does not give; give a --tool-axis whose "
                                                     "cutting plane the file's directions span, or the second "
                                                     "direction with --frf-y from a file of one direct FRF");
            }
            Warn(kTool, frf_path + ": posture " + id + ": no cross FRF " + "xyz"[a] + "xyz"[b] + "; taken as zero");
          }
        }
      }
      std::vector<Eigen::Matrix3cd> H(s.H.begin() + first, s.H.end());
      t.Phi_C = stability::OrientInCuttingPlane(H, R);
      if (fit) {
        std::vector<stability::TipModalModel> parts;
        for (int a : dirs) {
          t.fits.push_back(FitOne(id + " H" + std::string(2, "xyz"[a]), DirectFrf(s, a)));
          parts.push_back(stability::DominantModes(
              stability::ModesAlong(t.fits.back().fit.fit, Eigen::Vector3d::Unit(a)).Rotated(R), sd_modes));
        }
        t.modes_C = stability::Concatenate(parts);
        bool cross = false;
        for (int a : dirs) {
          for (int b : dirs) cross |= a != b && s.present[a][b];
        }
        if (cross && dirs.size() == 2) {
          // Two base directions span the cutting plane: a mode seen in both
          // direct FRFs is one mode whose shape's sign the cross FRF gives.
          const int a = dirs[0], b = dirs[1];
          const int r = s.present[a][b] ? a : b, c = s.present[a][b] ? b : a;
          double lo = -INFINITY, hi = INFINITY;
          for (const DirectionFit& d : t.fits) {
            if (d.fit.noise.usable_bands.empty()) continue;
            lo = std::max(lo, d.fit.noise.usable_bands.front().first);
            hi = std::min(hi, d.fit.noise.usable_bands.back().second);
          }
          std::vector<int> lines;
          for (Eigen::Index k = 0; k < s.freq_hz.size(); ++k) {
            if (s.freq_hz(k) >= lo && s.freq_hz(k) <= hi) lines.push_back(static_cast<int>(k));
          }
          if (lines.size() >= 8) {
            Eigen::VectorXcd h(s.freq_hz.size());
            for (Eigen::Index k = 0; k < h.size(); ++k) h(k) = s.H[k](r, c);
            const dynamics::Frf cross_frf = dynamics::Frf::FromSamples(s.freq_hz, h).Select(lines);
            t.modes_C = stability::DominantModes(
                stability::ModesOfTwoDirections(t.fits[0].fit.fit, Eigen::Vector3d::Unit(a), t.fits[1].fit.fit,
                                                Eigen::Vector3d::Unit(b), cross_frf)
                    .Rotated(R),
                2 * sd_modes);
            std::cerr << kTool << ": note: " << id << ": a mode found in both H" << "xyz"[a] << "xyz"[a] << " and H"
                      << "xyz"[b] << "xyz"[b] << " is one mode of the SD's model, its shape's sign from the cross FRF H"
                      << "xyz"[r] << "xyz"[c] << "\n";
          }
        } else if (cross) {
          std::cerr << kTool << ": note: " << id << ": the SD's modal model is fitted to the direct FRFs; the "
                    "cross FRFs of the file are used by the ZOA only\n";
        }
      }
    }
    if (fit) {
      t.modes_fitted = true;
      t.no_modes = t.modes_C.num_modes() == 0;
      // The ZOA uses the measured FRF where the noise model finds it usable
      // in every fitted direction: below that (the drift of an integrated
      // accelerometer signal) and above it (the floor) a line says nothing
      // of the structure, and a drift 5x the resonance makes spurious
      // lobes of a few hertz.
      double lo = -INFINITY, hi = INFINITY;
      for (const DirectionFit& d : t.fits) {
        if (d.fit.noise.usable_bands.empty()) continue;
        lo = std::max(lo, d.fit.noise.usable_bands.front().first);
        hi = std::min(hi, d.fit.noise.usable_bands.back().second);
      }
      if (std::isfinite(lo) && std::isfinite(hi) && hi > lo) {
        std::vector<Eigen::Matrix2cd> phi;
        std::vector<double> f;
        for (Eigen::Index k = 0; k < t.freq_hz.size(); ++k) {
          if (t.freq_hz(k) >= lo && t.freq_hz(k) <= hi) {
            f.push_back(t.freq_hz(k));
            phi.push_back(t.Phi_C[k]);
          }
        }
        if (f.size() >= 3 && static_cast<Eigen::Index>(f.size()) < t.freq_hz.size()) {
          std::cerr << kTool << ": " << id << ": the ZOA uses the measured FRF in its usable band, "
                    << io::FormatDouble(lo) << " to " << io::FormatDouble(hi) << " Hz\n";
          t.freq_hz = Eigen::Map<Eigen::VectorXd>(f.data(), static_cast<Eigen::Index>(f.size()));
          t.Phi_C = std::move(phi);
        }
      }
    }
    tips.push_back(std::move(t));
  }
  if (tips.empty()) throw InputError({frf_path, 0, 0}, "none of the requested postures is in the file");
  return tips;
}

// The smallest critical depth [m] of one method over its ok points.
double MinDepth(const std::vector<LobeRow>& rows, const std::string& id, const std::string& method) {
  double m = INFINITY;
  for (const LobeRow& r : rows) {
    if (r.id == id && r.method == method && r.point.status == stability::LobeStatus::kOk) {
      m = std::min(m, r.point.critical_depth);
    }
  }
  return m;
}

// --method both: the ZOA and the SD should agree on the smallest critical
// depth at radial immersions of 0.3 and more, where the ZOA's averaged
// directional factors are accurate (Altintas & Budak 1995; the SD is exact
// up to its discretisation). The SD's speed grid is coarse and its lobes
// lie a little apart from the ZOA's, so its minimum is also searched on 7
// speeds within ±4 % of the bottom of each of the (at most 4) lowest ZOA
// lobes (`sd_at`); the ZOA's lobe bottoms are all about equally deep, the
// SD's are not (on issue #18's tap test, 0.886 mm at lobe 0 and 0.971 mm
// at lobe 2 against the ZOA's 0.896 mm).
using SdAt = std::function<std::vector<stability::LobePoint>(const TipDynamics&, const Eigen::VectorXd&)>;
void CompareZoaAndSd(const std::vector<TipDynamics>& tips, const std::vector<LobeRow>& rows,
                     const io::CutSpec& cut, const SdAt& sd_at, bool* flagged) {
  if (cut.process.radial_immersion < 0.3) return;
  for (const TipDynamics& t : tips) {
    double sd = MinDepth(rows, t.id, "sd");
    const double zoa = MinDepth(rows, t.id, "zoa");
    if (!std::isfinite(sd) || !std::isfinite(zoa)) continue;
    std::map<int, const LobeRow*> bottom;  // lowest ZOA point of each lobe
    for (const LobeRow& r : rows) {
      if (r.id != t.id || r.method != "zoa" || r.point.status != stability::LobeStatus::kOk) continue;
      const LobeRow*& b = bottom[r.point.lobe_index];
      if (!b || r.point.critical_depth < b->point.critical_depth) b = &r;
    }
    std::vector<const LobeRow*> lows;
    for (const auto& [k, r] : bottom) {
      if (r->point.critical_depth <= 1.2 * zoa) lows.push_back(r);
    }
    std::sort(lows.begin(), lows.end(),
              [](const LobeRow* a, const LobeRow* b) { return a->point.critical_depth < b->point.critical_depth; });
    if (lows.size() > 4) lows.resize(4);
    for (const LobeRow* r : lows) {
      const double lo = std::max(cut.spindle_speed_min_rad_s, 0.96 * r->point.spindle_speed_rad_s);
      const double hi = std::min(cut.spindle_speed_max_rad_s, 1.04 * r->point.spindle_speed_rad_s);
      if (!(hi > lo)) continue;
      for (const stability::LobePoint& p : sd_at(t, Eigen::VectorXd::LinSpaced(7, lo, hi))) {
        if (p.status == stability::LobeStatus::kOk) sd = std::min(sd, p.critical_depth);
      }
    }
    const double diff = std::abs(sd - zoa) / std::min(sd, zoa);
    std::ostringstream m;
    m << t.id << ": smallest critical depth SD " << FormatNumber(MToMm(sd)) << " mm, ZOA " << FormatNumber(MToMm(zoa)) << " mm";
    if (diff > 0.10) {
      Warn(kTool, m.str() + ": they differ by " + io::FormatDouble(std::round(diff * 1000.0) / 10.0) +
                      " % (more than 10 % at a radial immersion of " + io::FormatDouble(cut.process.radial_immersion) +
                      ", where they should agree): check " +
                      (t.fits.empty() ? std::string("") : "the modal fit (--fit-plot), ") +
                      "the modes the SD keeps (--sd-modes) and its steps per tooth period (--sd-steps)");
      *flagged = true;
    } else {
      std::cerr << kTool << ": " << m.str() << " (they agree within 10 %)\n";
    }
  }
}

// --modes-out: the modes the SD used, in the frame of the file's FRFs
// (p_B = R_BC p_C), as docs/formats.md §4's modal table.
void WriteFittedModes(const std::string& path, const std::vector<TipDynamics>& tips) {
  std::vector<std::string> ids;
  std::vector<std::vector<dynamics::Mode>> modes;
  for (const TipDynamics& t : tips) {
    ids.push_back(t.id);
    modes.emplace_back();
    for (int k = 0; k < t.modes_C.num_modes(); ++k) {
      dynamics::Mode m;
      m.freq_hz = RadPerSecToHz(t.modes_C.omega_rad_s(k));
      m.damping_ratio = t.modes_C.zeta(k);
      m.p_T = t.R_BC * t.modes_C.p.col(k);
      m.modal_mass_kg = 1.0 / m.p_T.squaredNorm();
      Eigen::Index big = 0;
      m.p_T.cwiseAbs().maxCoeff(&big);
      m.shape_T = m.p_T.normalized() * (m.p_T(big) < 0.0 ? -1.0 : 1.0);
      for (int i = 0; i < 3; ++i) m.shape_T(i) = m.shape_T(i) == 0.0 ? 0.0 : m.shape_T(i);  // no "-0"
      modes.back().push_back(m);
    }
  }
  io::WriteModalTableCsv(path, ids, modes);
}

// --fit-plot: each fitted direct FRF with its modal fit, magnitude and phase.
void PlotFits(const std::string& path, const std::string& frf_path, const std::vector<TipDynamics>& tips) {
  int n = 0;
  for (const TipDynamics& t : tips) n += static_cast<int>(t.fits.size());
  if (n == 0) return;
  report::Figure fig(2 * n, 1, 1000, 330);
  fig.title = "robomach stability-lobes: modal fits of " + std::filesystem::path(frf_path).filename().string();
  int row = 0;
  for (const TipDynamics& t : tips) {
    for (const DirectionFit& d : t.fits) {
      std::ostringstream title;
      title << d.label << ": " << d.fit.fit.modes.size() << " modes";
      if (std::isfinite(d.fit.noise_rms)) {
        title << ", rms misfit " << io::FormatDouble(std::round(d.fit.noise_rms * 100.0) / 100.0) << " x noise";
      }
      title << "; " << calibration::DescribeUsable(d.fit.noise);
      report::FillModalFitPanels(d.fit.measured, d.fit.noise, d.fit.fit, title.str(), &fig.at(row, 0),
                                 &fig.at(row + 1, 0));
      row += 2;
    }
  }
  fig.SavePng(path);
}

int Run(int argc, char** argv) {
  CLI::App app{
      "stability-lobes: regenerative chatter stability lobes (spindle speed against critical\n"
      "axial depth) by the zero-order approximation (Altintas-Budak) and/or first-order\n"
      "semi-discretization (Insperger-Stepan), for the robot model at postures, a measured\n"
      "FRF file (docs/formats.md §3) or a modal table (§4)."};
  AddVersionFlag(app, kTool);
  app.footer(ExitCodeHelp() +
             " Exit 3 when some speeds have no stability boundary, when a measured receptance is outside "
             "1e-12..1e-3 m/N (a unit mistake, e.g. a mobility read as receptance), when a measured FRF's modal fit is poor "
             "(misfit above 3 x the noise), finds no mode (then no SD lobes) or a mode at the edge of the usable "
             "band, when the FRF is not a passive driving point (Im H > 0 on more than 5 % of its usable lines), "
             "or when --method both finds the "
             "SD's and the ZOA's smallest depths more than 10 % apart at a radial immersion of 0.3 or more.");
  std::string robot_path, cut_path, postures_path, frf_path, frf_y_path, modal_path, out_path, plot_path,
      fit_plot_path, modes_out_path, summary_path, method = "zoa", tool_axis_text = "0,0,1";
  std::vector<std::string> pose_ids;
  int speeds = 0, sd_speeds = 60, sd_steps = 0, sd_modes = 3, threads = 0, max_lobe = 30;
  double sd_max_depth_mm = 20.0;
  const stability::SdOptions sd_defaults;
  double sd_steps_per_mode = sd_defaults.steps_per_mode_period;
  app.add_option("--cut", cut_path, "cut file YAML (config/cut_demo.yaml): tool, immersion, coefficients, speed range")->required();
  app.add_option("--robot", robot_path, "robot config YAML; with --postures and --posture");
  app.add_option("--postures", postures_path, "posture file CSV: pose_id,q1_deg..q6_deg");
  app.add_option("--posture", pose_ids, "pose_id to analyse (repeatable); all postures of the file if omitted");
  app.add_option("--frf", frf_path,
                 "tool-tip FRF file, CSV of docs/formats.md §3 or UFF58 (.uff/.unv; receptance, mobility or accelerance); "
                 "one direct FRF (any direction) = a symmetric tool, the same FRF in both in-plane directions of the cut");
  app.add_option("--frf-y", frf_y_path,
                 "with --frf: a second file with the one direct FRF normal to the feed in the cutting plane; --frf is "
                 "then the FRF along the feed (no cross terms)");
  app.add_option("--fit-plot", fit_plot_path,
                 "with --frf: PNG of each direct FRF with its modal fit (magnitude, phase, noise floor, usable band)")
      ->check(PngFileName());
  app.add_option("--modes-out", modes_out_path,
                 "with --frf: the modal table the SD used (docs/formats.md §4), in the frame of the FRF file; --modal-table "
                 "reads it back (with the same --tool-axis, and --sd-modes of at least its number of modes)");
  app.add_option("--modal-table", modal_path, "modal table CSV (docs/formats.md §4): freq_hz, damping_ratio, modal_mass_kg or modal_stiffness_N_per_m, ux,uy,uz");
  app.add_option("--tool-axis", tool_axis_text, "with --frf/--modal-table: tool axis from tip to spindle in the FRF frame, x,y,z (not used for a "
                 "file with one direct FRF, a symmetric tool, except for the frame of --modes-out)")->capture_default_str();
  app.add_option("--method", method, "zoa, sd or both")->check(CLI::IsMember({"zoa", "sd", "both"}))->capture_default_str();
  app.add_option("--out", out_path, "lobes CSV (spindle_speed_rpm, critical_depth_mm, chatter_freq_hz, lobe_index, method); stdout if omitted");
  app.add_option("--plot", plot_path, "lobe diagram PNG (speed [rpm] against depth [mm])")->check(PngFileName());
  app.add_option("--summary", summary_path,
                 "summary JSON (docs/formats.md §4.1): inputs, per posture and method the smallest and largest "
                 "critical depth and their speeds, status; '-' = stdout");
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
  app.add_option("--sd-modes", sd_modes,
                 "SD: number of modes kept (largest in-plane compliance); with --frf, per fitted direct FRF")
      ->capture_default_str();
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
      throw UsageError("give exactly one tool-tip source: --robot (with --postures), --frf or --modal-table");
    }
    if (!robot_path.empty() && postures_path.empty()) throw UsageError("--robot needs --postures");
    if (frf_path.empty()) {
      for (const auto& [o, v] : {std::pair{"--frf-y", &frf_y_path}, {"--fit-plot", &fit_plot_path},
                                 {"--modes-out", &modes_out_path}}) {
        if (!v->empty()) throw UsageError(std::string(o) + " needs --frf");
      }
    }
    if ((sd_steps != 0 && sd_steps < 2) || sd_speeds < 1 || sd_modes < 1 || !(sd_max_depth_mm > 0.0) || speeds < 0 ||
        max_lobe < 0) {
      throw UsageError(
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
                        {"--frf", frf_path}, {"--frf-y", frf_y_path}, {"--modal-table", modal_path}},
                       {{"--out", out_path}, {"--plot", plot_path}, {"--fit-plot", fit_plot_path},
                        {"--modes-out", modes_out_path}, {"--summary", summary_path}});
    for (const auto& [p, what] : {std::pair{robot_path, "robot config"}, {postures_path, "posture file"},
                                  {frf_path, "FRF file"}, {frf_y_path, "FRF file (--frf-y)"},
                                  {modal_path, "modal table"}}) {
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
    } else if (!frf_path.empty()) {
      // Always fitted: the noise model's usable band serves the ZOA too.
      tips = FrfTips(frf_path, frf_y_path, pose_ids, tool_axis_text, cut, cut_path, true, sd_modes);
    } else {
      const Eigen::Vector3d axis = ParseVector("--tool-axis", tool_axis_text);
      Eigen::Matrix3d R;
      try {
        R = stability::CuttingFrame(axis, cut.feed_direction_B);
      } catch (const std::invalid_argument& e) {
        throw InputError({cut_path, cut.feed_line, cut.feed_column}, std::string("feed_direction: ") + e.what() + " (--tool-axis " + tool_axis_text + ")");
      }
      for (const io::ModalTableEntry& e : io::ReadModalTable(modal_path)) {
        if (!pose_ids.empty() && std::find(pose_ids.begin(), pose_ids.end(), e.pose_id) == pose_ids.end()) continue;
        TipDynamics t;
        t.id = e.pose_id;
        t.freq_hz = stability::LobeFrequencyGrid(e.modes, cut.process.teeth, cut.spindle_speed_max_rad_s, kLines);
        t.Phi_C = stability::OrientInCuttingPlane(stability::ModalReceptance(e.modes, t.freq_hz), R);
        t.modes_C = e.modes.Rotated(R);
        tips.push_back(std::move(t));
      }
      if (tips.empty()) throw InputError({modal_path, 0, 0}, "none of the requested postures is in the file");
    }
    bool flagged = g_implausible_frfs > 0;
    for (const TipDynamics& t : tips) {
      for (const DirectionFit& d : t.fits) {
        if (d.fit.not_driving_point) {
          Warn(kTool, d.label + ": Im H > 0 (beyond twice the noise) on " +
                          io::FormatDouble(std::round(d.fit.active_fraction * 1000.0) / 10.0) +
                          " % of the usable lines: this is not the driving-point receptance of a passive structure "
                          "(response and excitation at different points, e.g. a transfer FRF, or in opposite "
                          "directions, or another sign convention), so the lobes from it do not describe a tool tip");
          flagged = true;
        }
        for (double f : d.fit.edge_modes_hz) {
          Warn(kTool, d.label + ": the mode at " + io::FormatDouble(std::round(f * 10.0) / 10.0) +
                          " Hz reaches past the edge of the usable band (" + calibration::DescribeUsable(d.fit.noise) +
                          "): the fit saw one flank only, and it may model the drift or the noise floor beyond "
                          "the band rather than the tool (see --fit-plot)");
          flagged = true;
        }
        if (d.fit.poor) {
          Warn(kTool, d.label + ": " + d.fit.problem +
                          (d.fit.fit.modes.empty() ? "" : "; the SD uses these modes all the same (see --fit-plot)"));
          flagged = true;
        }
      }
      if (do_sd && t.no_modes) {
        Warn(kTool, t.id + ": no mode was fitted, so no SD lobes (the ZOA uses the measured FRF)");
        flagged = true;
      }
    }

    stability::SdOptions so;
    so.steps_per_period = sd_steps;
    so.steps_per_mode_period = sd_steps_per_mode;
    so.max_depth = MmToM(sd_max_depth_mm);
    const SdAt sd_at = [&](const TipDynamics& t, const Eigen::VectorXd& speeds) {
      const stability::TipModalModel m = t.modes_fitted ? t.modes_C : stability::DominantModes(t.modes_C, sd_modes);
      return stability::SdLobes(m, cut.process, speeds, so, threads, nullptr);
    };
    std::vector<LobeRow> rows;
    bool no_boundary = false;
    for (const TipDynamics& t : tips) {
      if (do_zoa) {
        stability::ZoaOptions zo;
        zo.max_lobe_index = max_lobe;
        zo.min_spindle_speed_rad_s = cut.spindle_speed_min_rad_s;
        const auto lobes = stability::ComputeZoaLobes(t.freq_hz, t.Phi_C, cut.process, zo);
        for (const auto& p : lobes.At(zoa_speeds)) {
          rows.push_back({t.id, "zoa", p});
          no_boundary |= p.status != stability::LobeStatus::kOk;
        }
      }
      if (do_sd && t.modes_C.num_modes() > 0) {
        // Fitted models keep --sd-modes per direct FRF already (FrfTips).
        const stability::TipModalModel m = t.modes_fitted ? t.modes_C : stability::DominantModes(t.modes_C, sd_modes);
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
          no_boundary |= p.status == stability::LobeStatus::kUnstableAtZero;
        }
      }
    }

    if (do_zoa && do_sd) CompareZoaAndSd(tips, rows, cut, sd_at, &flagged);

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
    io::WriteFileAtomically(out_path.empty() ? "-" : out_path, write);
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
    if (!modes_out_path.empty()) WriteFittedModes(modes_out_path, tips);
    if (!fit_plot_path.empty()) PlotFits(fit_plot_path, frf_path, tips);
    if (no_boundary) Warn(kTool, "some speeds have no boundary (status column): widen the FRF band or the lobe range");
    flagged |= no_boundary;
    if (!summary_path.empty()) {
      nlohmann::json j;
      j["tool"] = kTool;
      j["cut"] = cut_path;
      j["source"] = !robot_path.empty() ? "robot" : !frf_path.empty() ? "frf" : "modal_table";
      if (!robot_path.empty()) {
        j["robot"] = robot_path;
        j["postures"] = postures_path;
      }
      if (!frf_path.empty()) j["frf"] = frf_path;
      if (!frf_y_path.empty()) j["frf_y"] = frf_y_path;
      if (!modal_path.empty()) j["modal_table"] = modal_path;
      j["method"] = method;
      j["teeth"] = cut.process.teeth;
      j["radial_immersion"] = cut.process.radial_immersion;
      j["lobes_csv"] = out_path.empty() ? "-" : out_path;
      nlohmann::json results = nlohmann::json::array();
      for (const TipDynamics& t : tips) {
        for (const char* m : {"zoa", "sd"}) {
          nlohmann::json r;
          int points = 0, ok = 0;
          double min_depth = INFINITY, max_depth = -INFINITY, min_speed = NAN, max_speed = NAN, min_freq = NAN;
          for (const LobeRow& row : rows) {
            if (row.id != t.id || row.method != m) continue;
            ++points;
            const auto& p = row.point;
            if (!std::isfinite(p.critical_depth)) continue;
            ++ok;
            const double d = MToMm(p.critical_depth), rpm = RoundRpm(RadPerSecToRpm(p.spindle_speed_rad_s));
            if (d < min_depth) {
              min_depth = d;
              min_speed = rpm;
              min_freq = p.chatter_freq_hz;
            }
            if (d > max_depth) {
              max_depth = d;
              max_speed = rpm;
            }
          }
          if (points == 0) continue;
          r["pose_id"] = t.id;
          r["method"] = m;
          r["speeds"] = points;
          r["speeds_with_boundary"] = ok;
          if (ok > 0) {
            r["min_critical_depth_mm"] = min_depth;
            r["min_critical_depth_speed_rpm"] = min_speed;
            if (std::isfinite(min_freq)) r["min_critical_depth_chatter_freq_hz"] = min_freq;
            r["max_critical_depth_mm"] = max_depth;
            r["max_critical_depth_speed_rpm"] = max_speed;
          }
          results.push_back(r);
        }
      }
      j["lobes"] = results;
      j["no_boundary_at_some_speeds"] = no_boundary;
      j["flagged"] = flagged;
      j["exit_code"] = flagged ? kExitFlagged : kExitOk;
      io::WriteFileAtomically(summary_path, report::DumpJson(j));
    }
    return flagged ? kExitFlagged : kExitOk;
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
