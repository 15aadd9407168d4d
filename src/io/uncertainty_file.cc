#include "robomach/io/uncertainty_file.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/yaml_doc.h"

namespace robomach::io {

std::string ParameterUncertaintyYaml(const dynamics::ParameterUncertainty& u) {
  dynamics::CheckValid(u);
  std::ostringstream o;
  const size_t n = u.parameters.size();
  o << "# robomach parameter uncertainty (docs/formats.md §12): estimates and the covariance of\n"
       "# theta = value (linear), log(value) (log) or 1/value (inverse), rows in the order of parameters.\n";
  o << "parameter_uncertainty:\n";
  std::string quoted;
  for (char c : u.source) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c == '\n' ? ' ' : c;
  }
  o << "  source: \"" << quoted << "\"\n";
  o << "  parameters:\n";
  for (size_t i = 0; i < n; ++i) {
    const auto& p = u.parameters[i];
    const double s = std::sqrt(std::max(u.covariance(i, i), 0.0));
    std::string sd;
    switch (p.scale) {
      case dynamics::UncertainScale::kLog: sd = FormatNumber(100.0 * s, 3) + " % (1 sigma of log)"; break;
      case dynamics::UncertainScale::kInverse: sd = FormatNumber(100.0 * s * p.value, 3) + " % (1 sigma of 1/value, relative)"; break;
      case dynamics::UncertainScale::kLinear: sd = FormatNumber(s, 4) + " (1 sigma)"; break;
    }
    o << "    - {name: " << p.name << ", value: " << FormatDouble(p.value) << ", scale: "
      << dynamics::ToString(p.scale) << "}  # " << sd << '\n';
  }
  o << "  covariance:\n";
  for (size_t i = 0; i < n; ++i) {
    o << "    - [";
    for (size_t j = 0; j < n; ++j) o << (j ? ", " : "") << FormatDouble(u.covariance(i, j));
    o << "]\n";
  }
  o << "# correlation:\n";
  for (size_t i = 0; i < n; ++i) {
    o << "#   ";
    for (size_t j = 0; j < n; ++j) {
      const double d = std::sqrt(u.covariance(i, i) * u.covariance(j, j));
      o << (j ? " " : "") << (d > 0.0 ? FormatNumber(u.covariance(i, j) / d, 3) : std::string("nan"));
    }
    o << "  " << u.parameters[i].name << '\n';
  }
  return o.str();
}

void WriteParameterUncertainty(const std::string& path, const dynamics::ParameterUncertainty& u) {
  WriteFileAtomically(path, ParameterUncertaintyYaml(u));
}

dynamics::ParameterUncertainty ReadParameterUncertainty(const std::string& path) {
  const YamlDoc doc = YamlDoc::LoadFile(path, kUncertaintyFileFormat);
  if (!doc.IsMap()) throw doc.Error(std::string("expected ") + kUncertaintyFileFormat);
  const YamlDoc top = doc["parameter_uncertainty"];
  doc.RejectUnknownKeys();
  dynamics::ParameterUncertainty u;
  u.source = top.Has("source") ? top["source"].String() : path;
  top.MarkUsed("source");
  const YamlDoc params = top["parameters"];
  if (params.size() == 0) throw params.Error("expected at least one parameter");
  for (int i = 0; i < params.size(); ++i) {
    const YamlDoc p = params.at(i);
    dynamics::UncertainParameter up;
    up.name = p["name"].String();
    up.value = p["value"].Number();
    const YamlDoc scale = p["scale"];
    up.scale = scale.Checked([&] { return dynamics::ParseUncertainScale(scale.String()); });
    if (up.scale != dynamics::UncertainScale::kLinear && !(up.value > 0.0)) {
      throw p["value"].Error("expected a value > 0 on the " + std::string(dynamics::ToString(up.scale)) + " scale");
    }
    p.RejectUnknownKeys();
    u.parameters.push_back(up);
  }
  const int n = params.size();
  const YamlDoc cov = top["covariance"];
  if (cov.size() != n) {
    throw cov.Error("expected " + std::to_string(n) + " rows (one per parameter), got " + std::to_string(cov.size()));
  }
  u.covariance.resize(n, n);
  for (int i = 0; i < n; ++i) {
    const std::vector<double> row = cov.at(i).Numbers(n);
    for (int j = 0; j < n; ++j) u.covariance(i, j) = row[j];
  }
  top.RejectUnknownKeys();
  cov.Checked([&] { dynamics::CheckValid(u); });
  if (u.source.empty()) u.source = path;
  return u;
}

dynamics::ParameterUncertainty ReadParameterUncertainties(const std::vector<std::string>& paths) {
  std::vector<dynamics::ParameterUncertainty> parts;
  for (const std::string& p : paths) {
    parts.push_back(ReadParameterUncertainty(p));
    parts.back().source = p + " (" + parts.back().source + ")";
  }
  return AtLocation({paths.back(), 0, 0}, "", [&] { return dynamics::CombineIndependent(parts); });
}

nlohmann::json ParameterUncertaintyToJson(const dynamics::ParameterUncertainty& u) {
  nlohmann::json j;
  j["source"] = u.source;
  j["parameters"] = nlohmann::json::array();
  for (size_t i = 0; i < u.parameters.size(); ++i) {
    const auto& p = u.parameters[i];
    j["parameters"].push_back({{"name", p.name},
                               {"value", p.value},
                               {"scale", dynamics::ToString(p.scale)},
                               {"std_dev_theta", std::sqrt(std::max(u.covariance(i, i), 0.0))}});
  }
  j["covariance"] = nlohmann::json::array();
  for (Eigen::Index r = 0; r < u.covariance.rows(); ++r) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index c = 0; c < u.covariance.cols(); ++c) row.push_back(u.covariance(r, c));
    j["covariance"].push_back(row);
  }
  return j;
}

nlohmann::json ModeIntervalsToJson(const dynamics::PostureModeIntervals& intervals) {
  auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  nlohmann::json j;
  j["method"] = dynamics::ToString(intervals.propagation.method_used);
  j["reason"] = intervals.propagation.reason;
  j["evaluations"] = intervals.propagation.evaluations;
  j["failed_samples"] = intervals.propagation.failed_samples;
  j["modes"] = nlohmann::json::array();
  for (size_t k = 0; k < intervals.modes.size(); ++k) {
    const dynamics::ModeIntervals& m = intervals.modes[k];
    j["modes"].push_back({{"mode", k + 1},
                          {"freq_hz", num(m.freq_hz.value)},
                          {"freq_hz_lower", num(m.freq_hz.lower)},
                          {"freq_hz_upper", num(m.freq_hz.upper)},
                          {"damping_ratio", num(m.damping_ratio.value)},
                          {"damping_ratio_lower", num(m.damping_ratio.lower)},
                          {"damping_ratio_upper", num(m.damping_ratio.upper)},
                          {"peak_receptance_m_per_N", num(m.peak_receptance_m_per_N.value)},
                          {"peak_receptance_m_per_N_lower", num(m.peak_receptance_m_per_N.lower)},
                          {"peak_receptance_m_per_N_upper", num(m.peak_receptance_m_per_N.upper)}});
  }
  return j;
}

}  // namespace robomach::io
