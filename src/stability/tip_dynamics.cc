#include "robomach/stability/tip_dynamics.h"

#include <algorithm>
#include <map>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "robomach/calibration/frf_noise.h"
#include "robomach/common/errors.h"
#include "robomach/common/option_validate.h"
#include "robomach/common/number_format.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/frf_prediction.h"
#include "robomach/dynamics/tool_tip_frf.h"

namespace robomach::stability {
namespace {

// The shown id of a posture of an FRF file: an FRF without a posture
// (pose_id "") is shown as the file's stem.
std::string ShownId(const std::string& pose_id, const std::string& path) {
  return pose_id.empty() ? std::filesystem::path(path).stem().string() : pose_id;
}

// The direct FRFs a file's posture gives, and how many FRFs it gives.
std::vector<int> DirectFrfs(const TipFrfs& s, int* total) {
  std::vector<int> d;
  *total = 0;
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) *total += s.present[a][b];
    if (s.present[a][a]) d.push_back(a);
  }
  return d;
}

// One direct FRF of a posture as an Frf (all lines, 0 Hz included).
dynamics::Frf DirectFrf(const TipFrfs& s, int a) {
  Eigen::VectorXcd h(s.freq_hz.size());
  for (Eigen::Index k = 0; k < h.size(); ++k) h(k) = s.H[k](a, a);
  return dynamics::Frf::FromSamples(s.freq_hz, h);
}

std::string Hname(int a, int b) { return std::string("H") + "xyz"[a] + "xyz"[b]; }

// Refines a measured tip's ZOA grid between its lines: a line at f between
// measured lines f_i and f_i+1 gets Φ_fit(f) + the linear interpolation of
// the residual Φ_meas − Φ_fit of the two (Φ_fit: the in-plane receptance of
// t->fit_C), so the measured lines stay as measured and the fit supplies
// the resonance's shape between them. Without it, the ZOA on a hammer
// test's grid misses lobes: on frf-synth's 0.25 Hz lines (KR210 demo
// posture P1, a 19.0 Hz mode of ζ 0.027, half-power band 4 lines wide) the
// lobe of index 0 at 6000 rpm has its chatter frequency at 18.9 Hz, where
// the branch goes from no boundary to a boundary between two lines, and
// the ZOA's smallest depth came out 2.08 mm against 0.57 mm from the modes
// (and from the SD). Lines are added until the relative spacing is
// kRefinedSpacing (the model grid's, kLobeGridLines), at most kMaxPerGap
// per gap. A fitted mode narrower than its gap (2ζf below the line
// spacing: its damping is not in the data) is left out of Φ_fit. Returns
// the number of lines added.
int RefineBetweenLines(TipDynamics* t) {
  constexpr double kRefinedSpacing = 1e-3;
  constexpr int kMaxPerGap = 64;
  const Eigen::Index L = t->freq_hz.size();
  if (L < 2 || t->fit_C.num_modes() == 0) return 0;
  const Eigen::VectorXd& f = t->freq_hz;
  // The fitted modes broader than the line spacing around them.
  std::vector<int> keep;
  for (int k = 0; k < t->fit_C.num_modes(); ++k) {
    const double fk = RadPerSecToHz(t->fit_C.omega_rad_s(k));
    const Eigen::Index j = std::clamp<Eigen::Index>(
        static_cast<Eigen::Index>(std::lower_bound(f.data(), f.data() + L, fk) - f.data()), 1, L - 1);
    if (2.0 * t->fit_C.zeta(k) * fk >= f(j) - f(j - 1)) keep.push_back(k);
  }
  if (keep.empty()) return 0;
  TipModalModel m;
  m.omega_rad_s.resize(static_cast<Eigen::Index>(keep.size()));
  m.zeta.resize(m.omega_rad_s.size());
  m.p.resize(3, m.omega_rad_s.size());
  for (size_t j = 0; j < keep.size(); ++j) {
    m.omega_rad_s(j) = t->fit_C.omega_rad_s(keep[j]);
    m.zeta(j) = t->fit_C.zeta(keep[j]);
    m.p.col(j) = t->fit_C.p.col(keep[j]);
  }
  std::vector<double> fine;
  std::vector<std::pair<Eigen::Index, double>> at;  // (gap i, weight of line i+1)
  for (Eigen::Index i = 0; i + 1 < L; ++i) {
    fine.push_back(f(i));
    at.push_back({i, 0.0});
    const double gap = f(i + 1) - f(i);
    const int n = std::clamp(static_cast<int>(std::ceil(gap / (kRefinedSpacing * f(i)))), 1, kMaxPerGap);
    for (int r = 1; r < n; ++r) {
      const double w = static_cast<double>(r) / n;
      fine.push_back(f(i) + w * gap);
      at.push_back({i, w});
    }
  }
  fine.push_back(f(L - 1));
  at.push_back({L - 2, 1.0});
  const int added = static_cast<int>(fine.size()) - static_cast<int>(L);
  if (added == 0) return 0;
  const Eigen::VectorXd fv = Eigen::Map<const Eigen::VectorXd>(fine.data(), static_cast<Eigen::Index>(fine.size()));
  const std::vector<Eigen::Matrix2cd> model_fine = InPlaneModalReceptance(m, fv);
  const std::vector<Eigen::Matrix2cd> model_lines = InPlaneModalReceptance(m, f);
  std::vector<Eigen::Matrix2cd> phi(fine.size());
  for (size_t j = 0; j < fine.size(); ++j) {
    const auto [i, w] = at[j];
    const Eigen::Matrix2cd r0 = t->Phi_C[i] - model_lines[i], r1 = t->Phi_C[i + 1] - model_lines[i + 1];
    phi[j] = model_fine[j] + (1.0 - w) * r0 + w * r1;
  }
  // The measured lines exactly as measured (no rounding of model + residual).
  for (size_t j = 0; j < fine.size(); ++j) {
    const auto [i, w] = at[j];
    if (w == 0.0) phi[j] = t->Phi_C[i];
    if (w == 1.0) phi[j] = t->Phi_C[i + 1];
  }
  t->freq_hz = fv;
  t->Phi_C = std::move(phi);
  return added;
}

// Noise model and modal fit of one direct FRF, told to `on_message`.
DirectionFit FitOne(const std::string& label, const dynamics::Frf& frf, const MessageSink& on_message) {
  DirectionFit d{label, FitDirectFrf(frf), ""};
  std::ostringstream m;
  m << label << ": noise " << d.fit.noise.description << "\n" << label << ": modal fit: " << d.fit.fit.message;
  for (const calibration::FittedMode& fm : d.fit.fit.modes) {
    m << "\n  " << FormatDouble(std::round(fm.freq_hz * 10.0) / 10.0) << " Hz, damping ratio "
      << FormatDouble(std::round(fm.damping_ratio * 1e4) / 1e4) << ", modal mass "
      << (fm.modal_constant.real() > 0.0 ? FormatNumber(1.0 / fm.modal_constant.real()) + " kg"
                                          : std::string("none (Re A <= 0: not a driving-point mode, left out)"));
  }
  if (std::isfinite(d.fit.noise_rms)) {
    m << "\n  rms misfit " << FormatDouble(std::round(d.fit.noise_rms * 100.0) / 100.0) << " x the noise";
  }
  if (on_message) on_message({Message::Kind::kInfo, m.str()});
  return d;
}

// FitOne, unless an earlier fit of the tip (`fits`) is of an identical FRF
// (the same lines, every value equal): each distinct FRF is fitted once
// (issue #34 item 6), its result reused under the new label.
DirectionFit FitOrReuse(const std::string& label, const dynamics::Frf& frf, const std::vector<DirectionFit>& fits,
                        const MessageSink& on_message) {
  for (const DirectionFit& d : fits) {
    if (!d.same_as.empty()) continue;
    const dynamics::Frf& m = d.fit.measured;
    if (m.size() == frf.size() && m.freq_hz() == frf.freq_hz() && m.receptance() == frf.receptance()) {
      if (on_message) {
        on_message({Message::Kind::kInfo, label + ": the same FRF as " + d.label + " (every line equal): its noise "
                                                "model and modal fit are reused"});
      }
      return DirectionFit{label, d.fit, d.label};
    }
  }
  return FitOne(label, frf, on_message);
}

// The band [lo, hi] usable in every fitted direction (±inf where none says).
std::pair<double, double> CommonUsableBand(const std::vector<DirectionFit>& fits) {
  double lo = -INFINITY, hi = INFINITY;
  for (const DirectionFit& d : fits) {
    if (d.fit.noise.usable_bands.empty()) continue;
    lo = std::max(lo, d.fit.noise.usable_bands.front().first);
    hi = std::min(hi, d.fit.noise.usable_bands.back().second);
  }
  return {lo, hi};
}

}  // namespace

std::string TipFrfsUnitFinding(const TipFrfs& s) {
  // A frequency axis in kHz first: the receptance's band means nothing then
  // (io::FrequencyUnitFindings, the other readers' rule).
  const std::string where = s.source + (s.pose_id.empty() ? std::string() : ": posture " + s.pose_id);
  if (s.freq_hz.size() > 0) {
    if (std::string f = dynamics::FrequencyAxisFinding(where, s.freq_hz.maxCoeff()); !f.empty()) return f;
  }
  // Each FRF on its own usable band (issue #34 item 5): a tap test's drift
  // lines below ~100 Hz reach 1e-3 m/N on a 1e-6 m/N tool tip.
  calibration::UsableBandPeak largest;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (!s.present[i][j]) continue;
      Eigen::VectorXcd h(static_cast<Eigen::Index>(s.H.size()));
      for (size_t k = 0; k < s.H.size(); ++k) h(static_cast<Eigen::Index>(k)) = s.H[k](i, j);
      const calibration::UsableBandPeak p =
          calibration::PeakReceptanceInUsableBand(dynamics::Frf::FromSamples(s.freq_hz, h));
      if (p.peak_m_per_N > largest.peak_m_per_N) largest = p;
    }
  }
  return calibration::UsableBandUnitFinding(where, largest);
}

TipDynamics TipFromPosture(const std::string& id, const dynamics::PostureDynamics& d, const Eigen::Vector3d& feed_B,
                           int teeth, double max_speed_rad_s, int lines) {
  const Eigen::Matrix3d R = CuttingFrameAtPosture(d.X_BT, feed_B);
  TipDynamics t;
  t.id = id;
  const TipModalModel modes = ModalModelFromPosture(d);
  t.freq_hz = LobeFrequencyGrid(modes, teeth, max_speed_rad_s, lines);
  t.Phi_C = OrientInCuttingPlane(dynamics::Receptance(d, t.freq_hz), R);
  t.modes_C = modes.Rotated(R);
  t.R_BC = R;
  return t;
}

TipDynamics TipFromModes(const std::string& id, const TipModalModel& modes_B, const Eigen::Matrix3d& R_BC, int teeth,
                         double max_speed_rad_s, int lines) {
  TipDynamics t;
  t.id = id;
  t.freq_hz = LobeFrequencyGrid(modes_B, teeth, max_speed_rad_s, lines);
  t.Phi_C = OrientInCuttingPlane(ModalReceptance(modes_B, t.freq_hz), R_BC);
  t.modes_C = modes_B.Rotated(R_BC);
  t.R_BC = R_BC;
  return t;
}

namespace {

// What the postures of one TipsFromMeasuredFrfs call share: the files, the
// options, the message sink, and what is said once for all postures.
struct MeasuredTipsContext {
  const std::vector<TipFrfs>& sets;   // --frf
  const std::vector<TipFrfs>& ysets;  // --frf-y (empty: none)
  const MeasuredTipOptions& o;
  const MessageSink& on_message;
  bool noted = false;  // the note of a symmetric tool said
  // Missing cross FRFs, said once for the file (a direct-only test of five
  // postures gave ten warnings).
  std::map<std::string, std::string> no_cross;  // posture -> its missing pairs ("xy, yx")

  void Tell(Message::Kind kind, const std::string& text) const {
    if (on_message) on_message({kind, text});
  }
  // The cutting frame; the FRFs of a posture with more than one direction need it.
  Eigen::Matrix3d Frame() const {
    if (!o.cutting_frame) throw std::invalid_argument("TipsFromMeasuredFrfs: the FRFs need a cutting frame, and none was given");
    return o.cutting_frame();
  }
  // A unit finding is said before the fits' reports (a kHz axis came after
  // 60 lines of fits in kHz); ComputeLobes flags it without saying it again.
  void SayUnits(TipDynamics* t) const {
    if (t->unit_finding.empty()) return;
    Tell(Message::Kind::kWarning, "implausible (unit mistake?): " + t->unit_finding);
    t->unit_finding_said = static_cast<bool>(on_message);  // else ComputeLobes says it
  }
};

// The one direct FRF of posture `id` of a file given with --frf-y (`option`
// names the file's flag); throws an InputError if it gives anything else.
int OnlyDirect(const TipFrfs& s, const std::string& path, const std::string& id, const std::string& option) {
  int total = 0;
  const std::vector<int> d = DirectFrfs(s, &total);
  if (d.size() != 1 || total != 1) {
    throw InputError({path, 0, 0}, "posture " + id + ": with --frf-y, " + option + " must give exactly one direct FRF; it gives " +
                                       std::to_string(total) + " FRFs, " + std::to_string(d.size()) + " of them direct");
  }
  return d[0];
}

// t->Phi_C diagonal, hx along x_C and hy along y_C, from line `first` on
// (t->freq_hz's lines).
void SetDiagonal(TipDynamics* t, Eigen::Index first, const Eigen::VectorXcd& hx, const Eigen::VectorXcd& hy) {
  t->Phi_C.assign(t->freq_hz.size(), Eigen::Matrix2cd::Zero());
  for (Eigen::Index k = 0; k < t->freq_hz.size(); ++k) {
    t->Phi_C[k](0, 0) = hx(k + first);
    t->Phi_C[k](1, 1) = hy(k + first);
  }
}

// The tip of posture s from two files, one direct FRF each: along the feed
// (x_C, --frf) and normal to it (y_C, --frf-y). `first`: the first line kept.
void TipFromTwoFiles(const MeasuredTipsContext& c, const TipFrfs& s, Eigen::Index first, TipDynamics* t_ptr) {
  TipDynamics& t = *t_ptr;
  const MeasuredTipOptions& o = c.o;
  const std::string& id = t.id;
  const Eigen::Vector3d ex = Eigen::Vector3d::UnitX(), ey = Eigen::Vector3d::UnitY();
  const int a = OnlyDirect(s, o.frf_path, id, "--frf");
  const TipFrfs* y = nullptr;
  for (const TipFrfs& yc : c.ysets) {
    if (ShownId(yc.pose_id, o.frf_y_path) == id || (yc.pose_id == s.pose_id)) y = &yc;
  }
  if (!y && c.sets.size() == 1 && c.ysets.size() == 1) y = &c.ysets.front();
  if (!y) throw InputError({o.frf_y_path, 0, 0}, "no posture " + id + " in the file (--frf-y)");
  const int b = OnlyDirect(*y, o.frf_y_path, id, "--frf-y");
  if (y->freq_hz.size() != s.freq_hz.size() || y->freq_hz != s.freq_hz) {
    throw InputError({o.frf_y_path, 0, 0}, "posture " + id + ": the FRF of --frf-y uses another frequency grid than "
                                               "the one of --frf; both must use the same lines");
  }
  if (const std::string fy = TipFrfsUnitFinding(*y); !fy.empty()) {
    t.unit_finding += (t.unit_finding.empty() ? "" : "; ") + fy;
  }
  const dynamics::Frf hx = DirectFrf(s, a), hy = DirectFrf(*y, b);
  SetDiagonal(&t, first, hx.receptance(), hy.receptance());
  c.SayUnits(&t);
  if (o.fit) {
    t.fits.push_back(FitOne(id + " " + Hname(a, a) + " (feed, x of the cut)", hx, c.on_message));
    t.fits.push_back(FitOrReuse(id + " " + Hname(b, b) + " (normal to the feed, y of the cut)", hy, t.fits,
                                c.on_message));
    t.fit_C = Concatenate({ModesAlong(t.fits[0].fit.fit, ex), ModesAlong(t.fits[1].fit.fit, ey)});
    t.modes_C = Concatenate({DominantModes(ModesAlong(t.fits[0].fit.fit, ex), o.sd_modes),
                             DominantModes(ModesAlong(t.fits[1].fit.fit, ey), o.sd_modes)});
  }
  t.R_BC = c.Frame();
}

// The tip of posture s from its one direct FRF (direction a): a symmetric
// tool (issue #18). `first`: the first line kept.
void TipFromOneDirect(MeasuredTipsContext& c, const TipFrfs& s, int a, Eigen::Index first, TipDynamics* t_ptr) {
  TipDynamics& t = *t_ptr;
  const MeasuredTipOptions& o = c.o;
  const std::string& id = t.id;
  const Eigen::Vector3d ex = Eigen::Vector3d::UnitX(), ey = Eigen::Vector3d::UnitY();
  const dynamics::Frf h = DirectFrf(s, a);
  SetDiagonal(&t, first, h.receptance(), h.receptance());
  if (!c.noted) {
    c.Tell(Message::Kind::kNote, id + " has one direct FRF (" + Hname(a, a) +
                                     "): the tool is taken as symmetric, this FRF in both in-plane directions of "
                                     "the cut and no cross terms; --tool-axis does not apply");
    c.noted = true;
  }
  c.SayUnits(&t);
  if (o.fit) {
    t.fits.push_back(FitOne(id + " " + Hname(a, a), h, c.on_message));
    const TipModalModel mx = DominantModes(ModesAlong(t.fits[0].fit.fit, ex), o.sd_modes);
    const TipModalModel my = DominantModes(ModesAlong(t.fits[0].fit.fit, ey), o.sd_modes);
    t.modes_C = Concatenate({mx, my});
    t.fit_C = Concatenate({ModesAlong(t.fits[0].fit.fit, ex), ModesAlong(t.fits[0].fit.fit, ey)});
  }
  // The modal table is written for the default tool axis (z) unless one is given.
  if (o.cutting_frame) {
    try {
      t.R_BC = o.cutting_frame();
    } catch (const InputError&) {
      t.R_BC = Eigen::Matrix3d::Identity();
    }
  }
}

// The modes of a tip of several FRFs in the base frame: a fit of each
// direct FRF of the base directions `dirs` that span the cutting plane
// (frame R), and, where a cross FRF couples two of them, one model of the
// two directions.
void FitBaseFrameModes(const MeasuredTipsContext& ctx, const TipFrfs& s, const std::vector<int>& dirs,
                       const Eigen::Matrix3d& R, TipDynamics* t_ptr) {
  TipDynamics& t = *t_ptr;
  const MeasuredTipOptions& o = ctx.o;
  const std::string& id = t.id;
  std::vector<TipModalModel> parts, all;
  for (int a : dirs) {
    t.fits.push_back(FitOrReuse(id + " " + Hname(a, a), DirectFrf(s, a), t.fits, ctx.on_message));
    all.push_back(ModesAlong(t.fits.back().fit.fit, Eigen::Vector3d::Unit(a)).Rotated(R));
    parts.push_back(DominantModes(all.back(), o.sd_modes));
  }
  t.modes_C = Concatenate(parts);
  t.fit_C = Concatenate(all);
  bool two_dir_model = false;  // the modes of two directions coupled by the cross FRF
  bool cross = false;
  for (int a : dirs) {
    for (int b : dirs) cross |= a != b && s.present[a][b];
  }
  if (cross && dirs.size() == 2) {
    // Two base directions span the cutting plane: a mode seen in both
    // direct FRFs is one mode whose shape's sign the cross FRF gives.
    const int a = dirs[0], b = dirs[1];
    const int r = s.present[a][b] ? a : b, c = s.present[a][b] ? b : a;
    const auto [lo, hi] = CommonUsableBand(t.fits);
    std::vector<int> lines;
    for (Eigen::Index k = 0; k < s.freq_hz.size(); ++k) {
      if (s.freq_hz(k) >= lo && s.freq_hz(k) <= hi) lines.push_back(static_cast<int>(k));
    }
    if (lines.size() >= 8) {
      Eigen::VectorXcd h(s.freq_hz.size());
      for (Eigen::Index k = 0; k < h.size(); ++k) h(k) = s.H[k](r, c);
      const dynamics::Frf cross_frf = dynamics::Frf::FromSamples(s.freq_hz, h).Select(lines);
      t.fit_C = ModesOfTwoDirections(t.fits[0].fit.fit, Eigen::Vector3d::Unit(a), t.fits[1].fit.fit,
                                     Eigen::Vector3d::Unit(b), cross_frf)
                    .Rotated(R);
      t.modes_C = DominantModes(t.fit_C, 2 * o.sd_modes);
      two_dir_model = true;
      ctx.Tell(Message::Kind::kNote, id + ": a mode found in both " + Hname(a, a) + " and " + Hname(b, b) +
                                         " is one mode of the SD's model, its shape's sign from the cross FRF " +
                                         Hname(r, c));
    }
  } else if (cross) {
    ctx.Tell(Message::Kind::kNote, id + ": the SD's modal model is fitted to the direct FRFs; the cross FRFs "
                                       "of the file are used by the ZOA only");
  }
  t.fit_lacks_cross = cross && !two_dir_model;
}

// The tip of posture s from several FRFs in the base frame, oriented by the
// tool axis; a missing cross FRF is noted in c.no_cross. `first`: the
// first line kept.
void TipFromBaseFrame(MeasuredTipsContext& c, const TipFrfs& s, Eigen::Index first, TipDynamics* t_ptr) {
  TipDynamics& t = *t_ptr;
  const MeasuredTipOptions& o = c.o;
  const std::string& id = t.id;
  const Eigen::Matrix3d R = c.Frame();
  t.R_BC = R;
  std::vector<int> dirs;
  for (int a = 0; a < 3; ++a) {
    if (R.col(0).cwiseAbs()(a) > 1e-9 || R.col(1).cwiseAbs()(a) > 1e-9) dirs.push_back(a);
  }
  for (int a : dirs) {
    for (int b : dirs) {
      if (!s.present[a][b]) {
        if (a == b) {
          throw InputError({o.frf_path, 0, 0}, "posture " + id + ": the cutting plane (" + o.tool_axis_source +
                                                   ") needs FRF " + "xyz"[a] + "xyz"[b] +
                                                   ", which the file does not give; give a --tool-axis whose "
                                                   "cutting plane the file's directions span, or the second "
                                                   "direction with --frf-y from a file of one direct FRF");
        }
        std::string& pairs = c.no_cross[id];
        pairs += (pairs.empty() ? "" : ", ") + std::string(1, "xyz"[a]) + "xyz"[b];
      }
    }
  }
  std::vector<Eigen::Matrix3cd> H(s.H.begin() + first, s.H.end());
  t.Phi_C = OrientInCuttingPlane(H, R);
  c.SayUnits(&t);
  if (o.fit) FitBaseFrameModes(c, s, dirs, R, &t);
}

// After the fits: the ZOA's lines limited to the common usable band, then
// refined between the measured lines (RefineBetweenLines), each told.
void FitToUsableBand(const MeasuredTipsContext& c, TipDynamics* t_ptr) {
  TipDynamics& t = *t_ptr;
  const std::string& id = t.id;
  t.modes_fitted = true;
  t.no_modes = t.modes_C.num_modes() == 0;
  // The ZOA uses the measured FRF where the noise model finds it usable
  // in every fitted direction: below that (the drift of an integrated
  // accelerometer signal) and above it (the floor) a line says nothing
  // of the structure, and a drift 5x the resonance makes spurious
  // lobes of a few hertz.
  const auto [lo, hi] = CommonUsableBand(t.fits);
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
      c.Tell(Message::Kind::kInfo, id + ": the ZOA uses the measured FRF in its usable band, " + FormatDouble(lo) +
                                       " to " + FormatDouble(hi) + " Hz");
      t.freq_hz = Eigen::Map<Eigen::VectorXd>(f.data(), static_cast<Eigen::Index>(f.size()));
      t.Phi_C = std::move(phi);
    }
  }
  const int added = RefineBetweenLines(&t);
  if (added > 0) {
    c.Tell(Message::Kind::kInfo, id + ": between the measured lines the ZOA follows the modal fit's shape (" +
                                     std::to_string(added) + " lines added; the measured lines are kept as " +
                                     "they are)");
  }
}

// The missing cross FRFs of c.no_cross: one warning per set of missing
// pairs, naming its postures (in the order of `tips`).
void WarnMissingCross(const MeasuredTipsContext& c, const std::vector<TipDynamics>& tips) {
  std::map<std::string, std::vector<std::string>> by_pairs;  // "xy, yx" -> postures
  for (const TipDynamics& t : tips) {
    if (const auto it = c.no_cross.find(t.id); it != c.no_cross.end()) by_pairs[it->second].push_back(t.id);
  }
  for (const auto& [pairs, ids] : by_pairs) {
    std::string postures;
    for (const std::string& id : ids) postures += (postures.empty() ? "" : ", ") + id;
    c.Tell(Message::Kind::kWarning, c.o.frf_path + ": no cross FRF " + pairs + " at " +
                                        (ids.size() == 1 ? "posture " : std::to_string(ids.size()) + " postures (") +
                                        postures + (ids.size() == 1 ? "" : ")") +
                                        "; taken as zero (the directions uncoupled)");
  }
}

}  // namespace

void MeasuredTipOptions::Validate() const { CheckOptionAtLeast("sd_modes", sd_modes, 1); }

std::vector<TipDynamics> TipsFromMeasuredFrfs(const std::vector<TipFrfs>& sets, const std::vector<TipFrfs>& ysets,
                                              const MeasuredTipOptions& o, const MessageSink& on_message) {
  o.Validate();
  MeasuredTipsContext c{sets, ysets, o, on_message, false, {}};
  std::vector<TipDynamics> tips;
  for (const TipFrfs& s : sets) {
    const std::string id = ShownId(s.pose_id, o.frf_path);
    if (!o.pose_ids.empty() && std::find(o.pose_ids.begin(), o.pose_ids.end(), id) == o.pose_ids.end()) continue;
    int total = 0;
    const std::vector<int> direct = DirectFrfs(s, &total);
    TipDynamics t;
    t.id = id;
    t.unit_finding = TipFrfsUnitFinding(s);
    // Drop a 0 Hz line (the ZOA needs ω > 0); the fit keeps every line.
    const Eigen::Index first = s.freq_hz.size() > 0 && s.freq_hz(0) == 0.0 ? 1 : 0;
    t.freq_hz = s.freq_hz.tail(s.freq_hz.size() - first);
    if (!ysets.empty()) {
      TipFromTwoFiles(c, s, first, &t);
    } else if (direct.size() == 1 && total == 1) {
      TipFromOneDirect(c, s, direct[0], first, &t);
    } else {
      TipFromBaseFrame(c, s, first, &t);
    }
    if (o.fit) FitToUsableBand(c, &t);
    tips.push_back(std::move(t));
  }
  if (tips.empty()) throw InputError({o.frf_path, 0, 0}, "none of the requested postures is in the file");
  WarnMissingCross(c, tips);
  return tips;
}

std::vector<dynamics::Mode> ModesInSourceFrame(const TipDynamics& tip) {
  std::vector<dynamics::Mode> modes;
  for (int k = 0; k < tip.modes_C.num_modes(); ++k) {
    dynamics::Mode m;
    m.freq_hz = RadPerSecToHz(tip.modes_C.omega_rad_s(k));
    m.damping_ratio = tip.modes_C.zeta(k);
    m.p_T = tip.R_BC * tip.modes_C.p.col(k);
    m.modal_mass_kg = 1.0 / m.p_T.squaredNorm();
    Eigen::Index big = 0;
    m.p_T.cwiseAbs().maxCoeff(&big);
    m.shape_T = m.p_T.normalized() * (m.p_T(big) < 0.0 ? -1.0 : 1.0);
    for (int i = 0; i < 3; ++i) m.shape_T(i) = m.shape_T(i) == 0.0 ? 0.0 : m.shape_T(i);  // no "-0"
    modes.push_back(m);
  }
  return modes;
}

}  // namespace robomach::stability
