#pragma once
// The prediction workflow (frf-predict, Python's predict_frfs): the tool-tip
// receptance and the dynamics of a robot model at a list of postures, with
// the checks a user expects - a posture outside the joint limits and one
// near a singularity are flagged, not refused.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "robomach/common/eigen_types.h"
#include "robomach/common/run_status.h"
#include "robomach/dynamics/posture_dynamics.h"

namespace robomach::dynamics {

enum class ReceptanceMethod {
  kModal,   // superposition of the real modes (complex modes for non-proportional damping)
  kDirect,  // solve (K - w^2 M + i w C) x = f per line
};

/// "modal" or "direct" (frf-predict's --method).
const char* ToString(ReceptanceMethod m);
/// The inverse of ToString. @throws std::invalid_argument for anything else.
ReceptanceMethod ParseReceptanceMethod(const std::string& name);

/// H(f) [m/N] by `method` (Receptance or ReceptanceDirect).
std::vector<Eigen::Matrix3cd> ReceptanceBy(ReceptanceMethod method, const PostureDynamics& dynamics,
                                           const Eigen::VectorXd& freq_hz);

struct NamedPosture {
  std::string id;
  Eigen::VectorXd q;  // [rad]
};

struct PredictOptions {
  /// kModal or kDirect (a value cast from another integer is refused).
  ReceptanceMethod method{ReceptanceMethod::kModal};
  /// Called after each posture with (postures done, postures in all).
  std::function<void(long, long)> progress;

  /// @throws OptionError("method", "method: expected modal (0) or direct
  ///   (1), got N") for a method that is neither.
  void Validate() const;
};

struct PosturePredictionResult {
  std::string id;
  PostureDynamics dynamics;
  std::vector<Eigen::Matrix3cd> H;  // [m/N] per line of freq_hz, in B
  std::vector<int> joints_outside_limits;  // 0-based
};

/// A mode below this is a rigid-body mode: no robot-held tool has one (robot
/// modes start at a few Hz; docs/plausibility.md's joint frequencies >= 1 Hz).
inline constexpr double kMinPredictedModeHz = 0.01;

/// Plausible top of an FRF band [Hz] (docs/plausibility.md): hammer tests of
/// robots and machine tools have lines to 0.1 - 10 kHz (Schmitz and Smith,
/// "Machining Dynamics", ch. 2); a robot's structural modes are below 2 kHz
/// (the joint frequencies of docs/plausibility.md). Outside: kHz or mHz
/// typed in an Hz option (frf-synth, frf-predict flag it, exit 3).
inline constexpr double kMinPlausibleFmaxHz = 1.0;
inline constexpr double kMaxPlausibleFmaxHz = 50000.0;
/// Most lines of a predicted or synthesised frequency grid: FFT analysers
/// give 400 - 25 600 lines, so 200 000 is 8 times the finest of them; a grid
/// over it is refused (exit 64), because its outputs are gigabytes (5
/// postures x 800 000 lines made a 2.28 GB CSV).
inline constexpr double kMaxFrequencyLines = 200000.0;

struct FrfPredictionResult {
  RunFindings verdict;
  RunStatus status() const { return verdict.status(); }
  std::vector<PosturePredictionResult> postures;  // in the order given
};

/// Evaluates `model` at each posture and its receptance at `freq_hz`
/// (finite, >= 0). Findings (input_index = the posture's index): each joint
/// outside its limits, each posture near a singularity (the FRF, in joint
/// space, stays valid; the Cartesian M, K, C do not), each posture with a
/// mode below kMinPredictedModeHz (a singular stiffness: a spring of the
/// model that holds nothing, e.g. an interface stiffness made negligible by
/// a unit mistake; its FRF is that of a free body).
/// @throws std::invalid_argument for a non-finite frequency or a posture of
///   the wrong size; std::runtime_error for a non-finite receptance.
FrfPredictionResult PredictFrfs(const std::shared_ptr<const RobotModel>& model,
                                const std::vector<NamedPosture>& postures, const Eigen::VectorXd& freq_hz,
                                const PredictOptions& options = {});

}  // namespace robomach::dynamics
