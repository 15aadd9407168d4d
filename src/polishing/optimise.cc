#include "robomach/polishing/optimise.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdio>
#include <chrono>
#include <mutex>
#include <random>

#include <nlopt.hpp>

#include "robomach/common/golden_section.h"
#include "robomach/common/enum_names.h"
#include "robomach/common/number_format.h"
#include "robomach/common/option_checks.h"
#include "robomach/common/option_validate.h"
#include "robomach/common/parallel.h"
#include "robomach/common/units.h"
#include "robomach/polishing/process.h"
#include "robomach/polishing/removal.h"

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
  // An exception from the objective. NLopt's C++ wrapper would turn it into
  // a generic failure ("nlopt failure"), so NloptThunk keeps it and stops
  // the run, and RunNlopt rethrows it: an objective that throws is a bug or
  // bad input, not an optimiser status.
  std::exception_ptr error;
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
  double v = 0.0;
  try {
    v = t->Eval(std::vector<double>(x, x + 3));
  } catch (...) {
    t->error = std::current_exception();
    throw nlopt::forced_stop();
  }
  t->res->history.push_back(t->res->best_value);
  if (t->o->progress) t->o->progress(t->res->evaluations, t->res->best_value);
  return v;
}

// Sets the result's status and stop reason (NLopt's word).
void RunNlopt(nlopt::algorithm alg, int budget, std::vector<double>* x, Tracker* t, OptimiseResult* res) {
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
    const bool budget_out = r == nlopt::MAXEVAL_REACHED;
    res->status = budget_out ? SolverStatus::kNotConverged : SolverStatus::kConverged;
    res->stop_reason = budget_out ? "max_evaluations" : "converged";
  } catch (const nlopt::roundoff_limited&) {
    // At the objective's noise level (OptimisePlan's local searches take it
    // as converged too).
    res->status = SolverStatus::kConverged;
    res->stop_reason = "roundoff_limited";
  } catch (const nlopt::forced_stop&) {
    if (t->error) std::rethrow_exception(t->error);
    res->status = SolverStatus::kFailed;
    res->stop_reason = "forced_stop";
  } catch (const std::runtime_error& e) {
    // NLopt's own failure (NLOPT_FAILURE); the objective's exceptions are
    // rethrown above.
    res->status = SolverStatus::kFailed;
    res->stop_reason = std::string("failed: ") + e.what();
  }
}

}  // namespace

std::string ToString(Optimiser o) { return o == Optimiser::kNlopt ? "nlopt" : "pso"; }

Optimiser ParseOptimiser(const std::string& name) {
  return ParseByName("optimiser", name, kOptimisers);
}

void OptimiseOptions::Validate() const {
  CheckOptionAbove("offset_min", offset_min, 0.0);
  CheckOptionBand("offset_min", offset_min, "offset_max", offset_max);
  CheckOptionFinite("offset_max", offset_max);  // the band helper lets +inf through (open Hz bands)
  CheckOptionAtLeast("global_evaluations", global_evaluations, 1);
  CheckOptionAtLeast("local_evaluations", local_evaluations, 1);
  CheckOptionAtLeast("pso_particles", pso_particles, 1);
  CheckOptionAtLeast("pso_max_iterations", pso_max_iterations, 0);
  CheckOptionAtLeast("pso_stall_iterations", pso_stall_iterations, 1);
  CheckOptionAtLeast("pso_tolerance", pso_tolerance, 0.0);
}

OptimiseResult OptimiseCycloid(const std::function<double(const PathParameters&)>& objective,
                               const PathParameters& start, const OptimiseOptions& o) {
  o.Validate();
  OptimiseResult res;
  Tracker t{&objective, &start, &o, &res, {}, {}};
  if (o.method == Optimiser::kNlopt) {
    res.method = "NLopt GN_DIRECT_L (" + std::to_string(o.global_evaluations) + " evaluations) then LN_SBPLX (" +
                 std::to_string(o.local_evaluations) + ")";
    std::vector<double> x = ToUnit(start, o);
    // The status is the local stage's (the global stage always spends its budget).
    RunNlopt(nlopt::GN_DIRECT_L, o.global_evaluations, &x, &t, &res);
    x = t.best_x;
    RunNlopt(nlopt::LN_SBPLX, o.local_evaluations, &x, &t, &res);
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
    res.status = SolverStatus::kNotConverged;
    res.stop_reason = "max_iterations";
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
        res.status = SolverStatus::kConverged;
        res.stop_reason = "converged";
        break;
      }
    }
  }
  res.best = FromUnit(t.best_x, start, o);
  return res;
}


// ---------------------------------------------------------------------------
// OptimisePlan

PlanEvaluation EvaluatePlan(const PlanProblem& pb, const PathParameters& p, double margin) {
  PlanEvaluation e;
  e.params = p;
  try {
    const PlannedPath path = PlanPath(*pb.surface, *pb.grid, p, *pb.process);
    const RemovalStats st = ComputeRemovalStats(pb.sim->Simulate(path.rows), pb.grid->areas(), pb.grid->in_region());
    e.valid = std::isfinite(st.cv) && st.mean > 0;
    if (!e.valid) e.error = "the path removes nothing in the region";
    e.cv = st.cv;
    e.mean = st.mean;
    e.coverage = st.coverage;
    e.feasible = e.valid && (pb.target <= 0 || st.mean <= margin * pb.target) && st.coverage >= kMinCoverage;
  } catch (const std::invalid_argument& err) {
    e.valid = false;
    e.error = err.what();
  }
  return e;
}

std::string FamilyName(const GuideFamily& f) {
  if (f.guides == GuideLines::kBoundaryOffsets) return ToString(GuideLines::kBoundaryOffsets);
  const double deg = f.line_angle * 180.0 / kPi;
  if (std::abs(deg) < 1e-9) return "parallel lines along s";
  if (std::abs(deg - 90.0) < 1e-9) return "parallel lines along t";
  return "parallel lines at " + std::to_string(deg) + " deg";
}

namespace {

using Clock = std::chrono::steady_clock;

std::string io_ftol(double x) { return FormatNumber(x, 6); }

// Ranks evaluations: feasible before infeasible; feasible by cv; infeasible
// by how far they miss the target (mean), invalid last.
bool Better(const PlanEvaluation& a, const PlanEvaluation& b) {
  if (a.feasible != b.feasible) return a.feasible;
  if (a.feasible) return a.cv < b.cv;
  if (a.valid != b.valid) return a.valid;
  const bool ca = a.coverage >= kMinCoverage, cb = b.coverage >= kMinCoverage;
  if (ca != cb) return ca;
  return a.mean < b.mean;
}

// Shared state of one OptimisePlan run: the evaluation log, the history and
// the progress callback, behind one mutex.
class Book {
 public:
  Book(const PlanProblem& pb, const PlanOptimiseOptions& o) : pb_(pb), o_(o), t0_(Clock::now()) {}
  double Elapsed() const { return std::chrono::duration<double>(Clock::now() - t0_).count(); }
  double Remaining() const { return o_.max_time_s - Elapsed(); }
  bool OutOfTime() const { return Remaining() <= 0; }

  PlanEvaluation Evaluate(const PathParameters& p) {
    PlanEvaluation e = EvaluatePlan(pb_, p, o_.feasibility_margin);
    std::lock_guard<std::mutex> lock(mu_);
    ++res_.evaluations;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    res_.cv_history.push_back(e.feasible ? e.cv : nan);
    res_.history_parallel.push_back(p.pattern == Pattern::kParallel);
    if (e.feasible && (!std::isfinite(best_cv_) || e.cv < best_cv_)) best_cv_ = e.cv;
    res_.best_history.push_back(std::isfinite(best_cv_) ? best_cv_ : nan);
    if (o_.progress) o_.progress(res_.evaluations, best_cv_, Elapsed());
    return e;
  }
  // Evaluates all of `ps` on the threads (stops starting new ones when out of time).
  std::vector<PlanEvaluation> Batch(const std::vector<PathParameters>& ps) {
    std::vector<PlanEvaluation> out(ps.size());
    std::vector<char> done(ps.size(), 0);
    RunParallel(static_cast<int>(ps.size()), [&](int i) {
      if (OutOfTime()) return;
      out[i] = Evaluate(ps[i]);
      done[i] = 1;
    });
    std::vector<PlanEvaluation> kept;
    for (size_t i = 0; i < ps.size(); ++i)
      if (done[i]) kept.push_back(out[i]);
    return kept;
  }
  // Runs job(0..n-1) on o.threads threads; the first exception is rethrown.
  void RunParallel(int n, const std::function<void(int)>& job) {
    ParallelForOptions po;
    po.threads = std::max(1, o_.threads);
    po.chunk_size = 1;  // one plan evaluation each (milliseconds to seconds)
    ParallelFor(0, n, [&](long i, int) { job(static_cast<int>(i)); }, po);
  }
  PlanOptimiseResult& result() { return res_; }
  std::mutex& mutex() { return mu_; }

 private:
  const PlanProblem& pb_;
  const PlanOptimiseOptions& o_;
  Clock::time_point t0_;
  std::mutex mu_;
  PlanOptimiseResult res_;
  double best_cv_{std::numeric_limits<double>::quiet_NaN()};
};

constexpr int kDim = 5;  // d, r/d, pitch/r, stagger, edge overrun / its largest value

PathParameters CycloidFromUnit(const double* x, const PathParameters& base, const GuideFamily& fam,
                               const PlanOptimiseOptions& o, const PolishingProcess& process) {
  PathParameters p = base;
  p.pattern = Pattern::kCycloid;
  p.guides = fam.guides;
  p.line_angle = fam.line_angle;
  // d on a log scale: the good spacings are a few contact widths or less,
  // and a step in d matters relative to d.
  p.offset = o.offset_min * std::pow(o.offset_max / o.offset_min, std::clamp(x[0], 0.0, 1.0));
  p.radius = p.offset * (kRatioMin + std::clamp(x[1], 0.0, 1.0) * (kRatioMax - kRatioMin));
  p.pitch = p.radius * (kPitchMin + std::clamp(x[2], 0.0, 1.0) * (kPitchMax - kPitchMin));
  p.stagger = std::clamp(x[3], 0.0, 1.0);
  p.edge_overrun = std::clamp(x[4], 0.0, 1.0) * MaxEdgeOverrun(p, process);
  return p;
}

// One local search (COBYLA, the target as an inequality constraint).
struct LocalRun {
  Book* book;
  const PathParameters* base;
  GuideFamily fam;
  const PlanOptimiseOptions* o;
  const PlanProblem* pb;
  // The last evaluation (NLopt asks for the objective and the constraint
  // at the same x one after the other).
  std::vector<double> last_x;
  PlanEvaluation last;
  PlanEvaluation best;
  bool have_best{false};

  const PlanEvaluation& At(const double* x) {
    if (last_x.size() == kDim && std::equal(last_x.begin(), last_x.end(), x)) return last;
    last_x.assign(x, x + kDim);
    last = book->Evaluate(CycloidFromUnit(x, *base, fam, *o, *pb->process));
    if (!have_best || Better(last, best)) best = last, have_best = true;
    return last;
  }
  static double Objective(unsigned, const double* x, double*, void* data) {
    const PlanEvaluation& e = static_cast<LocalRun*>(data)->At(x);
    return e.valid ? e.cv : 10.0;  // invalid: far worse than any cv
  }
  static double Constraint(unsigned, const double* x, double*, void* data) {
    LocalRun* r = static_cast<LocalRun*>(data);
    const PlanEvaluation& e = r->At(x);
    if (r->pb->target <= 0) return -1.0;
    if (!e.valid) return 1.0;
    return e.mean / (r->o->feasibility_margin * r->pb->target) - 1.0;
  }
  static double CoverageConstraint(unsigned, const double* x, double*, void* data) {
    const PlanEvaluation& e = static_cast<LocalRun*>(data)->At(x);
    return e.valid ? kMinCoverage - e.coverage : 1.0;
  }
};

std::vector<double> CycloidToUnit(const PathParameters& p, const PlanOptimiseOptions& o, const PolishingProcess& process) {
  const double max_over = MaxEdgeOverrun(p, process);
  return {std::clamp(std::log(p.offset / o.offset_min) / std::log(o.offset_max / o.offset_min), 0.0, 1.0),
          std::clamp((p.radius / p.offset - kRatioMin) / (kRatioMax - kRatioMin), 0.0, 1.0),
          std::clamp((p.pitch / p.radius - kPitchMin) / (kPitchMax - kPitchMin), 0.0, 1.0),
          std::clamp(p.stagger, 0.0, 1.0),
          max_over > 0 ? std::clamp(p.edge_overrun / max_over, 0.0, 1.0) : 0.0};
}

bool SameFamily(const PathParameters& p, const GuideFamily& f) {
  return p.guides == f.guides && (f.guides == GuideLines::kBoundaryOffsets || std::abs(p.line_angle - f.line_angle) < 1e-9);
}

// The zig-zag: spacing scan and golden-section refinement, both directions.
PlanEvaluation OptimiseParallel(const PlanProblem& pb, const PathParameters& start, Book* book) {
  PathParameters base = start;
  base.pattern = Pattern::kParallel;
  const double w = pb.contact_width;
  std::vector<PathParameters> scan;
  for (double angle : {0.0, kPi / 2}) {
    for (double over : {0.0, 0.5, 1.0}) {
      for (int k = 0; k < 13; ++k) {
        PathParameters p = base;
        p.line_angle = angle;
        p.offset = (0.3 + 0.1 * k) * w;
        p.edge_overrun = over * pb.process->margin;
        scan.push_back(p);
      }
    }
  }
  std::vector<PlanEvaluation> ev = book->Batch(scan);
  PlanEvaluation best;
  bool have = false;
  for (const auto& e : ev)
    if (!have || Better(e, best)) best = e, have = true;
  if (!have) return best;
  // Refine around the best scan point of each direction that is feasible
  // (the cv is not unimodal over the whole range: rows resonate with the
  // contact's width).
  std::vector<double> angles = {0.0, kPi / 2};
  std::vector<PlanEvaluation> seeds(2);
  std::vector<bool> has(2, false);
  for (const auto& e : ev) {
    const int a = e.params.line_angle > 0 ? 1 : 0;
    if (!has[a] || Better(e, seeds[a])) seeds[a] = e, has[a] = true;
  }
  std::mutex mu;
  book->RunParallel(2, [&](int a) {
    if (!has[a] || !seeds[a].feasible || book->OutOfTime()) return;
    const double w0 = seeds[a].params.offset / w;
    auto f = [&](double wr) {
      PathParameters p = seeds[a].params;
      p.offset = wr * w;
      const PlanEvaluation e = book->Evaluate(p);
      {
        std::lock_guard<std::mutex> lock(mu);
        if (Better(e, best)) best = e;
      }
      return e.feasible ? -e.cv : -10.0 - e.mean / std::max(pb.target, 1e-30);
    };
    GoldenSectionMaximum(f, std::max(0.3, w0 - 0.1), std::min(1.5, w0 + 0.1), 8, 1e-3);
  });
  return best;
}

// What the stages of OptimisePlan share: the problem, its options, the
// user's start and the book of evaluations (which holds the result).
struct PlanRun {
  const PlanProblem& pb;
  const PathParameters& start;
  const PlanOptimiseOptions& o;
  Book& book;
};

// The best evaluation seen so far over every stage (by Better).
struct BestSoFar {
  PlanEvaluation best;
  bool have = false;
  void Consider(const PlanEvaluation& e) {
    if (!have || Better(e, best)) best = e, have = true;
  }
};

// The seed's PSO over (d, r, pitch) on the first family, half-loop stagger,
// the target as a penalty.
void RunPsoPlan(const PlanRun& run, const GuideFamily& family, BestSoFar* best) {
  const PlanProblem& pb = run.pb;
  const PlanOptimiseOptions& o = run.o;
  PlanOptimiseResult& res = run.book.result();
  PathParameters base = run.start;
  base.guides = family.guides;
  base.line_angle = family.line_angle;
  OptimiseOptions po;
  po.method = Optimiser::kPso;
  po.offset_min = o.offset_min;
  po.offset_max = o.offset_max;
  po.seed = o.seed;
  OptimiseResult r = OptimiseCycloid(
      [&](const PathParameters& p) {
        const PlanEvaluation e = run.book.Evaluate(p);
        best->Consider(e);
        if (!e.valid) return 1e6;
        return e.feasible ? e.cv : 10.0 + e.mean / pb.target;
      },
      base, po);
  res.method = r.method + ", the target as a penalty, the best feasible point kept";
  res.status = r.status;
  res.stop_reason = r.stop_reason;
}

// 1. Coarse grid per family at the half-loop stagger, and the user's (or
// default) start point; every point is considered for the best.
std::vector<PlanEvaluation> CoarseGrid(const PlanRun& run, const std::vector<GuideFamily>& fams, BestSoFar* best) {
  const double gd[] = {0.0, 0.2, 0.45}, gr[] = {0.3, 1.0}, gp[] = {0.15, 0.5, 0.85};
  std::vector<PathParameters> grid_pts;
  for (const GuideFamily& f : fams)
    for (double a : gd)
      for (double b : gr)
        for (double c : gp) {
          {
            const double x[kDim] = {a, b, c, 0.5, 1.0};  // rows to the patch's edge
            grid_pts.push_back(CycloidFromUnit(x, run.start, f, run.o, *run.pb.process));
          }
        }
  std::vector<PlanEvaluation> ev = run.book.Batch(grid_pts);
  {
    PlanEvaluation s0 = run.book.Evaluate(run.start);  // the user's (or default) start point
    if (s0.valid) ev.push_back(s0);
  }
  for (const auto& e : ev) best->Consider(e);
  return ev;
}

// 2. Starts: the best of each family, then the next best overall (`ev`
// sorted by Better), most promising first.
std::vector<PlanEvaluation> ChooseStarts(const std::vector<PlanEvaluation>& ev, const std::vector<GuideFamily>& fams,
                                         const PlanOptimiseOptions& o) {
  // A family whose best grid point is far behind the best (cv > 1.5 x,
  // or infeasible when a feasible point exists) gets no local search.
  std::vector<PlanEvaluation> starts;
  for (const GuideFamily& f : fams) {
    for (const auto& e : ev)
      if (e.valid && SameFamily(e.params, f)) {
        const bool close = !ev[0].feasible || (e.feasible && e.cv <= 1.5 * ev[0].cv);
        if (close && static_cast<int>(starts.size()) < std::max(o.starts, 1)) starts.push_back(e);
        break;
      }
  }
  for (const auto& e : ev) {
    if (static_cast<int>(starts.size()) >= std::max<int>(o.starts, 1)) break;
    if (!e.valid) continue;
    bool dup = false;
    for (const auto& s : starts) dup |= s.params.offset == e.params.offset && s.params.radius == e.params.radius &&
                                        s.params.pitch == e.params.pitch && SameFamily(s.params, {e.params.guides, e.params.line_angle});
    if (!dup) starts.push_back(e);
  }
  // Local searches, most promising first.
  std::sort(starts.begin(), starts.end(), Better);
  return starts;
}

// The COBYLA runs of the multi-start search, on the book's threads: how
// many ran, how many met their tolerance and their statuses; each run's
// best is considered and added to `ev` (for the best per family).
class LocalSearches {
 public:
  LocalSearches(const PlanRun& run, BestSoFar* best, std::vector<PlanEvaluation>* ev)
      : run_(run), best_(best), ev_(ev) {}

  // One COBYLA run from `from`; records its status and its best.
  void Run(const PathParameters& from) {
    const PlanProblem& pb = run_.pb;
    const PlanOptimiseOptions& o = run_.o;
    Book& book = run_.book;
    LocalRun run{&book, &run_.start, {from.guides, from.line_angle}, &o, &pb, {}, {}, {}, false};
    nlopt::opt opt(nlopt::LN_COBYLA, kDim);
    opt.set_lower_bounds(std::vector<double>(kDim, 0.0));
    opt.set_upper_bounds(std::vector<double>(kDim, 1.0));
    opt.set_min_objective(LocalRun::Objective, &run);
    opt.add_inequality_constraint(LocalRun::Constraint, &run, 1e-4);
    opt.add_inequality_constraint(LocalRun::CoverageConstraint, &run, 1e-4);
    opt.set_ftol_rel(o.ftol_rel);
    opt.set_xtol_abs(5e-3);  // 5e-3 of the box: ~1 % of d, below what the grid resolves
    opt.set_maxeval(o.max_local_evaluations);
    opt.set_maxtime(std::max(0.1, book.Remaining()));
    opt.set_initial_step(std::vector<double>{0.08, 0.15, 0.1, 0.15, 0.25});
    std::vector<double> x = CycloidToUnit(from, o, *pb.process);
    double f = 0;
    std::string st;
    try {
      const nlopt::result r = opt.optimize(x, f);
      st = r == nlopt::MAXEVAL_REACHED ? "max_evaluations" : r == nlopt::MAXTIME_REACHED ? "max_time" : "converged";
    } catch (const nlopt::roundoff_limited&) {
      st = "converged";  // at the objective's noise level
    } catch (const nlopt::forced_stop&) {
      st = "max_time";
    } catch (const std::invalid_argument&) {
      st = "failed";
    }
    std::lock_guard<std::mutex> lock(mu_);
    ++ran_;
    converged_ += st == "converged";
    statuses_.push_back(st);
    if (run.have_best) {
      best_->Consider(run.best);
      ev_->push_back(run.best);
    }
  }
  // Read once no run is going.
  int ran() const { return ran_; }
  int converged() const { return converged_; }
  const std::vector<std::string>& statuses() const { return statuses_; }

 private:
  const PlanRun& run_;
  BestSoFar* best_;
  std::vector<PlanEvaluation>* ev_;
  std::mutex mu_;
  int converged_ = 0, ran_ = 0;
  std::vector<std::string> statuses_;
};

// 3. Restarts from the best point (COBYLA's simplex shrinks early on a
// sampled objective): a fresh run from it and one a quarter loop of
// stagger away (the stagger's landscape has several valleys), repeated
// while the best improves by more than ftol_rel.
void Restarts(const PlanRun& run, const BestSoFar& best_so_far, LocalSearches* local) {
  Book& book = run.book;
  const PlanEvaluation& best = best_so_far.best;
  for (int round = 0; round < 5 && best_so_far.have && best.feasible && !book.OutOfTime(); ++round) {
    const double before = best.cv;
    const PathParameters b = best.params;
    book.RunParallel(2, [&](int i) {
      if (book.OutOfTime()) return;
      PathParameters from = b;
      if (i == 1) from.stagger = std::fmod(b.stagger + (round % 2 ? 0.75 : 0.25), 1.0);
      local->Run(from);
    });
    if (!(best.cv < before * (1 - run.o.ftol_rel))) break;
  }
}

// The multi-start search: the coarse grid, local searches from the best
// starts, restarts from the best point; then the status, the method and
// the best per family into the book's result.
void RunMultiStartPlan(const PlanRun& run, const std::vector<GuideFamily>& fams, BestSoFar* best) {
  const PlanOptimiseOptions& o = run.o;
  Book& book = run.book;
  PlanOptimiseResult& res = book.result();
  std::vector<PlanEvaluation> ev = CoarseGrid(run, fams, best);
  std::sort(ev.begin(), ev.end(), Better);
  const std::vector<PlanEvaluation> starts = ChooseStarts(ev, fams, o);
  LocalSearches local(run, best, &ev);
  book.RunParallel(static_cast<int>(starts.size()), [&](int i) {
    if (!book.OutOfTime()) local.Run(starts[i].params);
  });
  Restarts(run, *best, &local);
  const int ran = local.ran(), converged = local.converged();
  res.local_searches = ran;
  res.local_converged = converged;
  res.stop_reason = ran == 0 ? "max_time" : converged == ran ? "converged" : "max_time";
  for (const auto& s : local.statuses())
    if (s == "max_evaluations") res.stop_reason = "max_evaluations";
  if (ran < static_cast<int>(starts.size()) || book.OutOfTime()) res.stop_reason = "max_time";
  // A budget ran out unless every local search met its tolerance.
  res.status = res.stop_reason == "converged" ? SolverStatus::kConverged : SolverStatus::kNotConverged;
  res.method = "NLopt: coarse grid over (d, r/d, pitch/r) for each guide family (" + std::to_string(fams.size()) +
               "), then COBYLA from " + std::to_string(starts.size()) +
               " starts over (d, r/d, pitch/r, stagger, edge overrun) with the target as a constraint, then restarts "
               "from the best while it improves; ftol_rel " + io_ftol(o.ftol_rel);
  // Best per family, from the grid and the local searches.
  for (const GuideFamily& f : fams) {
    PlanEvaluation fb;
    bool h = false;
    for (const auto& e : ev)
      if (SameFamily(e.params, f) && (!h || Better(e, fb))) fb = e, h = true;
    if (h) res.family_best.push_back(fb);
  }
}

}  // namespace

void PlanOptimiseOptions::Validate() const {
  CheckOptionAbove("offset_min", offset_min, 0.0);
  CheckOptionBand("offset_min", offset_min, "offset_max", offset_max);
  CheckOptionFinite("offset_max", offset_max);  // the band helper lets +inf through (open Hz bands)
  CheckOptionAbove("feasibility_margin", feasibility_margin, 0.0);
  CheckOptionRange("feasibility_margin", feasibility_margin, 0.0, 1.0);
  CheckOptionRange("ftol_rel", ftol_rel, 0.0, 1.0);
  CheckOptionAtLeast("max_local_evaluations", max_local_evaluations, 1);
  CheckOptionAtLeast("max_time_s", max_time_s, 0.0);
}

PlanOptimiseResult OptimisePlan(const PlanProblem& pb, const PathParameters& start, const PlanOptimiseOptions& o) {
  o.Validate();
  Book book(pb, o);
  PlanOptimiseResult& res = book.result();
  const bool cyc = o.pattern == Pattern::kCycloid;
  if (!cyc || o.compare_parallel) res.best_parallel = OptimiseParallel(pb, start, &book);
  if (!cyc) {
    res.best = res.best_parallel;
    res.method = "zig-zag: row spacing scanned on [0.3, 1.5] contact widths (13 points) x edge overrun (0, 0.5, 1 "
                 "margin) x rows along s and t, then golden-section refinement of the spacing";
    const bool out_of_time = book.OutOfTime();
    res.stop_reason = out_of_time ? "max_time" : "converged";
    res.status = out_of_time ? SolverStatus::kNotConverged : SolverStatus::kConverged;
    res.seconds = book.Elapsed();
    return res;
  }
  std::vector<GuideFamily> fams = o.families;
  if (fams.empty()) fams = {{GuideLines::kBoundaryOffsets, 0.0}, {GuideLines::kParallelLines, 0.0},
                            {GuideLines::kParallelLines, kPi / 2}};
  const PlanRun run{pb, start, o, book};
  BestSoFar best;
  if (o.method == Optimiser::kPso) {
    RunPsoPlan(run, fams[0], &best);
  } else {
    RunMultiStartPlan(run, fams, &best);
  }
  res.best = best.best;
  res.seconds = book.Elapsed();
  return res;
}

}  // namespace robomach::polishing
