#include "robomach/workflows/polish_plan.h"

#include <cmath>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/common/option_checks.h"
#include "robomach/common/units.h"
#include "robomach/io/number_format.h"
#include "robomach/io/polishing_files.h"
#include "robomach/io/polishing_summary.h"
#include "robomach/polishing/face_check.h"
#include "robomach/polishing/path_patterns.h"
#include "robomach/polishing/removal.h"
#include "robomach/workflows/polish_simulation.h"

namespace robomach::workflows {
namespace {

// The pattern, spacing, radius, pitch and row step of `o` as path
// parameters, the spacing at its 8 mm default when not given: what the face
// checks and the size estimate take.
polishing::PathParameters CheckParameters(const PolishPlanOptions& o) {
  polishing::PathParameters p;
  p.pattern = polishing::ParsePattern(o.pattern);
  p.offset = MmToM(o.offset_mm.value_or(8.0));
  p.radius = MmToM(o.radius_mm);
  p.pitch = MmToM(o.pitch_mm);
  p.row_step = MmToM(o.row_step_mm);
  return p;
}

// Refuses a face too large to sample at sample_mm (naming it, its size and
// the estimate), and warns with the estimate before long work. The hint
// names polish-plan's options: the one caller that plans on a face it
// chose (Python's plan_polishing says its own).
void CheckFaceSize(const polishing::NurbsSurface& surface, const PolishPlanOptions& o, const MessageSink& tell) {
  const polishing::PolishableOptions limits;
  const polishing::PlanSize size = polishing::EstimatePlanSize(surface, MmToM(o.sample_mm), CheckParameters(o), limits);
  if (size.too_large) {
    throw InputError({o.surface_path, 0, 0}, size.too_large_message + " (check the file's unit: --cad-unit-scale; or "
                                                                      "choose a smaller face, --list-faces)");
  }
  if (size.large) Tell(tell, Message::Kind::kWarning, size.what + " is large: " + size.estimate + "; planning may take a minute");
}

}  // namespace

void SurfaceChoice::Validate() const {
  if (cad_face < 0) {
    throw OptionError("cad_face", "cad_face " + std::to_string(cad_face) +
                                      ": expected a face number >= 1 (1-based), or 0 for the largest face");
  }
  if (!(cad_unit_scale > 0.0) || !std::isfinite(cad_unit_scale)) {
    throw OptionError("cad_unit_scale", "cad_unit_scale: expected a finite factor > 0 (1000 for a file in metres, "
                                        "25.4 in inches), got " + FormatNumber(cad_unit_scale, 6));
  }
}

polishing::NurbsSurface LoadPolishSurface(const std::string& path, const SurfaceChoice& choice, const MessageSink& tell) {
  choice.Validate();
  if (!io::IsCadFile(path)) {
    if (choice.cad_face_given) {
      throw OptionError("cad_face", "cad_face " + std::to_string(choice.cad_face) + ": " + path +
                                        " is a NURBS YAML (one patch); cad_face picks a face of a STEP/IGES file");
    }
    if (choice.cad_unit_scale != 1.0) {
      throw OptionError("cad_unit_scale", "cad_unit_scale: " + path + " is a NURBS YAML (lengths in mm by "
                                          "docs/formats.md §5); the option applies to STEP/IGES files");
    }
    return io::ReadNurbsYaml(path);
  }
  io::CadReadOptions options;
  options.unit_scale = choice.cad_unit_scale;
  io::CadPartInfo info;
  polishing::NurbsSurface s = io::ReadCadFace(path, choice.cad_face, options, &info);
  if (!info.unit_warning.empty()) Tell(tell, Message::Kind::kWarning, path + ": " + info.unit_warning);
  if (choice.cad_face == 0 && s.trim()) {
    std::ostringstream m;
    m << "--face 0: " << s.trim()->source << ", the largest of " << info.num_faces << " faces by area ("
      << 1e6 * s.trim()->area << " mm^2); --list-faces lists them all";
    Tell(tell, Message::Kind::kNote, m.str());
  }
  return s;
}

void PolishPlanOptions::Validate() const {
  // The planning options' checks are PlanOptions'; the files and the face
  // are checked where they are read.
  polishing::PlanOptions::Validate();
}

std::vector<io::CadFaceRow> ListPolishFaces(const PolishPlanOptions& o, const MessageSink& tell,
                                            const FaceProgress& progress) {
  // Listing needs nothing but the file (issue #35); with a process file
  // each face is also checked against the contact.
  std::optional<polishing::PolishingProcess> process;
  if (!o.process_path.empty()) process = io::ReadPolishingProcess(o.process_path);
  const polishing::PathParameters params = CheckParameters(o);
  polishing::PolishableOptions po;
  po.sample_spacing = MmToM(o.sample_mm);
  io::CadReadOptions options;
  options.unit_scale = o.surface_choice.cad_unit_scale;
  io::CadPartInfo info;
  std::vector<io::CadFaceRow> rows = io::ListCadFaces(
      o.surface_path,
      [&](const polishing::NurbsSurface& s) {
        if (!process) return std::make_pair(true, std::string("contact not checked (give --process)"));
        const polishing::Polishability p = polishing::CheckPolishable(s, *process, params, po);
        return std::make_pair(p.polishable, p.reason);
      },
      options, &info, [&](int done, int total) {
        if (progress) progress("faces", done, total);
      });
  if (!info.unit_warning.empty()) Tell(tell, Message::Kind::kWarning, o.surface_path + ": " + info.unit_warning);
  return rows;
}

nlohmann::json PolishPlanRun::Summary(const PolishPlanOptions& options) const {
  return io::PolishPlanSummaryJson(outcome, context, options, PlanFiguresOf(outcome, context.process));
}

PolishPlanRun RunPolishPlan(const PolishPlanOptions& o, const MessageSink& tell, const PlanProgress& progress) {
  o.Validate();
  auto warn = [&](const std::string& text) { Tell(tell, Message::Kind::kWarning, text); };
  auto note = [&](const std::string& text) { Tell(tell, Message::Kind::kNote, text); };
  PolishPlanRun run;
  run.process = io::ReadPolishingProcess(o.process_path, &run.input_findings);
  for (const std::string& w : polishing::ImplausiblePlanOptions(o)) run.input_findings.push_back(w);
  for (const std::string& w : run.input_findings) warn(w);
  run.surface = std::make_shared<const polishing::NurbsSurface>(LoadPolishSurface(o.surface_path, o.surface_choice, tell));
  CheckFaceSize(*run.surface, o, tell);
  run.context = polishing::PreparePlanning(*run.surface, run.process, MmToM(o.sample_mm), o.surface_path, o.process_path);
  const polishing::SampleGrid& grid = *run.context.grid;

  // Every parameter comes from an option: a value out of its limits is the
  // caller's mistake.
  polishing::PlanRequest req;
  try {
    req = polishing::ToPlanRequest(o, run.context);
  } catch (const std::invalid_argument& e) {
    throw OptionError("path_parameters", std::string("path_parameters: ") + e.what());
  }
  if (req.optimise && progress) req.progress = progress;
  run.outcome = polishing::PlanPolishing(run.context, req);
  const polishing::PlanOutcome& outcome = run.outcome;
  const polishing::EvaluatedPlan& e = outcome.plan;
  for (const Finding& f : outcome.verdict.findings) warn(f.message);
  if (outcome.optimisation && outcome.optimisation->stop_reason == "max_time") {
    note("the optimiser stopped at --max-time-s " + io::FormatDouble(o.max_time_s) +
         " before its local searches converged; the best plan so far is written");
  }
  if (outcome.comparison && outcome.comparison->zigzag_better) {
    const polishing::PathParameters& pp = outcome.comparison->parallel;
    note("to plan the zig-zag: --pattern parallel --offset-mm " + io::FormatDouble(1e3 * pp.offset) +
         " --line-angle-deg " + io::FormatDouble(pp.line_angle * 180.0 / kPi) + " --edge-overrun-mm " +
         io::FormatDouble(1e3 * pp.edge_overrun));
  }
  const std::string unpolished = polishing::DescribeUnpolished(e.stats, grid.region_area(), o.pattern);
  if (!unpolished.empty()) warn(unpolished);
  if (e.stats.coverage < 0.99) {
    warn("coverage " + FormatNumber(e.stats.coverage, 3) + " < 0.99: parts of the region get less than a "
         "tenth of the mean removal" + (req.optimise ? "" : " (--optimise, or a smaller --offset-mm, covers them)"));
  }
  // An uneven removal is the plan's own result, not a fault of the input:
  // a note that says what evens it (docs/polishing.md).
  if (!req.optimise && e.stats.cv > 0.3) {
    note("the removal varies by " + FormatNumber(100 * e.stats.cv, 2) + " % (CV) over the region: --optimise "
         "chooses the pattern's parameters for the most even removal (docs/polishing.md)");
  }
  return run;
}

}  // namespace robomach::workflows
