#include "robomach/polishing/optimise.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <nlopt.hpp>

#include "robomach/common/units.h"

namespace robomach::polishing {
namespace {

constexpr double kRatioMin = 0.5, kRatioMax = 1.0;        // r / d
constexpr double kPitchMin = 0.5, kPitchMax = kPi;        // pitch / r

PathParameters FromUnit(const std::vector<double>& x, const PathParameters& base, const OptimiseOptions& o) {
  PathParameters p = base;
  p.offset = o.offset_min + std::clamp(x[0], 0.0, 1.0) * (o.offset_max - o.offset_min);
  p.radius = p.offset * (kRatioMin + std::clamp(x[1], 0.0, 1.0) * (kRatioMax - kRatioMin));
  p.pitch = p.radius * (kPitchMin + std::clamp(x[2], 0.0, 1.0) * (kPitchMax - kPitchMin));
  return p;
}

std::vector<double> ToUnit(const PathParameters& p, const OptimiseOptions& o) {
  return {std::clamp((p.offset - o.offset_min) / (o.offset_max - o.offset_min), 0.0, 1.0),
          std::clamp((p.radius / p.offset - kRatioMin) / (kRatioMax - kRatioMin), 0.0, 1.0),
          std::clamp((p.pitch / p.radius - kPitchMin) / (kPitchMax - kPitchMin), 0.0, 1.0)};
}

struct Tracker {
  const std::function<double(const PathParameters&)>* f;
  const PathParameters* base;
  const OptimiseOptions* o;
  OptimiseResult* res;
  std::vector<double> best_x;
  double Eval(const std::vector<double>& x) {
    double v = (*f)(FromUnit(x, *base, *o));
    if (!std::isfinite(v)) v = 1e6;
    ++res->evaluations;
    if (res->history.empty() || v < res->best_value) {
      res->best_value = v;
      best_x = x;
    }
    return v;
  }
};

double NloptThunk(unsigned, const double* x, double*, void* data) {
  Tracker* t = static_cast<Tracker*>(data);
  const double v = t->Eval(std::vector<double>(x, x + 3));
  t->res->history.push_back(t->res->best_value);
  if (t->o->progress) t->o->progress(t->res->evaluations, t->res->best_value);
  return v;
}

void RunNlopt(nlopt::algorithm alg, int budget, std::vector<double>* x, Tracker* t, std::string* status) {
  nlopt::opt opt(alg, 3);
  opt.set_lower_bounds(std::vector<double>(3, 0.0));
  opt.set_upper_bounds(std::vector<double>(3, 1.0));
  opt.set_min_objective(NloptThunk, t);
  opt.set_maxeval(budget);
  if (alg == nlopt::LN_SBPLX) {
    opt.set_initial_step(std::vector<double>(3, 0.05));
    opt.set_xtol_abs(1e-3);
  }
  double f = 0.0;
  try {
    const nlopt::result r = opt.optimize(*x, f);
    *status = r == nlopt::MAXEVAL_REACHED ? "max_evaluations" : "converged";
  } catch (const nlopt::roundoff_limited&) {
    *status = "roundoff_limited";
  } catch (const std::runtime_error& e) {
    *status = std::string("failed: ") + e.what();
  }
}

}  // namespace

OptimiseResult OptimiseCycloid(const std::function<double(const PathParameters&)>& objective,
                               const PathParameters& start, const OptimiseOptions& o) {
  OptimiseResult res;
  Tracker t{&objective, &start, &o, &res, {}};
  if (o.method == Optimiser::kNlopt) {
    res.method = "NLopt GN_DIRECT_L (" + std::to_string(o.global_evaluations) + " evaluations) then LN_SBPLX (" +
                 std::to_string(o.local_evaluations) + ")";
    std::vector<double> x = ToUnit(start, o);
    std::string status;
    RunNlopt(nlopt::GN_DIRECT_L, o.global_evaluations, &x, &t, &status);
    x = t.best_x;
    RunNlopt(nlopt::LN_SBPLX, o.local_evaluations, &x, &t, &status);
    res.status = status;
  } else {
    res.method = "PSO with adaptive inertia (seed 004 eq. 18), " + std::to_string(o.pso_particles) + " particles";
    std::mt19937 rng(o.seed);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    const int np = o.pso_particles;
    constexpr double kWmin = 0.4, kWmax = 0.9, kC1 = 2.0, kC2 = 2.0, kVmax = 0.2;
    std::vector<std::vector<double>> x(np, std::vector<double>(3)), v = x, pbest;
    std::vector<double> f(np), pbest_f;
    x[0] = ToUnit(start, o);  // the default path is one of the particles
    for (int i = 1; i < np; ++i)
      for (double& xi : x[i]) xi = U(rng);
    for (auto& vi : v)
      for (double& c : vi) c = kVmax * (2 * U(rng) - 1);
    for (int i = 0; i < np; ++i) f[i] = t.Eval(x[i]);
    pbest = x;
    pbest_f = f;
    double best = res.best_value, last_improved = best;
    int stall = 0;
    res.status = "max_iterations";
    for (int it = 0; it < o.pso_max_iterations; ++it) {
      const double fmin = *std::min_element(f.begin(), f.end());
      double favg = 0;
      for (double fi : f) favg += fi / np;
      for (int i = 0; i < np; ++i) {
        // Eq. 18: particles better than average keep a small weight (local
        // search), the others the largest (move towards better regions).
        const double w = (f[i] <= favg && favg > fmin) ? kWmin + (kWmax - kWmin) * (f[i] - fmin) / (favg - fmin) : kWmax;
        for (int k = 0; k < 3; ++k) {
          v[i][k] = w * v[i][k] + kC1 * U(rng) * (pbest[i][k] - x[i][k]) + kC2 * U(rng) * (t.best_x[k] - x[i][k]);
          v[i][k] = std::clamp(v[i][k], -kVmax, kVmax);
          x[i][k] += v[i][k];
          if (x[i][k] < 0 || x[i][k] > 1) {
            x[i][k] = std::clamp(x[i][k], 0.0, 1.0);
            v[i][k] = -0.5 * v[i][k];
          }
        }
        f[i] = t.Eval(x[i]);
        if (f[i] < pbest_f[i]) pbest_f[i] = f[i], pbest[i] = x[i];
      }
      best = res.best_value;
      res.history.push_back(best);
      if (o.progress) o.progress(it + 1, best);
      if (last_improved - best > o.pso_tolerance) {
        last_improved = best;
        stall = 0;
      } else if (++stall >= o.pso_stall_iterations) {
        res.status = "converged";
        break;
      }
    }
  }
  res.best = FromUnit(t.best_x, start, o);
  return res;
}

}  // namespace robomach::polishing
