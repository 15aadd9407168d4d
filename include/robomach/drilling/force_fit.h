#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "robomach/common/solver_status.h"
#include "robomach/drilling/drill_forces.h"

namespace robomach::drilling {

/// One row of a measured thrust/torque table (formats.md §9.1), SI.
struct ForceTableRow {
  double diameter{0.0};      // D [m]
  double feed_per_rev{0.0};  // f [m/rev]
  double thrust{0.0};        // [N]
  double torque{0.0};        // [N·m]
};

/// The library's one solver status (kNotImproved does not occur here).
using FitStatus = SolverStatus;

/// A row of a force table that the fit cannot use: a value that is not
/// positive and finite, or a row where the force model gives no positive
/// thrust and torque (a feed far beyond the model's range for the diameter,
/// typically a feed in mm/min under feed_mm_per_rev). Bad data, not a bad
/// call: a tool maps `row()` to the file's line (exit 65).
class ForceTableRowError : public std::invalid_argument {
 public:
  ForceTableRowError(size_t row, const std::string& message) : std::invalid_argument(message), row_(row) {}
  /// 0-based index into the rows given to FitDrillingForces.
  size_t row() const { return row_; }

 private:
  size_t row_;
};

struct ForceFitOptions {
  ChiselModel chisel{ChiselModel::kSeedScaling};
  bool fit_kienzle_exponent{true};   // false: keep initial.kienzle_exponent
  int max_iterations{200};
  ForceModelOptions model;

  /// The bounds (issue #36):
  /// - max_iterations >= 1: Ceres' iteration budget, 0 fits nothing.
  /// - model: ForceModelOptions::Validate, its fields named "model.FIELD".
  /// @throws OptionError(field, "FIELD: expected a value >= LO, got VALUE").
  void Validate() const;
};

struct ForceFitResult {
  DrillingMaterial material;          // fitted coefficients
  double std_dev_shear_stress_thrust{NAN};  // 1 sigma [Pa]
  double std_dev_shear_stress_torque{NAN};  // 1 sigma [Pa]
  double std_dev_kienzle_exponent{NAN};     // 1 sigma (0 if held)
  std::vector<double> thrust_model;   // per row [N]
  std::vector<double> torque_model;   // per row [N·m]
  double max_rel_error_thrust{NAN};   // max |model - measured| / measured
  double max_rel_error_torque{NAN};
  double rms_rel_error{NAN};          // over all residuals
  /// The fitted Kienzle exponent ended on its bound (0 or 0.95, within 1e-3): the forces
  /// grow with the feed faster than linearly or hardly at all, which
  /// usually means a unit mistake in the table.
  bool kienzle_exponent_at_bound{false};
  FitStatus status{FitStatus::kFailed};
  std::string solver_message;         // ceres::Solver::Summary::BriefReport
};

/// Thrust and torque of the drill fully engaged, without tilt, at row `row`
/// (its diameter replaces drill.diameter; the web and chisel scale with it).
DrillForces PredictRow(const DrillGeometry& drill, const DrillingMaterial& material,
                       const ForceTableRow& row, const ForceModelOptions& options = {});

/// Fits K_TH, K_TQ and the Kienzle exponent m (DrillingMaterial) to the
/// table by least squares on the relative errors
/// (model - measured) / measured of thrust and torque (Ceres,
/// central-difference Jacobians). The parameters are log K_TH, log K_TQ and
/// m, so the shear stresses stay positive. Standard deviations come from the
/// covariance at the solution scaled by the residual variance
/// sigma^2 = sum r^2 / (2 n - p) (no measurement noise is given).
/// @throws std::invalid_argument for fewer rows than parameters;
///   ForceTableRowError for a non-positive or non-finite value in a row, or
///   a row where the model gives no positive thrust and torque.
ForceFitResult FitDrillingForces(const DrillGeometry& drill, const std::vector<ForceTableRow>& rows,
                                 const ForceFitOptions& options = {});

}  // namespace robomach::drilling
