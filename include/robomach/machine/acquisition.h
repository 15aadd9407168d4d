#pragma once
// From encoder counts to the tool in workpiece coordinates, sample by sample
// (seed 002: eq. (1), then compensation eqs. (2)-(5), then the kinematics
// eqs. (6)-(12)); and the programmed path it is compared with.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "robomach/common/run_status.h"
#include "robomach/machine/axes.h"
#include "robomach/machine/compensation.h"
#include "robomach/machine/kinematics.h"

namespace robomach::machine {

/// A measured machine: its axes (in the counts file's order), the kinematics
/// and, for every kinematic axis, its index among `axes`.
struct Machine {
  std::vector<AxisScale> axes;
  std::shared_ptr<const MachineKinematics> kinematics;
  std::vector<int> kinematic_axis;  // kinematics->axis_names()[j] is axes[kinematic_axis[j]]
};

/// @throws std::invalid_argument if a kinematic axis is missing from `axes`.
std::vector<int> MapKinematicAxes(const std::vector<AxisScale>& axes, const MachineKinematics& kinematics);

/// One acquired sample (formats.md §8.5).
struct AcquiredSample {
  std::vector<double> real;  // compensated axis positions, in axes order [m, rad]
  ToolPose pose;             // tool tip and axis in workpiece coordinates
};

/// Counts -> measured -> real (compensation) -> tool pose. Reuses its buffers.
class Acquisition {
 public:
  Acquisition(const Machine& machine, const Compensation* compensation);
  /// `counts` holds one count per axis (axes order).
  const AcquiredSample& Process(double t_s, const std::int64_t* counts);

 private:
  const Machine& machine_;
  const Compensation* compensation_;
  std::vector<double> measured_;
  Eigen::VectorXd q_;
  AcquiredSample sample_;
};

/// The programmed path: a polyline of tool tips with the tool axis at each
/// vertex (linearly interpolated and normalised between vertices).
class ProgrammedPath {
 public:
  /// @throws std::invalid_argument for fewer than 2 points, a zero tool axis,
  ///   or non-finite values.
  ProgrammedPath(std::vector<Eigen::Vector3d> tips, std::vector<Eigen::Vector3d> axes);
  int num_points() const { return static_cast<int>(tips_.size()); }
  double length() const { return s_.back(); }
  /// Pose at arc length s (tip distance along the polyline), clamped to the ends.
  ToolPose At(double s) const;
  const std::vector<Eigen::Vector3d>& tips() const { return tips_; }
  const std::vector<Eigen::Vector3d>& axes() const { return axes_; }
  const std::vector<double>& arc_length() const { return s_; }

 private:
  std::vector<Eigen::Vector3d> tips_, axes_;
  std::vector<double> s_;
};

/// Contour error of one sample: distance of the tip to the programmed
/// polyline and angle between the tool axis and the programmed axis at the
/// nearest point.
struct ContourError {
  double distance{0.0};    // [m]
  double axis_angle{0.0};  // [rad]
  double s{0.0};           // arc length of the nearest point [m]
};

/// Nearest-point search that follows the machine along the path: the first
/// sample searches every segment, later ones a window (±8 segments) around the previous
/// nearest segment, widened while the distance keeps falling at its edge.
/// (A full search at every sample would cost n_samples x n_segments.) The
/// first sample takes the earliest segment within 10 µm of the nearest, so a
/// closed path is followed from its start; a sample farther than
/// kRecoverDistance from the local stretch triggers a full search again.
class ContourTracker {
 public:
  static constexpr double kRecoverDistance = 1e-4;  // [m]
  explicit ContourTracker(const ProgrammedPath& path, int window_segments = 8);
  ContourError Next(const ToolPose& pose);
  /// Exhaustive search, for tests and for the first sample.
  ContourError Nearest(const ToolPose& pose) const;

 private:
  ContourError OnSegment(int i, const ToolPose& pose) const;
  double DistanceSq(int i, const ToolPose& pose) const;
  const ProgrammedPath& path_;
  int window_;
  int last_{-1};
};

// Unit plausibility of a contour error (issue #22 item 1). A five-axis
// machine follows its programmed path to within micrometres to tens of
// micrometres (servo lag and geometric errors; ISO 10791-6 circular and
// cone tests accept 0.01-0.05 mm), and its tool axis to within hundredths
// of a degree. A contour error past these limits (~100 times wider) is not
// a machine error but a mismatch of the data: count columns swapped, a
// resolution in the wrong unit, another program, or another reference
// position.
inline constexpr double kMaxPlausibleContourError = 1e-3;      // [m] = 1 mm
inline constexpr double kMaxPlausibleAxisError = 0.0174532925;  // [rad] = 1 deg

/// Findings of the plausibility check of a run's contour errors against the
/// limits above and against the programmed path's extent (a contour error
/// as large as 10 % of the path's bounding box means the tool was elsewhere);
/// each a sentence naming the value, the limit and the likely mistake (the
/// axis error only when the contour error is plausible: a tip far off its
/// path is compared with another point's axis).
std::vector<std::string> ContourUnitFindings(const std::vector<ContourError>& contour, const ProgrammedPath& path);

/// axis-acquire's verdict on a run with a programmed path: flagged (exit 3)
/// with one finding per ContourUnitFindings sentence, prefixed
/// "implausible (unit or column mistake?): ".
RunFindings JudgeContour(const std::vector<ContourError>& contour, const ProgrammedPath& path);

/// Statistics of a series (max |v|, mean, rms, standard deviation).
struct SeriesStats {
  double max_abs{0.0}, mean{0.0}, rms{0.0}, std_dev{0.0};
  long count{0};
};
SeriesStats Stats(const std::vector<double>& v);

}  // namespace robomach::machine
