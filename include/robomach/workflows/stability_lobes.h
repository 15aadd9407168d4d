#pragma once
// stability-lobes as one library call (issue #36 §1): the cut file and one
// source of tool tips (the robot model at postures, a measured FRF file, a
// modal table) -> the tips -> the ZOA and/or SD lobes -> the verdict and the
// summary the tool writes. The tool parses its options into
// StabilityLobesOptions and writes what RunStabilityLobes returns; Python's
// run_stability_lobes binds the same call.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "robomach/io/cut_file.h"
#include "robomach/stability/lobe_uncertainty.h"
#include "robomach/stability/lobes_workflow.h"
#include "robomach/stability/tip_dynamics.h"

namespace robomach::workflows {

/// The options of stability-lobes, field by field (the tool's option is the
/// field's name with dashes: sd_speeds is --sd-speeds; robot_path --robot,
/// frf_path --frf, frf_y_path --frf-y, modal_table_path --modal-table,
/// cut_path --cut, pose_ids --posture).
struct StabilityLobesOptions {
  std::string cut_path;  // cut file YAML (docs/stability.md)
  // Exactly one source of tool tips:
  std::string robot_path, postures_path;  // the robot model at postures (both)
  std::string frf_path, frf_y_path;       // a measured FRF file (and one for y)
  std::string modal_table_path;           // a modal table (formats.md §4)
  std::vector<std::string> pose_ids;      // postures analysed; all when empty
  /// With frf_path / modal_table_path: the tool axis from tip to spindle in
  /// the file's frame, and how messages name it (e.g. "--tool-axis 0,0,1";
  /// empty: "tool_axis x,y,z").
  Eigen::Vector3d tool_axis{Eigen::Vector3d::UnitZ()};
  std::string tool_axis_source;

  stability::LobeMethod method{stability::LobeMethod::kZoa};
  int speeds{0};  // ZOA speeds in the cut's range; 0: the cut's spindle_speed_count
  int max_lobe{30};
  int sd_speeds{60};
  int sd_steps{0};  // steps per tooth period; 0: automatic
  double sd_steps_per_mode_period{stability::SdOptions{}.steps_per_mode_period};
  int sd_modes{3};
  double sd_max_depth_mm{20.0};  // [mm]
  int threads{0};                // SD worker threads; 0: all cores
  /// Parameter-uncertainty files (formats.md §12; robot source, ZOA): the
  /// estimates replace the config's values and each ZOA row gets the
  /// critical depth's interval (ZoaLobeBand).
  std::vector<std::string> uncertainty_paths;
  dynamics::PropagationOptions uncertainty;

  /// The bounds keep a typo from hours of work or an allocation failure.
  /// @throws OptionError naming the field, its value and its bound (speeds
  ///   [0, 100000], max_lobe [0, 1000], sd_speeds [1, 10000], sd_steps 0 or
  ///   [2, 1000], sd_steps_per_mode_period [4, 1000], sd_modes [1, 200],
  ///   sd_max_depth_mm [1e-6, 1e4], threads [0, 256], a non-zero
  ///   tool_axis), or the source fields when not exactly one source is given
  ///   (robot_path needs postures_path; frf_y_path needs frf_path);
  ///   uncertainty_paths without robot_path or with method sd, and the
  ///   uncertainty's options (confidence, samples).
  void Validate() const;
  /// Validate's checks of the lobe settings alone (method to threads): for
  /// a caller that brings its own tool tips (Python's stability_lobes).
  void ValidateSettings() const;
  /// "robot", "frf" or "modal_table" (after Validate).
  std::string Source() const;
};

/// The LobesOptions of a cut and the run's options (the speed grids from
/// the cut's range).
stability::LobesOptions MakeLobesOptions(const io::CutSpec& cut, const StabilityLobesOptions& o);

/// "x,y,z" (as --tool-axis takes it) -> the vector, or nullopt unless the
/// text starts with three numbers (the reading stops at the first item that
/// is not one; a fourth number is refused) and they are not all zero.
std::optional<Eigen::Vector3d> ParseToolAxis(const std::string& text);

/// One curve of the lobe diagram: a tip's lobes by one method, speed in
/// rpm against depth in mm (NaN where a speed has no boundary), with the
/// ZOA band's bounds [mm] when the run has bands (else empty).
struct LobeDiagramCurve {
  std::string label;  // "P1 ZOA", "P1 SD"
  std::vector<double> speed_rpm, depth_mm;
  bool markers{false};  // the SD's points (a coarser grid)
  std::vector<double> lower_mm, upper_mm;
};

/// The title of a fitted direct FRF's panel: its label, number of modes,
/// rms misfit in noise units (when known) and usable band.
std::string FitPanelTitle(const stability::DirectionFit& fit);

struct StabilityLobesRun {
  io::CutSpec cut;
  std::vector<stability::TipDynamics> tips;
  stability::LobesResult lobes;
  /// The cut file's and the robot config's unit findings ("implausible
  /// (unit mistake?): ..."), each also told as a warning: they flag the run.
  std::vector<std::string> input_findings;
  /// Per tip, with uncertainty_paths: the ZOA band (its rows' bounds are in
  /// lobes.rows).
  std::vector<stability::ZoaBand> bands;
  std::vector<std::string> uncertainty_files;  // the files the bands came from

  /// stability-lobes' exit 3: the lobes are flagged or an input was implausible.
  bool flagged() const { return lobes.verdict.flagged() || !input_findings.empty(); }
  /// The curves of the lobe diagram: per tip, its ZOA then its SD lobes
  /// (a method without rows is left out).
  std::vector<LobeDiagramCurve> DiagramCurves() const;
  /// What the cut is, for the diagram: "3 teeth, a_e/D = 0.5, down-milling".
  std::string CutDescription() const;
  /// What the diagram's bands are, "95 %, first order" (the level of
  /// o.uncertainty and how they were computed); "" without bands.
  std::string BandNote(const StabilityLobesOptions& o) const;
  /// Each tip's id and modes in the frame of its source file (the modal
  /// table --modes-out writes).
  void ModesInSourceFrame(std::vector<std::string>* ids, std::vector<std::vector<dynamics::Mode>>* modes) const;
  /// The summary JSON of docs/formats.md §4.1 as the tool writes it, but for
  /// the keys only the tool knows (tool, lobes_csv, exit_code).
  nlohmann::json Summary(const StabilityLobesOptions& o) const;
};

/// Validates `o`, reads the cut file, builds the tool tips from the source
/// and computes the lobes. What it has to say (the readers' and the fits'
/// warnings, the input findings, the SD's discretisation) goes to `tell` as
/// it goes; the SD's progress to `progress`.
/// @throws OptionError for bad options, InputError/NoInputError for bad or
///   missing files (as the readers throw them).
StabilityLobesRun RunStabilityLobes(const StabilityLobesOptions& o, const MessageSink& tell = {},
                                    const stability::SdProgressSink& progress = {});

}  // namespace robomach::workflows
