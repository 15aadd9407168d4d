#include "robomach/machine/acquisition.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "robomach/common/units.h"

namespace robomach::machine {

std::vector<int> MapKinematicAxes(const std::vector<AxisScale>& axes, const MachineKinematics& kinematics) {
  std::vector<int> map;
  const auto names = kinematics.axis_names();
  const auto rot = kinematics.rotary();
  for (size_t j = 0; j < names.size(); ++j) {
    const int i = FindAxis(axes, names[j]);
    if (i < 0) throw std::invalid_argument("the kinematics needs axis " + names[j] + ", which is not under axes:");
    if ((axes[i].kind == AxisKind::kRotary) != rot[j]) {
      throw std::invalid_argument("axis " + names[j] + " must be " + (rot[j] ? "rotary (_deg)" : "linear (_mm)"));
    }
    map.push_back(i);
  }
  return map;
}

Acquisition::Acquisition(const Machine& machine, const Compensation* compensation)
    : machine_(machine), compensation_(compensation) {
  const size_t n = machine.axes.size();
  if (compensation_ != nullptr && compensation_->num_axes() != static_cast<int>(n)) {
    throw std::invalid_argument("Acquisition: compensation and machine differ in axis count");
  }
  measured_.resize(n);
  sample_.real.resize(n);
  q_.resize(static_cast<Eigen::Index>(machine.kinematic_axis.size()));
}

const AcquiredSample& Acquisition::Process(double t_s, const std::int64_t* counts) {
  const size_t n = machine_.axes.size();
  for (size_t a = 0; a < n; ++a) measured_[a] = machine_.axes[a].Measured(counts[a]);  // eq. (1)
  if (compensation_ != nullptr) {
    compensation_->MeasuredToReal(t_s, measured_.data(), sample_.real.data());       // eq. (3)
  } else {
    sample_.real = measured_;
  }
  for (Eigen::Index j = 0; j < q_.size(); ++j) q_(j) = sample_.real[machine_.kinematic_axis[j]];
  sample_.pose = machine_.kinematics->Forward(q_);
  return sample_;
}

ProgrammedPath::ProgrammedPath(std::vector<Eigen::Vector3d> tips, std::vector<Eigen::Vector3d> axes)
    : tips_(std::move(tips)), axes_(std::move(axes)) {
  if (tips_.size() < 2 || tips_.size() != axes_.size()) {
    throw std::invalid_argument("programmed path: expected at least 2 points, each with a tool axis");
  }
  s_.push_back(0.0);
  for (size_t i = 0; i < tips_.size(); ++i) {
    if (!tips_[i].allFinite() || !axes_[i].allFinite()) throw std::invalid_argument("programmed path: non-finite value");
    const double n = axes_[i].norm();
    if (!(n > 1e-9)) {
      throw std::invalid_argument("programmed path: point " + std::to_string(i + 1) + " has a zero tool axis");
    }
    axes_[i] /= n;
    if (i > 0) s_.push_back(s_.back() + (tips_[i] - tips_[i - 1]).norm());
  }
  if (!(s_.back() > 0.0)) throw std::invalid_argument("programmed path: zero length");
}

ToolPose ProgrammedPath::At(double s) const {
  ToolPose p;
  if (s <= 0.0) {
    p.p_W = tips_.front();
    p.k_W = axes_.front();
    return p;
  }
  if (s >= s_.back()) {
    p.p_W = tips_.back();
    p.k_W = axes_.back();
    return p;
  }
  const size_t i = std::upper_bound(s_.begin(), s_.end(), s) - s_.begin() - 1;
  const double len = s_[i + 1] - s_[i];
  const double f = len > 0.0 ? (s - s_[i]) / len : 0.0;
  p.p_W = tips_[i] + f * (tips_[i + 1] - tips_[i]);
  p.k_W = (axes_[i] + f * (axes_[i + 1] - axes_[i])).normalized();
  return p;
}

ContourTracker::ContourTracker(const ProgrammedPath& path, int window_segments)
    : path_(path), window_(std::max(1, window_segments)) {}

namespace {

// Squared distance of p to segment [a, b] and the segment parameter of the
// nearest point: the cheap part, evaluated for every candidate segment.
inline double SegmentDistanceSq(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& p,
                                double* f) {
  const Eigen::Vector3d ab = b - a;
  const double l2 = ab.squaredNorm();
  *f = l2 > 0.0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (p - (a + *f * ab)).squaredNorm();
}

}  // namespace

ContourError ContourTracker::OnSegment(int i, const ToolPose& pose) const {
  double f = 0.0;
  const Eigen::Vector3d& a = path_.tips()[i];
  const Eigen::Vector3d& b = path_.tips()[i + 1];
  ContourError e;
  e.distance = std::sqrt(SegmentDistanceSq(a, b, pose.p_W, &f));
  e.s = path_.arc_length()[i] + f * (path_.arc_length()[i + 1] - path_.arc_length()[i]);
  const Eigen::Vector3d k = (path_.axes()[i] + f * (path_.axes()[i + 1] - path_.axes()[i])).normalized();
  e.axis_angle = std::atan2(k.cross(pose.k_W).norm(), k.dot(pose.k_W));
  return e;
}

double ContourTracker::DistanceSq(int i, const ToolPose& pose) const {
  double f = 0.0;
  return SegmentDistanceSq(path_.tips()[i], path_.tips()[i + 1], pose.p_W, &f);
}

ContourError ContourTracker::Nearest(const ToolPose& pose) const {
  ContourError best;
  best.distance = INFINITY;
  for (int i = 0; i + 1 < path_.num_points(); ++i) {
    const ContourError e = OnSegment(i, pose);
    if (e.distance < best.distance) best = e;
  }
  return best;
}

ContourError ContourTracker::Next(const ToolPose& pose) {
  const int segments = path_.num_points() - 1;
  int best_i = 0;
  double best = INFINITY;
  auto exhaustive = [&](bool prefer_first) {
    best = INFINITY;
    for (int i = 0; i < segments; ++i) {
      const double d = DistanceSq(i, pose);
      if (d < best) best = d, best_i = i;
    }
    if (prefer_first) {
      // A closed path starts and ends at the same point: start at its start
      // (the first segment within 10 µm of the nearest; measurement noise
      // can make the end look nearer by a few micrometres).
      const double tol = std::sqrt(best) + 1e-5;
      for (int i = 0; i < best_i; ++i) {
        const double d = DistanceSq(i, pose);
        if (d <= tol * tol) {
          best = d, best_i = i;
          break;
        }
      }
    }
  };
  if (last_ < 0) {
    exhaustive(true);
  } else {
    int lo = std::max(0, last_ - window_), hi = std::min(segments - 1, last_ + window_);
    for (int i = lo; i <= hi; ++i) {
      const double d = DistanceSq(i, pose);
      if (d < best) best = d, best_i = i;
    }
    // Widen while the best sits on an edge of the window and the distance falls.
    while (best_i == hi && hi < segments - 1) {
      const double d = DistanceSq(++hi, pose);
      if (!(d < best)) break;
      best = d, best_i = hi;
    }
    while (best_i == lo && lo > 0) {
      const double d = DistanceSq(--lo, pose);
      if (!(d < best)) break;
      best = d, best_i = lo;
    }
    // Far off the local stretch (a jump, or the machine somewhere else on the
    // path): search everything again.
    if (best > kRecoverDistance * kRecoverDistance) exhaustive(false);
  }
  last_ = best_i;
  return OnSegment(best_i, pose);
}

SeriesStats Stats(const std::vector<double>& v) {
  SeriesStats s;
  s.count = static_cast<long>(v.size());
  if (v.empty()) return s;
  double sum = 0.0, sq = 0.0;
  for (double x : v) {
    s.max_abs = std::max(s.max_abs, std::abs(x));
    sum += x;
    sq += x * x;
  }
  s.mean = sum / v.size();
  s.rms = std::sqrt(sq / v.size());
  double var = 0.0;
  for (double x : v) var += (x - s.mean) * (x - s.mean);
  s.std_dev = v.size() > 1 ? std::sqrt(var / (v.size() - 1)) : 0.0;
  return s;
}

std::vector<std::string> ContourUnitFindings(const std::vector<ContourError>& contour, const ProgrammedPath& path) {
  std::vector<std::string> out;
  double d = 0.0, a = 0.0;
  for (const ContourError& c : contour) {
    d = std::max(d, c.distance);
    a = std::max(a, c.axis_angle);
  }
  Eigen::Vector3d lo = path.tips().front(), hi = lo;
  for (const Eigen::Vector3d& p : path.tips()) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double extent = (hi - lo).norm();
  char b[500];
  if (d > kMaxPlausibleContourError) {
    std::snprintf(b, sizeof b,
                  "contour error up to %.4g mm (%.3g %% of the %.4g mm extent of the programmed path), more than the "
                  "%.4g mm a machine can be off its path: the count columns are probably swapped (their names in the "
                  "counts header against the data), or a resolution_mm/_deg or origin in the machine file is in "
                  "another unit, or the program is another one",
                  d * 1e3, extent > 0 ? 100 * d / extent : 0.0, extent * 1e3, kMaxPlausibleContourError * 1e3);
    out.push_back(b);
  }
  // With the tip far off its path the nearest point's programmed axis is
  // another one too: the axis error then adds nothing.
  if (a > kMaxPlausibleAxisError && out.empty()) {
    std::snprintf(b, sizeof b,
                  "tool axis error up to %.4g deg, more than the %.4g deg a machine's axis can be off: the rotary "
                  "count columns are probably swapped, or a resolution_deg is in another unit (rad, arcsec)",
                  a * 180.0 / kPi, kMaxPlausibleAxisError * 180.0 / kPi);
    out.push_back(b);
  }
  return out;
}

RunFindings JudgeContour(const std::vector<ContourError>& contour, const ProgrammedPath& path) {
  RunFindings verdict;
  for (const std::string& f : ContourUnitFindings(contour, path)) {
    verdict.Flag("implausible (unit or column mistake?): " + f);
  }
  return verdict;
}

}  // namespace robomach::machine
