#pragma once

// Measured tool-tip FRFs as validated value types (style.md §2.5).
//
// Why in `dynamics`: a measured FRF is the measured counterpart of the
// tool-tip receptance that dynamics::Receptance computes (same quantity, same
// frame B, same unit). `dynamics` is the lowest module that knows that
// quantity, and every module that needs measured FRFs may include it:
// `io` (readers and writers), `calibration`, `audit` and `stability`
// (style.md §2.1). `common` would also be reachable but holds only units,
// frames and errors.

#include <compare>
#include <complex>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/common/frames.h"

namespace robomach::dynamics {

/// One tool-tip FRF: receptance H(f) [m/N] on a strictly increasing grid,
/// expressed in the robot base frame B. Immutable after construction.
class Frf {
 public:
  /// @param freq_hz     frequency lines [Hz], finite, >= 0, strictly increasing.
  ///                    (0 Hz is allowed, unlike style.md §2.5's example: the
  ///                    static compliance is a valid receptance line.)
  /// @param receptance  H [m/N], finite, same size as freq_hz.
  /// @param coherence   optional, in [0, 1], same size.
  /// @throws std::invalid_argument naming the first offending line (0-based
  ///   index and frequency) and the violated rule.
  static Frf FromSamples(Eigen::VectorXd freq_hz, Eigen::VectorXcd receptance,
                         std::optional<Eigen::VectorXd> coherence = std::nullopt);

  const Eigen::VectorXd& freq_hz() const { return freq_hz_; }
  const Eigen::VectorXcd& receptance() const { return receptance_; }  // [m/N]
  const std::optional<Eigen::VectorXd>& coherence() const { return coherence_; }
  /// Standard deviation σ of the complex measurement noise of each line
  /// [m/N]: E|H_measured − H_true|² = σ² (see calibration/frf_noise.h).
  /// Absent until a noise model is attached with WithNoise.
  const std::optional<Eigen::VectorXd>& noise_sigma() const { return noise_sigma_; }
  int size() const { return static_cast<int>(freq_hz_.size()); }
  /// A copy with the per-line noise σ [m/N] attached.
  /// @throws std::invalid_argument if the size differs or a σ is not finite and > 0.
  Frf WithNoise(Eigen::VectorXd sigma_m_per_N) const;
  /// A copy of the given lines (0-based, strictly increasing), with their
  /// coherence and noise. @throws std::invalid_argument for a bad index list.
  Frf Select(const std::vector<int>& lines) const;
  /// True if the lines are evenly spaced within 1e-9 of the largest frequency.
  bool evenly_spaced() const;
  /// The lines with f in [fmin_hz, fmax_hz] (may be empty).
  Frf Band(double fmin_hz, double fmax_hz) const;

 private:
  Frf() = default;
  Eigen::VectorXd freq_hz_;
  Eigen::VectorXcd receptance_;
  std::optional<Eigen::VectorXd> coherence_;
  std::optional<Eigen::VectorXd> noise_sigma_;
};

/// Which FRF of a test campaign: posture, response and excitation direction
/// at the tool tip (in B). (pose, x, x) is the direct FRF Hxx.
///
/// A roving test (several measurement points on the structure, for mode
/// shapes: formats.md §3's `response_point`/`excitation_point` columns, UFF
/// node numbers) also numbers the points; 0 is "not numbered", the tool tip
/// of the tool-tip workflows. Readers strip the numbers of a file that holds
/// one point pair per posture, so every tool-tip tool sees 0 (io::ReadFrfFile).
struct FrfKey {
  std::string pose_id;
  Axis response{Axis::kX};
  Axis excitation{Axis::kX};
  int response_point{0};
  int excitation_point{0};
  auto operator<=>(const FrfKey&) const = default;
  /// "pose P1, response x, excitation y"; with points
  /// "pose P1, response z at point 1, excitation z at point 56".
  std::string ToString() const;
  /// "Hxy"; with points "H1z,56z" (response first), for labels.
  std::string Label() const;
  /// Response and excitation at the same point in the same direction.
  bool IsDrivingPoint() const { return response == excitation && response_point == excitation_point; }
};

/// All FRFs of one test campaign, keyed by posture and direction pair,
/// iterated in key order (posture id, then response, then excitation).
class FrfSet {
 public:
  /// @throws std::invalid_argument on a duplicate key, naming it.
  void Insert(FrfKey key, Frf frf);
  /// @throws std::out_of_range "no FRF for pose P3, response y, excitation x".
  const Frf& at(const FrfKey& key) const;
  bool contains(const FrfKey& key) const { return frfs_.count(key) > 0; }
  int size() const { return static_cast<int>(frfs_.size()); }
  bool empty() const { return frfs_.empty(); }
  /// Distinct posture ids in key order.
  std::vector<std::string> pose_ids() const;
  std::vector<FrfKey> keys() const;
  /// The FRFs of one posture.
  FrfSet ForPose(const std::string& pose_id) const;
  /// Adds all FRFs of `other`; @throws std::invalid_argument on a duplicate.
  void Merge(const FrfSet& other);

  auto begin() const { return frfs_.begin(); }
  auto end() const { return frfs_.end(); }

 private:
  std::map<FrfKey, Frf> frfs_;
};

// Unit plausibility of a receptance (issue #22 item 1). Plausible peak
// receptance of a tool tip or a machine structure [m/N]: 1 mm/N would move
// a tool 10 cm under a 100 N tap; 1e-12 m/N is stiffer than any steel
// structure a hammer can excite (a 1 m cube of steel under a point load is
// ~1e-10 m/N). Robot tool tips are 1e-7..1e-5 m/N (Cordes, Hintze, Altintas,
// "Chatter stability in robotic milling", Robot. CIM 55 (2019) 11-18),
// machine-tool tips 1e-8..1e-6 m/N (Altintas, Manufacturing Automation,
// 2nd ed. (2012), Ch. 3 examples).
/// The highest line of a measured tool-tip FRF [Hz]: a hammer test of a
/// robot's tool reaches 100 Hz and more (its modes are 5 - 2000 Hz; tests
/// run to 0.1 - 10 kHz). Below, the frequencies are in kHz: a test to 1 kHz
/// saved in kHz ends at 1 "Hz", one to 20 kHz at 20.
inline constexpr double kMinPlausibleMeasuredTopHz = 25.0;
inline constexpr double kMaxPlausibleReceptance = 1e-3;
inline constexpr double kMinPlausibleReceptance = 1e-12;

/// The one unit check of a peak receptance [m/N] against
/// [kMinPlausibleReceptance, kMaxPlausibleReceptance]: "" if plausible, else
/// a sentence starting with `what` that names the value, the range and the
/// likely unit mistakes (mm or um under an _m column, kN under force_N, a
/// mobility or accelerance read as receptance; or mN, km), and where to
/// look: the column names of a CSV, records 8-10 of a UFF58 file (its unit
/// lines and ordinate data type), either when `format` is kUnknown.
enum class FrfFileFormat { kUnknown, kCsv, kUff58 };
std::string ReceptancePeakFinding(const std::string& what, double peak_m_per_N,
                                  FrfFileFormat format = FrfFileFormat::kUnknown);

/// The one check of a measured FRF's frequency axis: "" when its highest
/// line `top_hz` reaches kMinPlausibleMeasuredTopHz (or is not positive),
/// else a sentence starting with `what` that names the line, the bound and
/// the likely mistake (kHz), and where to look for the format (a CSV's
/// freq_hz header, a UFF58 file's record 7 and 8; either when kUnknown).
std::string FrequencyAxisFinding(const std::string& what, double top_hz,
                                 FrfFileFormat format = FrfFileFormat::kUnknown);

/// The largest median of three neighbouring |H| (a resonance spans several
/// lines; a lone line is noise) of `frf` on its lines above 0 Hz with
/// coherence >= 0.5 (all lines above 0 Hz when it has no coherence) [m/N].
/// The 0 Hz line and lone lines are left out: a hammer test does not measure
/// the static compliance, and an integrated accelerometer's drift makes the
/// lowest lines of a measured receptance large (tests/tap_test_synth.h:
/// 1.2e-3 m/N at 0 Hz for a 6e-5 m/N tool tip).
double PeakReceptance(const Frf& frf);

/// ReceptancePeakFinding of every FRF of the set: one finding per FRF out of
/// range, each starting with `source` and the FRF's key.
std::vector<std::string> ReceptanceUnitFindings(const FrfSet& frfs, const std::string& source,
                                                FrfFileFormat format = FrfFileFormat::kUnknown);

}  // namespace robomach::dynamics
