#include "robomach/drilling/force_fit.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <ceres/ceres.h>

#include "robomach/common/option_validate.h"

namespace robomach::drilling {
namespace {

// The Kienzle exponent is fitted as y with m = kMaxKienzle / (1 + e^-y), so
// that every value the solver tries, numeric-derivative steps included, is
// one the force model accepts (CheckValid: 0 <= m < 1). The former linear m
// with a guard at -0.5 let the solver step below 0, where the model threw
// std::invalid_argument out of the solve (exit 64 for a table in the wrong
// units). A fit that runs to either end is reported in the result.
constexpr double kMaxKienzle = 0.95;
constexpr double kKienzleAtBound = 1e-3;  // m within this of 0 or kMaxKienzle: on its bound

double KienzleFromY(double y) { return kMaxKienzle / (1.0 + std::exp(-y)); }
double YFromKienzle(double m) { return std::log(m / (kMaxKienzle - m)); }

DrillingMaterial MaterialFromParameters(const DrillingMaterial& base, const double* x, bool fit_m) {
  DrillingMaterial m = base;
  m.shear_stress_thrust = std::exp(x[0]);
  m.shear_stress_torque = std::exp(x[1]);
  if (fit_m) m.kienzle_exponent = KienzleFromY(x[2]);
  return m;
}

// Residuals of one row: relative thrust and torque errors.
struct RowResidual {
  const DrillGeometry* drill;
  const DrillingMaterial* base;
  ForceTableRow row;
  ForceModelOptions options;
  bool fit_m;
  bool operator()(const double* x, double* r) const {
    const DrillForces f = PredictRow(*drill, MaterialFromParameters(*base, x, fit_m), row, options);
    r[0] = (f.thrust - row.thrust) / row.thrust;
    r[1] = (f.torque - row.torque) / row.torque;
    return true;
  }
};

}  // namespace

DrillForces PredictRow(const DrillGeometry& drill, const DrillingMaterial& material,
                       const ForceTableRow& row, const ForceModelOptions& options) {
  DrillGeometry d = drill;
  d.diameter = row.diameter;
  // Deep enough for full engagement: the point length is below D.
  const DrillState st{.feed_per_rev = row.feed_per_rev, .penetration = 2.0 * row.diameter};
  return ComputeDrillForces(d, material, st, options);
}

void ForceFitOptions::Validate() const {
  CheckOptionAtLeast("max_iterations", max_iterations, 1);
  ValidateNested("model", model);
}

ForceFitResult FitDrillingForces(const DrillGeometry& drill, const std::vector<ForceTableRow>& rows,
                                 const ForceFitOptions& options) {
  options.Validate();
  const int n_par = options.fit_kienzle_exponent ? 3 : 2;
  if (static_cast<int>(rows.size()) * 2 <= n_par) {
    throw std::invalid_argument("force table: expected at least 2 rows to fit the coefficients");
  }
  for (size_t k = 0; k < rows.size(); ++k) {
    const ForceTableRow& r = rows[k];
    for (double v : {r.diameter, r.feed_per_rev, r.thrust, r.torque}) {
      if (!(std::isfinite(v) && v > 0.0)) {
        throw ForceTableRowError(k, "force table row " + std::to_string(k + 1) +
                                        ": expected positive finite values");
      }
    }
  }
  DrillingMaterial base;
  base.chisel = options.chisel;
  const bool fit_m = options.fit_kienzle_exponent;
  base.kienzle_exponent = fit_m ? 0.25 : base.kienzle_exponent;
  // Start: K = 1 Pa gives forces proportional to K; scale to the data.
  double x[3] = {0.0, 0.0, fit_m ? YFromKienzle(base.kienzle_exponent) : 0.0};
  {
    double st = 0.0, sq = 0.0;
    for (size_t k = 0; k < rows.size(); ++k) {
      const ForceTableRow& r = rows[k];
      const DrillForces f = PredictRow(drill, MaterialFromParameters(base, x, fit_m), r, options.model);
      // The model's forces are proportional to K; where they are not
      // positive at K = 1 Pa, no K fits the row (the dynamic rake of a feed
      // of ~diameter per revolution turns the thrust negative).
      if (!(std::isfinite(f.thrust) && f.thrust > 0.0 && std::isfinite(f.torque) && f.torque > 0.0)) {
        std::ostringstream m;
        m << "force table row " << k + 1 << ": feed_mm_per_rev " << r.feed_per_rev * 1e3 << " with diameter_mm "
          << r.diameter * 1e3 << " is outside the force model's range (it gives a thrust of " << f.thrust
          << " N per Pa of shear stress); is the feed in mm/min instead of mm/rev?";
        throw ForceTableRowError(k, m.str());
      }
      st += std::log(r.thrust / f.thrust);
      sq += std::log(r.torque / f.torque);
    }
    x[0] = st / rows.size();
    x[1] = sq / rows.size();
  }
  ceres::Problem problem;
  for (const ForceTableRow& r : rows) {
    auto* cost = new ceres::NumericDiffCostFunction<RowResidual, ceres::CENTRAL, 2, 3>(
        new RowResidual{&drill, &base, r, options.model, fit_m});
    problem.AddResidualBlock(cost, nullptr, x);
  }
  if (!options.fit_kienzle_exponent) {
    problem.SetManifold(x, new ceres::SubsetManifold(3, {2}));
  }
  ceres::Solver::Options so;
  so.max_num_iterations = options.max_iterations;
  so.function_tolerance = 1e-12;
  so.parameter_tolerance = 1e-12;
  so.gradient_tolerance = 1e-14;
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);

  ForceFitResult out;
  out.material = MaterialFromParameters(base, x, fit_m);
  out.kienzle_exponent_at_bound = fit_m && (out.material.kienzle_exponent < kKienzleAtBound ||
                                            out.material.kienzle_exponent > kMaxKienzle - kKienzleAtBound);
  out.solver_message = summary.BriefReport();
  out.status = summary.termination_type == ceres::CONVERGENCE ? FitStatus::kConverged
               : summary.IsSolutionUsable()                   ? FitStatus::kNotConverged
                                                               : FitStatus::kFailed;
  double ss = 0.0;
  out.max_rel_error_thrust = out.max_rel_error_torque = 0.0;
  for (const ForceTableRow& r : rows) {
    const DrillForces f = PredictRow(drill, out.material, r, options.model);
    out.thrust_model.push_back(f.thrust);
    out.torque_model.push_back(f.torque);
    const double et = (f.thrust - r.thrust) / r.thrust, eq = (f.torque - r.torque) / r.torque;
    out.max_rel_error_thrust = std::max(out.max_rel_error_thrust, std::abs(et));
    out.max_rel_error_torque = std::max(out.max_rel_error_torque, std::abs(eq));
    ss += et * et + eq * eq;
  }
  const int n_res = 2 * static_cast<int>(rows.size());
  out.rms_rel_error = std::sqrt(ss / n_res);
  // Covariance of (log K_TH, log K_TQ, m), scaled by the residual variance.
  const int dof = n_res - n_par;
  ceres::Covariance::Options co;
  co.algorithm_type = ceres::DENSE_SVD;
  co.null_space_rank = -1;
  ceres::Covariance cov(co);
  std::vector<std::pair<const double*, const double*>> blocks{{x, x}};
  if (dof > 0 && cov.Compute(blocks, &problem)) {
    double C[9];
    cov.GetCovarianceBlock(x, x, C);
    const double s2 = ss / dof;
    out.std_dev_shear_stress_thrust = out.material.shear_stress_thrust * std::sqrt(s2 * C[0]);
    out.std_dev_shear_stress_torque = out.material.shear_stress_torque * std::sqrt(s2 * C[4]);
    out.std_dev_kienzle_exponent =
        // Delta method: dm/dy = m (1 - m / kMaxKienzle).
        fit_m ? std::sqrt(std::max(0.0, s2 * C[8])) * out.material.kienzle_exponent *
                    (1.0 - out.material.kienzle_exponent / kMaxKienzle)
              : 0.0;
  }
  return out;
}

}  // namespace robomach::drilling
