// Issue #36: the validators of the polishing options structs. The defaults
// pass; a bad value of each checked field throws OptionError whose field()
// is the field and whose what() names the value and the bound.
#include <cmath>
#include <functional>
#include <sstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "options_validate_support.h"
#include "robomach/common/errors.h"
#include "robomach/polishing/face_check.h"
#include "robomach/polishing/optimise.h"
#include "robomach/polishing/plan_workflow.h"

namespace robomach::polishing {
namespace {

using ::testing::HasSubstr;

using robomach::testing::ExpectOptionError;

TEST(PolishingOptionsValidate, DefaultsPass) {
  EXPECT_NO_THROW(PolishableOptions{}.Validate());
  EXPECT_NO_THROW(OptimiseOptions{}.Validate());
  EXPECT_NO_THROW(PlanOptimiseOptions{}.Validate());
  EXPECT_NO_THROW(PlanOptions{}.Validate());
}

TEST(PolishingOptionsValidate, PolishableOptionsNameTheField) {
  const auto bad = [](double PolishableOptions::*field, double value) {
    PolishableOptions o;
    o.*field = value;
    return o;
  };
  ExpectOptionError([&] { bad(&PolishableOptions::sample_spacing, 0.0).Validate(); }, "sample_spacing",
                    "sample_spacing: expected a value > 0, got 0");
  ExpectOptionError([&] { bad(&PolishableOptions::sample_spacing, NAN).Validate(); }, "sample_spacing", "got nan");
  ExpectOptionError([&] { bad(&PolishableOptions::sample_spacing, INFINITY).Validate(); }, "sample_spacing",
                    "sample_spacing: expected a finite value, got inf");
  ExpectOptionError([&] { bad(&PolishableOptions::max_grid_points, 0.0).Validate(); }, "max_grid_points",
                    "max_grid_points: expected a value >= 1, got 0");
  ExpectOptionError([&] { bad(&PolishableOptions::max_path_rows, -5.0).Validate(); }, "max_path_rows",
                    "max_path_rows: expected a value >= 1, got -5");
  ExpectOptionError([&] { bad(&PolishableOptions::check_grid_points, 0.5).Validate(); }, "check_grid_points",
                    "check_grid_points: expected a value >= 1, got 0.5");
}

TEST(PolishingOptionsValidate, OptimiseOptionsNameTheField) {
  OptimiseOptions o;
  o.offset_min = 0.0;
  ExpectOptionError([&] { o.Validate(); }, "offset_min", "offset_min: expected a value > 0, got 0");
  o = {};
  o.offset_max = o.offset_min;
  ExpectOptionError([&] { o.Validate(); }, "offset_max",
                    "offset_max: expected a value > offset_min 0.004, got 0.004");
  o = {};
  o.offset_max = INFINITY;  // an open band is for Hz, not for offsets
  ExpectOptionError([&] { o.Validate(); }, "offset_max", "offset_max: expected a finite value, got inf");
  o = {};
  o.global_evaluations = 0;
  ExpectOptionError([&] { o.Validate(); }, "global_evaluations", "global_evaluations: expected a value >= 1, got 0");
  o = {};
  o.local_evaluations = -1;
  ExpectOptionError([&] { o.Validate(); }, "local_evaluations", "local_evaluations: expected a value >= 1, got -1");
  o = {};
  o.pso_particles = 0;
  ExpectOptionError([&] { o.Validate(); }, "pso_particles", "pso_particles: expected a value >= 1, got 0");
  o = {};
  o.pso_max_iterations = -1;
  ExpectOptionError([&] { o.Validate(); }, "pso_max_iterations", "pso_max_iterations: expected a value >= 0, got -1");
  o = {};
  o.pso_stall_iterations = 0;
  ExpectOptionError([&] { o.Validate(); }, "pso_stall_iterations", "pso_stall_iterations: expected a value >= 1, got 0");
  o = {};
  o.pso_tolerance = -1e-3;
  ExpectOptionError([&] { o.Validate(); }, "pso_tolerance", "pso_tolerance: expected a value >= 0, got -0.001");
  // OptimiseCycloid checks them at its entry, before any evaluation.
  o = {};
  o.pso_particles = 0;
  int evaluations = 0;
  ExpectOptionError([&] {
    OptimiseCycloid([&](const PathParameters&) { return double(++evaluations); }, PathParameters{}, o);
  }, "pso_particles", "got 0");
  EXPECT_EQ(evaluations, 0);
}

TEST(PolishingOptionsValidate, PlanOptimiseOptionsNameTheField) {
  PlanOptimiseOptions o;
  o.offset_min = -0.004;
  ExpectOptionError([&] { o.Validate(); }, "offset_min", "offset_min: expected a value > 0, got -0.004");
  o = {};
  o.offset_max = 0.001;
  ExpectOptionError([&] { o.Validate(); }, "offset_max", "offset_max: expected a value > offset_min 0.004, got 0.001");
  o = {};
  o.offset_max = INFINITY;
  ExpectOptionError([&] { o.Validate(); }, "offset_max", "offset_max: expected a finite value, got inf");
  o = {};
  o.feasibility_margin = 0.0;
  ExpectOptionError([&] { o.Validate(); }, "feasibility_margin",
                    "feasibility_margin: expected a value > 0, got 0");
  o.feasibility_margin = 1.2;
  ExpectOptionError([&] { o.Validate(); }, "feasibility_margin",
                    "feasibility_margin: expected a value in [0, 1], got 1.2");
  o = {};
  o.ftol_rel = -0.1;
  ExpectOptionError([&] { o.Validate(); }, "ftol_rel", "ftol_rel: expected a value in [0, 1], got -0.1");
  o = {};
  o.max_local_evaluations = 0;
  ExpectOptionError([&] { o.Validate(); }, "max_local_evaluations", "max_local_evaluations: expected a value >= 1, got 0");
  o = {};
  o.max_time_s = NAN;
  ExpectOptionError([&] { o.Validate(); }, "max_time_s", "max_time_s: expected a value >= 0, got nan");
}

TEST(PolishingOptionsValidate, PlanOptionsNameTheField) {
  PlanOptions o;
  o.guides = "lines";
  ExpectOptionError([&] { o.Validate(); }, "guides", "guides 'lines': expected offsets or parallel");
  o = {};
  o.optimise = "cobyla";
  ExpectOptionError([&] { o.Validate(); }, "optimise", "optimise: expected none, nlopt or pso, got cobyla");
  o = {};
  o.pattern = "spiral";
  ExpectOptionError([&] { o.Validate(); }, "pattern", "unknown path pattern 'spiral': expected cycloid or parallel");
  o = {};
  o.pattern = "parallel";
  o.optimise = "pso";
  ExpectOptionError([&] { o.Validate(); }, "optimise", "optimise pso applies to the cycloid");
  o.optimise = "nlopt";
  EXPECT_NO_THROW(o.Validate());
  // Every range of PlanOptionRanges, just below its lower bound.
  for (const PlanOptionRange& r : PlanOptionRanges(PlanOptions{})) {
    PlanOptions bad;
    const double v = r.lo - 1.0;
    if (r.name == "sample_mm") bad.sample_mm = v;
    else if (r.name == "row_step_mm") bad.row_step_mm = v;
    else if (r.name == "opt_sample_mm") bad.opt_sample_mm = v;
    else if (r.name == "target_removal_um") bad.target_removal_um = v;
    else if (r.name == "offset_mm") bad.offset_mm = v;
    else if (r.name == "radius_mm") bad.radius_mm = v;
    else if (r.name == "pitch_mm") bad.pitch_mm = v;
    else if (r.name == "opt_offset_max_mm") bad.opt_offset_max_mm = v;
    else if (r.name == "opt_offset_min_contact_widths") bad.opt_offset_min_contact_widths = v;
    else if (r.name == "stagger_loops") bad.stagger_loops = v;
    else if (r.name == "edge_overrun_mm") bad.edge_overrun_mm = v;
    else if (r.name == "line_angle_deg") bad.line_angle_deg = v;
    else if (r.name == "max_time_s") bad.max_time_s = v;
    else if (r.name == "threads") bad.threads = static_cast<int>(v);
    else ADD_FAILURE() << "a range this test does not know: " << r.name;
    std::ostringstream words;
    words << r.name << ": expected a value in [" << r.lo << ", " << r.hi << "], got " << v;
    ExpectOptionError([&] { bad.Validate(); }, r.name, words.str());
  }
}

}  // namespace
}  // namespace robomach::polishing
