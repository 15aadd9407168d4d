#include "robomach/dynamics/measured_frf.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "robomach/common/number_format.h"

namespace robomach::dynamics {

Frf Frf::FromSamples(Eigen::VectorXd freq_hz, Eigen::VectorXcd receptance,
                     std::optional<Eigen::VectorXd> coherence) {
  if (freq_hz.size() != receptance.size()) {
    std::ostringstream m;
    m << "Frf: " << freq_hz.size() << " frequency lines but " << receptance.size()
      << " receptance values";
    throw std::invalid_argument(m.str());
  }
  if (freq_hz.size() == 0) throw std::invalid_argument("Frf: no frequency lines");
  if (coherence && coherence->size() != freq_hz.size()) {
    std::ostringstream m;
    m << "Frf: " << freq_hz.size() << " frequency lines but " << coherence->size()
      << " coherence values";
    throw std::invalid_argument(m.str());
  }
  for (Eigen::Index i = 0; i < freq_hz.size(); ++i) {
    auto fail = [&](const std::string& what) {
      std::ostringstream m;
      m.precision(12);
      m << "Frf: line " << i << " (f = " << freq_hz(i) << " Hz): " << what;
      throw std::invalid_argument(m.str());
    };
    if (!std::isfinite(freq_hz(i)) || freq_hz(i) < 0.0) fail("expected a finite frequency >= 0");
    if (i > 0 && !(freq_hz(i) > freq_hz(i - 1))) {
      std::ostringstream m;
      m.precision(12);
      m << "frequencies must be strictly increasing (previous line " << freq_hz(i - 1) << " Hz)";
      fail(m.str());
    }
    if (!std::isfinite(receptance(i).real()) || !std::isfinite(receptance(i).imag())) {
      fail("receptance is not finite");
    }
    if (coherence && !((*coherence)(i) >= 0.0 && (*coherence)(i) <= 1.0)) {
      fail("coherence must be in [0, 1]");
    }
  }
  Frf f;
  f.freq_hz_ = std::move(freq_hz);
  f.receptance_ = std::move(receptance);
  f.coherence_ = std::move(coherence);
  return f;
}

bool Frf::evenly_spaced() const {
  if (size() < 3) return true;
  const double df = (freq_hz_(size() - 1) - freq_hz_(0)) / (size() - 1);
  const double tol = 1e-9 * freq_hz_(size() - 1);
  for (int i = 0; i < size(); ++i) {
    if (std::abs(freq_hz_(i) - (freq_hz_(0) + i * df)) > tol) return false;
  }
  return true;
}

Frf Frf::Band(double fmin_hz, double fmax_hz) const {
  int first = 0;
  while (first < size() && freq_hz_(first) < fmin_hz) ++first;
  int last = first;
  while (last < size() && freq_hz_(last) <= fmax_hz) ++last;
  Frf f;
  f.freq_hz_ = freq_hz_.segment(first, last - first);
  f.receptance_ = receptance_.segment(first, last - first);
  if (coherence_) f.coherence_ = coherence_->segment(first, last - first);
  if (noise_sigma_) f.noise_sigma_ = noise_sigma_->segment(first, last - first);
  return f;
}

Frf Frf::WithNoise(Eigen::VectorXd sigma) const {
  if (sigma.size() != size()) {
    std::ostringstream m;
    m << "Frf: " << size() << " frequency lines but " << sigma.size() << " noise values";
    throw std::invalid_argument(m.str());
  }
  for (Eigen::Index i = 0; i < sigma.size(); ++i) {
    if (!(std::isfinite(sigma(i)) && sigma(i) > 0.0)) {
      std::ostringstream m;
      m.precision(12);
      m << "Frf: line " << i << " (f = " << freq_hz_(i) << " Hz): noise sigma must be finite and > 0, got "
        << sigma(i);
      throw std::invalid_argument(m.str());
    }
  }
  Frf f = *this;
  f.noise_sigma_ = std::move(sigma);
  return f;
}

Frf Frf::Select(const std::vector<int>& lines) const {
  const int n = static_cast<int>(lines.size());
  for (int k = 0; k < n; ++k) {
    if (lines[k] < 0 || lines[k] >= size() || (k > 0 && lines[k] <= lines[k - 1])) {
      throw std::invalid_argument("Frf::Select: line indices must be strictly increasing in [0, " +
                                  std::to_string(size()) + "), got " + std::to_string(lines[k]) + " at position " +
                                  std::to_string(k));
    }
  }
  Frf f;
  f.freq_hz_.resize(n);
  f.receptance_.resize(n);
  if (coherence_) f.coherence_ = Eigen::VectorXd(n);
  if (noise_sigma_) f.noise_sigma_ = Eigen::VectorXd(n);
  for (int k = 0; k < n; ++k) {
    f.freq_hz_(k) = freq_hz_(lines[k]);
    f.receptance_(k) = receptance_(lines[k]);
    if (coherence_) (*f.coherence_)(k) = (*coherence_)(lines[k]);
    if (noise_sigma_) (*f.noise_sigma_)(k) = (*noise_sigma_)(lines[k]);
  }
  return f;
}

std::string FrfKey::ToString() const {
  // A posture-free FRF (a tap test on a machine tool, a UFF record that
  // names no posture) has an empty pose id.
  const bool points = response_point != 0 || excitation_point != 0;
  auto at = [&](int p) { return points ? " at point " + std::to_string(p) : std::string(); };
  return (pose_id.empty() ? std::string() : "pose " + pose_id + ", ") + "response " + AxisName(response) +
         at(response_point) + ", excitation " + AxisName(excitation) + at(excitation_point);
}

std::string FrfKey::Label() const {
  if (response_point == 0 && excitation_point == 0) return std::string("H") + AxisName(response) + AxisName(excitation);
  std::string s = "H";
  s += std::to_string(response_point);
  s += AxisName(response);
  s += ',';
  s += std::to_string(excitation_point);
  s += AxisName(excitation);
  return s;
}

void FrfSet::Insert(FrfKey key, Frf frf) {
  if (frfs_.count(key)) throw std::invalid_argument("duplicate FRF for " + key.ToString());
  frfs_.emplace(std::move(key), std::move(frf));
}

const Frf& FrfSet::at(const FrfKey& key) const {
  auto it = frfs_.find(key);
  if (it == frfs_.end()) throw std::out_of_range("no FRF for " + key.ToString());
  return it->second;
}

std::vector<std::string> FrfSet::pose_ids() const {
  std::vector<std::string> ids;
  for (const auto& [k, f] : frfs_) {
    if (ids.empty() || ids.back() != k.pose_id) ids.push_back(k.pose_id);
  }
  return ids;
}

std::vector<FrfKey> FrfSet::keys() const {
  std::vector<FrfKey> k;
  for (const auto& [key, f] : frfs_) k.push_back(key);
  return k;
}

FrfSet FrfSet::ForPose(const std::string& pose_id) const {
  FrfSet s;
  for (const auto& [k, f] : frfs_) {
    if (k.pose_id == pose_id) s.frfs_.emplace(k, f);
  }
  return s;
}

void FrfSet::Merge(const FrfSet& other) {
  for (const auto& [k, f] : other.frfs_) Insert(k, f);
}

std::string FrequencyAxisFinding(const std::string& what, double top, FrfFileFormat format) {
  if (!(top > 0.0) || top >= kMinPlausibleMeasuredTopHz) return {};
  const char* where = format == FrfFileFormat::kUff58
                          ? " in the abscissa (UFF58 record 7's start and increment, record 8's unit)"
                          : format == FrfFileFormat::kCsv ? " under the freq_hz header" : "";
  return what + ": the FRFs' highest line is at " + FormatNumber(top, 4) + " Hz, below the " +
         FormatNumber(kMinPlausibleMeasuredTopHz, 4) +
         " Hz a hammer test of a tool tip reaches (lines to 0.1 - 10 kHz; robot modes 5 - 2000 Hz): frequencies in kHz" +
         where + "? (" + FormatNumber(top, 4) + " kHz is " + FormatNumber(1e3 * top, 4) + " Hz)";
}

std::string ReceptancePeakFinding(const std::string& what, double peak, FrfFileFormat format) {
  if (!(peak > kMaxPlausibleReceptance || (peak > 0.0 && peak < kMinPlausibleReceptance))) return "";
  char b[160];
  std::snprintf(b, sizeof b, ": the largest receptance is %.3g m/N, outside the plausible %.0e to %.0e m/N of a machine structure: ",
                peak, kMinPlausibleReceptance, kMaxPlausibleReceptance);
  // A UFF58 file has no columns: its units are in record 8 (abscissa),
  // record 9 (ordinate, the response, with its data type: displacement,
  // velocity, acceleration) and record 10 (denominator, the force).
  const bool high = peak > kMaxPlausibleReceptance;
  std::string mistake, check;
  switch (format) {
    case FrfFileFormat::kUff58:
      mistake = high ? "the response was probably recorded in mm or um (or the force in kN) under a unit line of m (and "
                       "N), or a mobility or accelerance was read as receptance"
                     : "the force was probably recorded in mN, or the response in km";
      check = "; check the unit lines and the ordinate data type of records 9 (response) and 10 (force), and record 8 "
              "(abscissa, Hz)";
      break;
    case FrfFileFormat::kCsv:
      mistake = high ? "the response was probably recorded in mm or um (or the force in kN) under a column named in m "
                       "(and N), or a mobility or accelerance was read as receptance (the file's quantity or unit labels)"
                     : "the force was probably recorded in mN, or the response in km";
      check = "; check the units in the column names";
      break;
    case FrfFileFormat::kUnknown:
      mistake = high ? "the response was probably recorded in mm or um (or the force in kN) under a unit of m (and N), "
                       "or a mobility or accelerance was read as receptance (the file's quantity or unit labels)"
                     : "the force was probably recorded in mN, or the response in km";
      check = "; check the units in the column names (CSV), or the unit lines and ordinate data type of records 9 "
              "and 10 (UFF58)";
      break;
  }
  return what + b + mistake + check;
}

namespace {

// The largest median of three neighbouring values.
double RobustPeak(const std::vector<double>& magnitude) {
  const int n = static_cast<int>(magnitude.size());
  if (n < 3) return n == 0 ? 0.0 : *std::min_element(magnitude.begin(), magnitude.end());
  double peak = 0.0;
  for (int k = 1; k + 1 < n; ++k) {
    double a = magnitude[k - 1], b = magnitude[k], c = magnitude[k + 1];
    peak = std::max(peak, std::max(std::min(a, b), std::min(std::max(a, b), c)));  // median of three
  }
  return peak;
}

}  // namespace

double PeakReceptance(const Frf& frf) {
  std::vector<double> m;
  for (int k = 0; k < frf.size(); ++k) {
    if (frf.freq_hz()(k) <= 0.0) continue;
    if (frf.coherence() && (*frf.coherence())(k) < 0.5) continue;
    m.push_back(std::abs(frf.receptance()(k)));
  }
  return RobustPeak(m);
}

std::vector<std::string> ReceptanceUnitFindings(const FrfSet& frfs, const std::string& source, FrfFileFormat format) {
  std::vector<std::string> out;
  for (const auto& [key, frf] : frfs) {
    const std::string f = ReceptancePeakFinding(source + ": " + key.ToString(), PeakReceptance(frf), format);
    if (!f.empty()) out.push_back(f);
  }
  return out;
}

}  // namespace robomach::dynamics
