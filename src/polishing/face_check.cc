#include "robomach/polishing/face_check.h"

#include "robomach/common/errors.h"
#include "robomach/common/option_validate.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "robomach/polishing/face_trim.h"

namespace robomach::polishing {
namespace {

constexpr double kClearance = 50e-6;  // as paths.cc's CycloidInset: chords of the outline and of the offsets

std::string Mm(double x_m) {
  std::ostringstream o;
  o.precision(3);
  o << 1e3 * x_m;
  return o.str();
}

std::string SizeText(double length_s, double length_t) { return Mm(length_s) + " x " + Mm(length_t) + " mm"; }

// Diameter of the region's inscribed circle [m]: exact for a rectangle.
double RegionWidth(const DevelopedRegion& region) {
  if (region.loops().empty()) return 0.0;
  if (region.rectangle()) {
    const Eigen::Vector4d b = region.Bounds();
    return std::min(b(2) - b(0), b(3) - b(1));
  }
  return 2.0 * region.Inradius();
}

}  // namespace

void CheckCircleFits(const NurbsSurface& surface, const SampleGrid& grid, const DevelopedRegion& region,
                     const PathParameters& params, const PolishingProcess& process) {
  if (params.pattern != Pattern::kCycloid || region.loops().empty()) return;
  const double need = std::max(0.0, params.radius - process.margin);  // centre this far inside the region
  double width = 0.0;
  if (region.rectangle()) {
    width = RegionWidth(region);
    if (width / 2 >= need - 1e-12) return;
  } else {
    if (need <= 0 || !region.Offset(need + kClearance).empty()) return;
    width = RegionWidth(region);
  }
  const double clearance = region.rectangle() ? 0.0 : kClearance;
  std::ostringstream m;
  m << "face too narrow for the circle (radius_mm " << Mm(params.radius) << ": the cycloid does not fit): "
    << SurfaceName(surface) << " (" << SizeText(grid.length_s(), grid.length_t()) << ") is " << Mm(width)
    << " mm wide where widest after process.margin_mm " << Mm(process.margin) << "; the circle's centre must stay "
    << Mm(need + clearance) << " mm (radius - margin) inside that region, or rows would leave the face or be clamped "
    << "onto its edges; use --radius-mm <= " << Mm(std::max(0.0, process.margin + width / 2 - clearance))
    << " or --pattern parallel";
  throw FaceTooNarrowError(m.str());
}

double EstimatePathRows(double area, const PathParameters& params) {
  const double factor = params.pattern == Pattern::kCycloid ? std::max(1.0, 2 * M_PI * params.radius / params.pitch) : 1.0;
  return area / params.offset * factor / params.row_step;
}

void PolishableOptions::Validate() const {
  CheckOptionAbove("sample_spacing", sample_spacing, 0.0);
  CheckOptionFinite("sample_spacing", sample_spacing);
  CheckOptionAtLeast("max_grid_points", max_grid_points, 1);
  CheckOptionAtLeast("max_path_rows", max_path_rows, 1);
  CheckOptionAtLeast("check_grid_points", check_grid_points, 1);
}

Polishability CheckPolishable(const NurbsSurface& surface, const PolishingProcess& process,
                              const PathParameters& params, const PolishableOptions& options) {
  options.Validate();
  Polishability p;
  const std::string name = SurfaceName(surface);
  try {
    const SurfaceSize size = MeasureSurface(surface);
    const std::string size_text = SizeText(size.length_u, size.length_v);
    p.grid_points = EstimateGridPoints(size, options.sample_spacing);
    if (!(p.grid_points <= options.max_grid_points)) {
      std::ostringstream m;
      m.precision(3);
      m << name << " (" << size_text << ") is too large: sampling it at " << Mm(options.sample_spacing) << " mm needs "
        << p.grid_points << " points (~" << p.grid_points * 90e-9 << " GB), above the limit of " << options.max_grid_points;
      p.reason = m.str();
      return p;
    }
    // The region on a grid of at most check_grid_points points.
    const double coarse = std::max(options.sample_spacing,
                                   std::sqrt(std::max(size.max_u, 1e-9) * std::max(size.max_v, 1e-9) / options.check_grid_points));
    const SampleGrid grid = SampleGrid::Build(surface, coarse, process.margin, process.flip_normal);
    if (grid.num_in_region() == 0) {
      p.reason = name + " (" + size_text + "): process.margin_mm " + Mm(process.margin) + " leaves no polished region";
      return p;
    }
    const DevelopedRegion region = DevelopedRegion::Build(surface, grid, process.margin);
    if (region.loops().empty()) {
      p.reason = name + " (" + size_text + "): process.margin_mm " + Mm(process.margin) + " leaves no polished region";
      return p;
    }
    p.region_width = RegionWidth(region);
    try {
      p.contact_width = ContactWidthAtCentre(surface, grid, process);
    } catch (const std::domain_error& e) {
      p.reason = name + " (" + size_text + "): at the centre of the region: " + e.what();
      return p;
    }
    CheckCircleFits(surface, grid, region, params, process);
    const double area = surface.trim() ? surface.trim()->area : size.length_u * size.length_v;
    const double rows = EstimatePathRows(area, params);
    if (rows > options.max_path_rows) {
      std::ostringstream m;
      m.precision(3);
      m << name << " (" << size_text << ", " << area * 1e6 << " mm^2) is too large: its path would have ~" << rows
        << " rows (offset " << Mm(params.offset) << " mm, row step " << Mm(params.row_step) << " mm), above the limit of "
        << options.max_path_rows;
      p.reason = m.str();
      return p;
    }
    p.polishable = true;
  } catch (const std::invalid_argument& e) {  // FaceTooNarrowError, a size that is not finite
    p.reason = e.what();
  } catch (const std::domain_error& e) {  // a degenerate point (no normal, no tangent plane)
    p.reason = e.what();
  } catch (const NumericalError& e) {
    p.reason = e.what();
  }
  // Anything else (a bug, memory) propagates: it says nothing about the face.
  return p;
}

PlanSize EstimatePlanSize(const NurbsSurface& surface, double sample_spacing, const PathParameters& params,
                          const PolishableOptions& limits) {
  limits.Validate();
  PlanSize out;
  const SurfaceSize size = MeasureSurface(surface);
  out.grid_points = EstimateGridPoints(size, sample_spacing);
  const double area = surface.trim() ? surface.trim()->area : size.length_u * size.length_v;
  out.path_rows = EstimatePathRows(area, params);
  std::ostringstream m;
  m.precision(3);
  m << SurfaceName(surface) << " (" << 1e3 * size.length_u << " x " << 1e3 * size.length_v
    << " mm, mean arc lengths along u and v; " << 1e6 * area << " mm^2)";
  out.what = m.str();
  m.str("");
  m << out.grid_points << " grid points at --sample-mm " << 1e3 * sample_spacing << " (~" << out.grid_points * 90e-9
    << " GB) and a path of ~" << out.path_rows << " rows";
  out.estimate = m.str();
  out.too_large = !(out.grid_points <= limits.max_grid_points) || !(out.path_rows <= limits.max_path_rows);
  out.large = out.grid_points > 2e5 || out.path_rows > 1e5;
  if (out.too_large) {
    m.str("");
    m << out.what << " is too large to plan within the limits (" << limits.max_grid_points << " grid points, "
      << limits.max_path_rows << " path rows; about a minute and 2 GB): " << out.estimate;
    out.too_large_message = m.str();
  }
  return out;
}

}  // namespace robomach::polishing
