#pragma once

// One-dimensional maximisation by golden-section search [Press et al.,
// Numerical Recipes, 3rd ed., §10.2], shared by the peak searches of the
// modal fit and the calibration and by the audit's start-value scan.

#include <algorithm>
#include <cmath>
#include <utility>

namespace robomach {

/// Maximum of `f`, assumed unimodal on [a, b]: the bracket shrinks by
/// 0.618 per evaluation until it is shorter than rel_tol · max(1, |b|) or
/// after max_iterations. Returns {x, f(x)} at the final bracket's midpoint.
template <typename F>
std::pair<double, double> GoldenSectionMaximum(const F& f, double a, double b, int max_iterations,
                                               double rel_tol) {
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double c = b - g * (b - a), d = a + g * (b - a);
  double fc = f(c), fd = f(d);
  for (int it = 0; it < max_iterations && (b - a) > rel_tol * std::max(1.0, std::abs(b)); ++it) {
    if (fc > fd) {
      b = d;
      d = c;
      fd = fc;
      c = b - g * (b - a);
      fc = f(c);
    } else {
      a = c;
      c = d;
      fc = fd;
      d = a + g * (b - a);
      fd = f(d);
    }
  }
  const double xm = 0.5 * (a + b);
  return {xm, f(xm)};
}

/// Maximum of `f` on [lo, hi] when it may have several local maxima: the
/// best of grid + 1 equally spaced points, refined by golden section within
/// one grid cell on each side. Returns {x, f(x)}, the better of the grid
/// point and the refined point.
template <typename F>
std::pair<double, double> MaximiseOnGrid(const F& f, double lo, double hi, int grid, int max_iterations,
                                         double rel_tol) {
  double best_x = lo, best = -INFINITY;
  for (int i = 0; i <= grid; ++i) {
    const double x = lo + (hi - lo) * i / grid;
    const double v = f(x);
    if (v > best) {
      best = v;
      best_x = x;
    }
  }
  const double step = (hi - lo) / grid;
  const auto refined =
      GoldenSectionMaximum(f, std::max(lo, best_x - step), std::min(hi, best_x + step), max_iterations, rel_tol);
  return refined.second >= best ? refined : std::pair{best_x, best};
}

}  // namespace robomach
