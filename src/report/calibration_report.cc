#include "robomach/report/calibration_report.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "robomach/dynamics/tool_tip_frf.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/number_format.h"
#include "robomach/report/frf_plot.h"
#include "robomach/report/modal_fit_plot.h"
#include "robomach/report/plot.h"

namespace robomach::report {
namespace {

using calibration::ModeMatch;

const ModeMatch* FindBefore(const calibration::Comparison& before, const ModeMatch& after) {
  for (const ModeMatch& m : before.matches) {
    if (m.key == after.key && m.measured == after.measured) return &m;
  }
  return nullptr;
}

std::string Fixed(double v, int digits) {
  if (!std::isfinite(v)) return "–";
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", digits, v);
  return buf;
}

std::string Sci(double v) {
  if (!std::isfinite(v)) return "–";
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.3e", v);
  return buf;
}

std::string Dir(const dynamics::FrfKey& k) { return std::string(1, AxisName(k.response)) + AxisName(k.excitation); }

}  // namespace

void WriteTable3Csv(const std::string& path, const std::vector<TableSet>& sets) {
  io::WriteFileAtomically(path, [&](std::ostream& os) {
    os << "pose_id,response,excitation,set,model_mode,measured_freq_hz,model_freq_hz_before,"
          "freq_error_before_pct,model_freq_hz,freq_error_pct,measured_peak_m_per_N,"
          "model_peak_m_per_N_before,peak_error_before_pct,model_peak_m_per_N,peak_error_pct,"
          "measured_damping_ratio,model_damping_ratio,ux,uy,uz\n";
    for (const TableSet& s : sets) {
      for (const ModeMatch& m : s.after.matches) {
        const ModeMatch* b = FindBefore(s.before, m);
        os << m.key.pose_id << ',' << AxisName(m.key.response) << ',' << AxisName(m.key.excitation) << ','
           << s.label << ',' << m.model_mode + 1 << ',' << FormatCell(m.measured_freq_hz) << ','
           << (b ? FormatCell(b->model_freq_hz) : "") << ',' << (b ? FormatCell(100 * b->freq_error()) : "") << ','
           << FormatCell(m.model_freq_hz) << ',' << FormatCell(100 * m.freq_error()) << ',' << FormatCell(m.measured_peak) << ','
           << (b ? FormatCell(b->model_peak) : "") << ',' << (b ? FormatCell(100 * b->peak_error()) : "") << ','
           << FormatCell(m.model_peak) << ',' << FormatCell(100 * m.peak_error()) << ',' << FormatCell(m.measured_damping) << ','
           << FormatCell(m.model_damping) << ',' << FormatCell(m.model_shape_T(0)) << ',' << FormatCell(m.model_shape_T(1)) << ','
           << FormatCell(m.model_shape_T(2)) << '\n';
      }
    }
  });
}

void WriteTable3Markdown(const std::string& path, const std::vector<TableSet>& sets, const std::string& title) {
  io::WriteFileAtomically(path, [&](std::ostream& os) {
    os << "# " << title << "\n\n";
    os << "Natural frequency and peak amplitude per posture and direction, model against measurement "
          "(modal fit of the measured FRF), relative error = model / measured − 1. "
          "'before' is the model with the initial parameters. Mode = model mode number (ascending "
          "frequency) matched by frequency and tool-tip direction; u = its unit tool-tip shape.\n\n";
    for (const TableSet& s : sets) {
      os << "## " << (s.label == "fit" ? "Postures used in the fit" : "Held-out postures (validation)") << "\n\n";
      os << "| pose | dir | mode | f meas [Hz] | f model [Hz] | err [%] | err before [%] | peak meas [m/N] | "
            "peak model [m/N] | err [%] | err before [%] | u (x, y, z) |\n";
      os << "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|\n";
      for (const ModeMatch& m : s.after.matches) {
        const ModeMatch* b = FindBefore(s.before, m);
        os << "| " << m.key.pose_id << " | " << Dir(m.key) << " | " << m.model_mode + 1 << " | "
           << Fixed(m.measured_freq_hz, 3) << " | " << Fixed(m.model_freq_hz, 3) << " | "
           << Fixed(100 * m.freq_error(), 2) << " | " << (b ? Fixed(100 * b->freq_error(), 2) : "–") << " | "
           << Sci(m.measured_peak) << " | " << Sci(m.model_peak) << " | " << Fixed(100 * m.peak_error(), 2)
           << " | " << (b ? Fixed(100 * b->peak_error(), 2) : "–") << " | (" << Fixed(m.model_shape_T(0), 2)
           << ", " << Fixed(m.model_shape_T(1), 2) << ", " << Fixed(m.model_shape_T(2), 2) << ") |\n";
      }
      os << "\nLargest |error| after calibration: natural frequency " << Fixed(100 * s.after.max_abs_freq_error, 3)
         << " %, peak amplitude " << Fixed(100 * s.after.max_abs_peak_error, 3) << " % (before: "
         << Fixed(100 * s.before.max_abs_freq_error, 3) << " %, " << Fixed(100 * s.before.max_abs_peak_error, 3)
         << " %).\n\n";
      if (!s.after.unmatched_measured.empty() && s.features) {
        os << "Measured modes without a model counterpart (too weak in this direction, or no model mode "
              "nearby):\n\n";
        for (int i : s.after.unmatched_measured) {
          const auto& mm = s.features->modes[i];
          os << "- " << mm.key.pose_id << " " << Dir(mm.key) << ": " << Fixed(mm.fit.freq_hz, 3) << " Hz, ζ = "
             << Fixed(mm.fit.damping_ratio, 4) << ", peak " << Sci(mm.peak_magnitude) << " m/N\n";
        }
        os << "\n";
      }
    }
  });
}

namespace {

Eigen::VectorXcd ModelEntry(const dynamics::PostureDynamics& d, const dynamics::FrfKey& key,
                            const Eigen::VectorXd& freq_hz) {
  return dynamics::ReceptanceEvaluator(d).Entry(freq_hz, static_cast<int>(key.response),
                                                static_cast<int>(key.excitation));
}

}  // namespace

PostureOverlay MakePostureOverlay(const std::string& pose, const dynamics::FrfSet& measured,
                                  const dynamics::PostureDynamics& before,
                                  const dynamics::PostureDynamics& after) {
  PostureOverlay o = MakePostureOverlay(pose, measured, before);
  for (size_t k = 0; k < o.keys.size(); ++k) o.after.push_back(ModelEntry(after, o.keys[k], o.freq_hz[k]));
  o.mode_freq_hz.clear();
  for (const auto& m : after.modes) o.mode_freq_hz.push_back(m.freq_hz);
  return o;
}

PostureOverlay MakePostureOverlay(const std::string& pose, const dynamics::FrfSet& measured,
                                  const dynamics::PostureDynamics& model) {
  PostureOverlay o;
  o.pose_id = pose;
  for (const auto& [key, frf] : measured.ForPose(pose)) {
    o.keys.push_back(key);
    o.freq_hz.push_back(frf.freq_hz());
    o.measured.push_back(frf.receptance());
    o.before.push_back(ModelEntry(model, key, frf.freq_hz()));
  }
  for (const auto& m : model.modes) o.mode_freq_hz.push_back(m.freq_hz);
  return o;
}

nlohmann::json NoiseSummaryJson(const calibration::NoiseModels& noise, const std::string& model, double min_snr) {
  nlohmann::json j{{"model", model}, {"min_snr", min_snr}, {"frfs", nlohmann::json::array()}};
  for (const auto& [key, n] : noise) {
    nlohmann::json bands = nlohmann::json::array();
    for (const auto& [lo, hi] : n.usable_bands) bands.push_back({lo, hi});
    // Isolated lines left out of every fit (hum, spikes): issue #33.
    nlohmann::json excluded = nlohmann::json::array();
    for (const calibration::ExcludedLine& e : n.excluded_lines) {
      excluded.push_back({{"freq_hz", e.freq_hz},
                          {"ratio", e.ratio},
                          {"excess_m_per_N", e.excess_m_per_N},
                          {"mains_hz", e.mains_hz > 0.0 ? nlohmann::json(e.mains_hz) : nlohmann::json(nullptr)},
                          {"description", calibration::DescribeExcludedLine(e)}});
    }
    j["frfs"].push_back({{"pose_id", key.pose_id},
                         {"response", std::string(1, AxisName(key.response))},
                         {"excitation", std::string(1, AxisName(key.excitation))},
                         {"source", calibration::ToString(n.source)},
                         {"averages", n.averages},
                         {"relative", n.relative},
                         {"floor_min_m_per_N", n.floor_m_per_N.minCoeff()},
                         {"floor_max_m_per_N", n.floor_m_per_N.maxCoeff()},
                         {"usable_bands_hz", bands},
                         {"usable_lines", n.usable_lines},
                         {"excluded_lines", excluded},
                         {"lines", static_cast<int>(n.usable.size())},
                         {"status", robomach::ToString(n.status)}});
  }
  return j;
}

void AddNoise(const calibration::NoiseModels& noise, PostureOverlay* o) {
  o->noise_sigma.clear();
  o->usable.clear();
  for (size_t k = 0; k < o->keys.size(); ++k) {
    auto it = noise.find(o->keys[k]);
    if (it == noise.end() || it->second.sigma_m_per_N.size() != o->freq_hz[k].size()) {
      o->noise_sigma.emplace_back();
      o->usable.emplace_back();
      continue;
    }
    o->noise_sigma.push_back(it->second.sigma_m_per_N);
    const std::string u = calibration::DescribeUsable(it->second);
    o->usable.push_back(u);
  }
}

void WriteOverlayPng(const std::string& path, const PostureOverlay& o, const std::string& title,
                     const std::string& before_label, const std::string& after_label) {
  const int rows = static_cast<int>(o.keys.size());
  Figure fig(std::max(1, rows), 2, 760, 340);
  fig.title = title;
  for (int r = 0; r < rows; ++r) {
    // Measured wide and first, the models thin on top: a model that fits
    // the measurement runs inside the measured band instead of hiding it.
    std::vector<FrfCurve> curves;
    // Light (sky blue) under dark (black): the contrast keeps both visible.
    curves.push_back({o.freq_hz[r], o.measured[r], "measured H" + Dir(o.keys[r]), PaletteColor(5), false, 6});
    curves.push_back({o.freq_hz[r], o.before[r], before_label, PaletteColor(1), true, 2});
    if (static_cast<size_t>(r) < o.after.size()) {
      curves.push_back({o.freq_hz[r], o.after[r], after_label, PaletteColor(6), false, 1});
    }
    std::string panel = "posture " + o.pose_id + ": H" + Dir(o.keys[r]);
    if (static_cast<size_t>(r) < o.noise_sigma.size() && o.noise_sigma[r].size() == o.freq_hz[r].size()) {
      FrfCurve noise{o.freq_hz[r], o.noise_sigma[r].cast<std::complex<double>>(), "noise (1 sigma)", {150, 150, 150},
                     true, 1};
      noise.magnitude_only = true;
      curves.push_back(noise);
      panel += ", " + o.usable[r];
    }
    FillFrfPanels(curves, o.mode_freq_hz, panel, &fig.at(r, 0), &fig.at(r, 1));
    fig.at(r, 1).title = "phase";
  }
  fig.SavePng(path);
}

void WriteStabilisationPng(const std::string& path, const std::string& pose_id,
                           const calibration::MeasuredFeatures& features) {
  std::vector<const std::pair<const dynamics::FrfKey, calibration::ModalFitResult>*> fits;
  for (const auto& kv : features.fits) {
    if (kv.first.pose_id == pose_id) fits.push_back(&kv);
  }
  Figure fig(std::max<int>(1, static_cast<int>(fits.size())), 1, 900, 320);
  fig.title = "stabilisation diagrams, posture " + pose_id;
  for (size_t r = 0; r < fits.size(); ++r) {
    const auto& [key, fit] = *fits[r];
    Axes& ax = fig.at(static_cast<int>(r), 0);
    ax.title = "H" + Dir(key) + ": " + std::to_string(fit.modes.size()) + " modes, LSCF order " +
               std::to_string(fit.order_used) + ", relative rms misfit " + Fixed(fit.relative_rms_error, 4);
    std::vector<double> modes;
    for (const auto& m : fit.modes) modes.push_back(m.freq_hz);
    FillStabilisationPanel(fit.stabilisation, modes, fit.fmin_hz, fit.fmax_hz, &ax);
  }
  fig.SavePng(path);
}

nlohmann::json CalibrationSummaryJson(const calibration::CalibrationResult& result,
                                      const calibration::CalibrationOptions& options,
                                      const std::vector<TableSet>& sets) {
  using nlohmann::json;
  json j;
  j["objective"] = calibration::ToString(options.objective);
  j["status"] = robomach::ToString(result.status);
  j["message"] = result.message;
  j["weakly_identified"] = result.weakly_identified;
  j["parameters"] = json::array();
  for (const auto& e : result.estimates) {
    j["parameters"].push_back({{"name", e.name},
                               {"unit", e.unit},
                               {"initial", e.initial},
                               {"value", e.value},
                               {"std_dev", e.std_dev},
                               {"relative_std", e.std_dev / std::abs(e.value)},
                               {"weakly_identified", e.weakly_identified},
                               {"at_bound", e.at_bound},
                               {"stage", e.stage}});
  }
  j["stages"] = json::array();
  for (const auto& s : result.stages) {
    j["stages"].push_back({{"name", s.name},
                           {"parameters", s.parameters},
                           {"termination", s.termination},
                           {"message", s.message},
                           {"iterations", s.iterations},
                           {"num_residuals", s.num_residuals},
                           {"initial_cost", s.initial_cost},
                           {"final_cost", s.final_cost},
                           {"covariance_ok", s.covariance_ok}});
  }
  for (const TableSet& s : sets) {
    json set;
    // From the matches themselves, the one source of the table's numbers.
    auto stats = [](const calibration::Comparison& c) {
      double mf = 0, mp = 0, sf = 0, sp = 0;
      for (const ModeMatch& m : c.matches) {
        mf = std::max(mf, std::abs(m.freq_error()));
        mp = std::max(mp, std::abs(m.peak_error()));
        sf += m.freq_error() * m.freq_error();
        sp += m.peak_error() * m.peak_error();
      }
      const double n = std::max<size_t>(1, c.matches.size());
      return std::array<double, 4>{mf, mp, std::sqrt(sf / n), std::sqrt(sp / n)};
    };
    const auto b = stats(s.before), a = stats(s.after);
    set["max_abs_freq_error"] = {{"before", b[0]}, {"after", a[0]}};
    set["max_abs_peak_error"] = {{"before", b[1]}, {"after", a[1]}};
    set["rms_freq_error"] = {{"before", b[2]}, {"after", a[2]}};
    set["rms_peak_error"] = {{"before", b[3]}, {"after", a[3]}};
    set["num_matches"] = {{"before", s.before.matches.size()}, {"after", s.after.matches.size()}};
    json postures = json::object();
    for (const auto& [key, err] : s.after.whole_curve_error) {
      json& p = postures[key.pose_id];
      p["whole_curve_error"][Dir(key)] = {{"before", s.before.whole_curve_error.count(key)
                                                         ? s.before.whole_curve_error.at(key)
                                                         : NAN},
                                          {"after", err}};
    }
    for (const auto& [label, cmp] : {std::pair<std::string, const calibration::Comparison*>{"before", &s.before},
                                     {"after", &s.after}}) {
      std::map<std::string, std::pair<double, double>> worst;
      for (const ModeMatch& m : cmp->matches) {
        auto& w = worst[m.key.pose_id];
        w.first = std::max(w.first, std::abs(m.freq_error()));
        w.second = std::max(w.second, std::abs(m.peak_error()));
      }
      for (const auto& [pose, w] : worst) {
        postures[pose]["max_abs_freq_error"][label] = w.first;
        postures[pose]["max_abs_peak_error"][label] = w.second;
      }
    }
    set["postures"] = postures;
    json matches = json::array();
    for (const ModeMatch& m : s.after.matches) {
      matches.push_back({{"pose_id", m.key.pose_id},
                         {"direction", Dir(m.key)},
                         {"model_mode", m.model_mode + 1},
                         {"measured_freq_hz", m.measured_freq_hz},
                         {"model_freq_hz", m.model_freq_hz},
                         {"freq_error", m.freq_error()},
                         {"measured_peak_m_per_N", m.measured_peak},
                         {"model_peak_m_per_N", m.model_peak},
                         {"peak_error", m.peak_error()},
                         {"model_shape_T", {m.model_shape_T(0), m.model_shape_T(1), m.model_shape_T(2)}}});
    }
    set["matches"] = matches;
    if (s.features) {
      json fits = json::array();
      for (const auto& [key, fit] : s.features->fits) {
        json modes = json::array();
        for (const auto& m : fit.modes) {
          modes.push_back({{"freq_hz", m.freq_hz},
                           {"damping_ratio", m.damping_ratio},
                           {"modal_constant", {m.modal_constant.real(), m.modal_constant.imag()}},
                           {"stable_orders", m.stable_orders}});
        }
        json peaks = json::array();
        if (auto it = s.features->peaks.find(key); it != s.features->peaks.end()) {
          for (const auto& p : it->second) {
            peaks.push_back({{"peak_freq_hz", p.peak_freq_hz},
                             {"peak_magnitude_m_per_N", p.peak_magnitude},
                             {"half_power_damping_ratio", p.damping_ratio}});
          }
        }
        fits.push_back({{"pose_id", key.pose_id},
                        {"peak_picking", peaks},
                        {"direction", Dir(key)},
                        {"status", robomach::ToString(fit.status)},
                        {"message", fit.message},
                        {"relative_rms_error", fit.relative_rms_error},
                        {"modes", modes}});
      }
      set["modal_fits"] = fits;
    }
    j["sets"][s.label] = set;
  }
  return j;
}

nlohmann::json FrfCalibrateSummaryJson(const calibration::CalibrationResult& result,
                                       const calibration::CalibrationOptions& options,
                                       const std::vector<TableSet>& sets, const nlohmann::json& misfit,
                                       const calibration::NoiseModels& noise,
                                       const calibration::NoiseModels& holdout_noise,
                                       const std::string& noise_model, double min_snr,
                                       const std::string& robot_path) {
  nlohmann::json summary = CalibrationSummaryJson(result, options, sets);
  summary["misfit"] = misfit;
  summary["noise"] = NoiseSummaryJson(noise, noise_model, min_snr);
  if (!holdout_noise.empty()) summary["holdout_noise"] = NoiseSummaryJson(holdout_noise, noise_model, min_snr);
  summary["robot"] = robot_path;
  return summary;
}

}  // namespace robomach::report
