// Example: a belt-polishing plan on a curved face.
//
// A contact wheel pressed on a surface removes material by Preston's law
// (removal rate = k_p × pressure × relative speed) under a Hertzian contact
// ellipse. A path polishes evenly when the removal it leaves is uniform over
// the face. This example:
//   1. reads a NURBS patch and a belt-grinding process (config/polishing);
//   2. samples the face and computes the contact (PreparePlanning);
//   3. plans a cycloid path and a zig-zag path with the same options, timed
//      to remove 5 µm on average, and simulates the removal of each
//      (PlanPolishing);
//   4. prints what each plan reports: length, time, coverage and uniformity.
//
// Usage: polishing_plan_on_a_face [surface.yaml [process.yaml]]
// (defaults: config/polishing/dome.yaml and config/polishing/belt_2N.yaml
// of the source tree). The polish-plan tool adds STEP/IGES faces, the
// optimisation of the path's spacing and the files (docs/polishing.md).
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "robomach/common/units.h"
#include "robomach/io/polishing_files.h"
#include "robomach/polishing/plan_workflow.h"

namespace rm = robomach;

int main(int argc, char** argv) try {
  const std::string surface_path = argc > 1 ? argv[1] : ROBOMACH_SOURCE_DIR "/config/polishing/dome.yaml";
  const std::string process_path = argc > 2 ? argv[2] : ROBOMACH_SOURCE_DIR "/config/polishing/belt_2N.yaml";

  // 1. The face (control points in mm in the file, metres here) and the
  // process: wheel, belt, pad and workpiece, force, margin, speed limit.
  const rm::polishing::NurbsSurface surface = rm::io::ReadNurbsYaml(surface_path);
  std::vector<std::string> implausible;  // values that look like unit mistakes
  const rm::polishing::PolishingProcess process = rm::io::ReadPolishingProcess(process_path, &implausible);
  for (const std::string& w : implausible) std::printf("warning: %s\n", w.c_str());

  // 2. The region to polish (the face inside the process's margin), sampled
  // every 0.5 mm of arc length, and the contact ellipse at its centre. The
  // context is shared by every plan below; the paths refer to the surface.
  const rm::polishing::PlanningContext context =
      rm::polishing::PreparePlanning(surface, process, rm::MmToM(0.5), surface_path, process_path);
  std::printf("region: %.0f mm^2, %d sample points; contact %.2f mm wide across the path\n",
              1e6 * context.grid->region_area(), context.grid->size(), 1e3 * context.contact_width);

  // 3. Plans. PlanOptions holds polish-plan's options with the units of its
  // command line and its defaults (cycloid of 6 mm radius, 3 mm pitch, on
  // guide lines 8 mm apart offset from the boundary); ToPlanRequest checks
  // them against the face and turns them into SI path parameters.
  // At these defaults the cycloid's overlapping loops leave a removal about
  // twice as even (cv, the coefficient of variation) as the zig-zag's rows;
  // options.optimise = "nlopt" searches the spacing that makes either most
  // even (up to options.max_time_s, 50 s by default; polish-plan --optimise).
  for (const char* pattern : {"cycloid", "parallel"}) {
    rm::polishing::PlanOptions options;
    options.pattern = pattern;         // "parallel" is the zig-zag, rows one contact width apart
    options.target_removal_um = 5.0;   // time the path for 5 µm mean removal
    const rm::polishing::PlanRequest request = rm::polishing::ToPlanRequest(options, context);
    const rm::polishing::PlanOutcome outcome = rm::polishing::PlanPolishing(context, request);

    // 4. What the plan reports. The path is a list of rows (time, contact
    // point, tool axes); the removal is simulated at every grid point.
    const rm::polishing::EvaluatedPlan& plan = outcome.plan;
    const rm::polishing::RemovalStats& s = plan.stats;
    const double time_s = plan.path.rows.back().t;
    std::printf("%s: %zu path rows, length %.2f m, %.0f s (mean speed along the path %.1f mm/s)\n", pattern,
                plan.path.rows.size(), plan.path.length, time_s, 1e3 * plan.path.length / time_s);
    std::printf("  removal: mean %.2f um, min %.2f um, max %.2f um, cv %.3f, coverage %.3f\n", 1e6 * s.mean,
                1e6 * s.min, 1e6 * s.max, s.cv, s.coverage);
    // A plan that ran but is doubtful is flagged, one finding each (the tool
    // prints them as warnings and exits 3): a target the speed limit does
    // not allow, rows off a trimmed face, a zig-zag that would do better.
    for (const rm::Finding& f : outcome.verdict.findings) std::printf("  finding: %s\n", f.message.c_str());
    const std::string unpolished = rm::polishing::DescribeUnpolished(s, context.grid->region_area());
    if (!unpolished.empty()) std::printf("  %s\n", unpolished.c_str());
  }
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "polishing_plan_on_a_face: %s\n", e.what());
  return 1;
}
