#pragma once
// polish-plan as one library call (issue #36 §1): a surface file (a NURBS
// YAML or a face of a STEP/IGES file) and a process file -> the sampled
// region, a path planned (optionally optimised for uniform removal) and
// timed for a target removal -> its findings and the summary the tool
// writes. The tool parses its options into PolishPlanOptions and writes
// what RunPolishPlan returns (the path, the removal map, the pictures);
// ListPolishFaces is its --list-faces. The surface choice is polish-sim's
// too (LoadPolishSurface).

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/common/messages.h"
#include "robomach/common/run_status.h"
#include "robomach/io/cad_face.h"
#include "robomach/polishing/nurbs_surface.h"
#include "robomach/polishing/plan_workflow.h"
#include "robomach/polishing/process.h"

namespace robomach::workflows {

/// Which surface of a surface file: face `cad_face` of a STEP/IGES file
/// (1-based, in the file's order; 0: the largest by area), and the factor
/// on its lengths. Both are errors with a NURBS YAML (one patch, in mm);
/// `cad_face_given` says whether the face was chosen (0 given is an error
/// there too). The tools' --face and --cad-unit-scale.
struct SurfaceChoice {
  int cad_face{0};
  bool cad_face_given{false};
  double cad_unit_scale{1.0};

  /// The values alone, before any file is read (a face beyond the file's
  /// count is the reader's).
  /// @throws OptionError "cad_face" below 0, "cad_unit_scale" not finite
  ///   and > 0, naming the value.
  void Validate() const;
};

/// A NURBS YAML, or face `choice.cad_face` of a STEP/IGES file (formats.md
/// §5), by the file's extension. Tells a warning when the CAD part is under
/// 1 mm or over 10 m (units plausibility), and a note naming the face taken
/// when the choice is 0, the largest.
/// @throws OptionError "cad_face" or "cad_unit_scale" when it is given with
///   a YAML surface; InputError from the readers.
polishing::NurbsSurface LoadPolishSurface(const std::string& path, const SurfaceChoice& choice,
                                          const MessageSink& tell = {});

/// polish-plan's options: the planning options (polishing::PlanOptions,
/// named as the tool's options with '_' for '-'), the files and the surface
/// choice.
struct PolishPlanOptions : polishing::PlanOptions {
  std::string surface_path;  // NURBS YAML or STEP/IGES file (formats.md §5)
  std::string process_path;  // process YAML (formats.md §7); may be empty for ListPolishFaces
  SurfaceChoice surface_choice;

  /// polishing::PlanOptions::Validate (names, then the ranges of
  /// PlanOptionRanges: "opt_sample_mm: expected a value in [0.1, 5], got
  /// 10"); the files and the face are checked where they are read.
  /// @throws OptionError naming the field.
  void Validate() const;
};

/// ListPolishFaces' progress: faces checked `done` of `total`.
using FaceProgress = std::function<void(const std::string& stage, long done, long total)>;

/// One row per face of the STEP/IGES file `options.surface_path` (stage
/// "faces"); with a process file, each face is checked against the contact
/// of options' pattern, radius, offset, pitch and row step at sample_mm.
/// Tells the part's unit warning after the listing.
/// @throws InputError from the reader.
std::vector<io::CadFaceRow> ListPolishFaces(const PolishPlanOptions& options, const MessageSink& tell = {},
                                            const FaceProgress& progress = {});

/// The optimiser's progress: evaluations, the best feasible cv so far (NaN
/// before the first), elapsed seconds.
using PlanProgress = std::function<void(int evaluations, double best_cv, double elapsed_s)>;

/// Flagged (the tool's exit 3) on the plan's findings or an implausible
/// input.
struct PolishPlanRun {
  polishing::PolishingProcess process;
  std::shared_ptr<const polishing::NurbsSurface> surface;  // what context.surface points to
  polishing::PlanningContext context;
  polishing::PlanOutcome outcome;
  /// The process file's unit findings and ImplausiblePlanOptions', told as
  /// warnings in that order: they flag the run.
  std::vector<std::string> input_findings;

  bool flagged() const { return outcome.verdict.flagged() || !input_findings.empty(); }
  RunStatus status() const { return flagged() ? RunStatus::kFlagged : RunStatus::kOk; }
  /// polish-plan's summary (formats.md §7; io::PolishPlanSummaryJson),
  /// without the robot block and the warnings.
  nlohmann::json Summary(const PolishPlanOptions& options) const;
};

/// Reads the process file (its unit findings and the options' are warnings),
/// loads the surface (LoadPolishSurface), refuses a face too large to
/// sample (warns before a large one), samples the region, plans (with the
/// optimiser's `progress`), and tells the plan's findings, why the
/// optimiser stopped early, the zig-zag's options when it is better, the
/// unpolished parts, a coverage under 0.99 and an uneven removal.
/// @throws OptionError (Validate; LoadPolishSurface's; "path_parameters"
///   for parameters outside the seed's limits: "path_parameters: why");
///   InputError from the files and the planner.
PolishPlanRun RunPolishPlan(const PolishPlanOptions& options, const MessageSink& tell = {},
                            const PlanProgress& progress = {});

}  // namespace robomach::workflows
