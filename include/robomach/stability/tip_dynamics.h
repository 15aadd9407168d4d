#pragma once
// The tool-tip dynamics a lobe computation needs, oriented into the cutting
// frame C (x_C along the feed, z_C along the tool axis), from each of the
// three sources stability-lobes accepts (issue #21: the builders live here,
// not in the tool): the robot model at a posture, a modal table, or measured
// (or predicted) tool-tip FRFs with a modal fit of their direct FRFs.

#include <array>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "robomach/common/messages.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/stability/measured_tip_model.h"
#include "robomach/stability/tool_tip_model.h"

namespace robomach::stability {

/// The tool-tip FRFs of one posture, as receptance [m/N] in B. Directions
/// that the file does not give are zero and flagged absent
/// (io::ReadTipFrfs reads them; io::FrfSetOfPose is this type).
struct TipFrfs {
  std::string pose_id;
  Eigen::VectorXd freq_hz;                       // one grid shared by all pairs of the pose
  std::vector<Eigen::Matrix3cd> H;               // per line [m/N]
  std::array<std::array<bool, 3>, 3> present{};  // [response][excitation]
  std::string source;                            // file, for messages
};

/// The modal fit of one direct FRF of a measured file.
struct DirectionFit {
  std::string label;  // "P1 Hxx", for messages and the plot
  DirectFrfFit fit;
  /// The label of an earlier fit of the same tip whose FRF is identical
  /// (every line equal, e.g. a file that gives one measurement as both Hxx
  /// and Hyy): that fit is reused, not repeated (issue #34 item 6), and its
  /// warnings are not repeated either. Empty for a fit of its own.
  std::string same_as;
};

/// The tool-tip dynamics of one source, oriented into the cutting frame.
struct TipDynamics {
  std::string id;
  Eigen::VectorXd freq_hz;              // grid of the FRF [Hz], > 0
  std::vector<Eigen::Matrix2cd> Phi_C;  // in-plane oriented FRF [m/N]: the ZOA's input
  TipModalModel modes_C;                // p in C [1/√kg]: the semi-discretization's input
  /// Measured tips: every fitted mode in C (modes_C keeps the dominant
  /// ones), the shape the ZOA follows between the measured lines and its
  /// cross-check (ComputeLobes); empty for a model's tip.
  TipModalModel fit_C;
  bool fit_lacks_cross{false};  // the file's cross FRFs are in Phi_C but fit_C does not model them
  bool modes_fitted{false};             // fitted to an FRF (not given)
  bool no_modes{false};                 // fitted, but no mode: no SD
  std::vector<DirectionFit> fits;       // measured FRFs: one per direct FRF fitted
  Eigen::Matrix3d R_BC{Eigen::Matrix3d::Identity()};  // the frame the modes were oriented with
  /// Measured FRFs whose largest receptance is outside the plausible range
  /// (TipFrfsUnitFinding: a mobility or accelerance read as receptance, a
  /// response in mm under _m); empty when plausible or not measured.
  std::string unit_finding;
  bool unit_finding_said{false};  // told as a warning when the tip was built
};

/// calibration::UsableBandUnitFinding of the largest
/// calibration::PeakReceptanceInUsableBand of the FRFs `frfs` gives (each
/// on the band its noise model finds usable), naming its file and posture;
/// empty when plausible.
std::string TipFrfsUnitFinding(const TipFrfs& frfs);

/// Lines of the log frequency grid of the model sources: ln(100)/4000 ≈ 1e-3
/// relative spacing, below ζ/10 for ζ ≥ 1 %.
inline constexpr int kLobeGridLines = 4000;

/// The tool tip of the robot model at a posture: its modes (ModalModelFromPosture)
/// and their receptance on LobeFrequencyGrid, in the cutting frame of the
/// posture's tool axis and `feed_B`.
/// @throws std::invalid_argument when the feed is along the tool axis.
TipDynamics TipFromPosture(const std::string& id, const dynamics::PostureDynamics& d, const Eigen::Vector3d& feed_B,
                           int teeth, double max_speed_rad_s, int lines = kLobeGridLines);

/// The tool tip of a modal table's modes (p in B), oriented by R_BC.
TipDynamics TipFromModes(const std::string& id, const TipModalModel& modes_B, const Eigen::Matrix3d& R_BC,
                         int teeth, double max_speed_rad_s, int lines = kLobeGridLines);

/// How measured tool-tip FRFs become tool tips.
struct MeasuredTipOptions {
  /// The files the FRFs came from: an FRF without a posture is shown as its
  /// file's stem, and messages name them.
  std::string frf_path;
  std::string frf_y_path;  // the second direction (y_C) from another file; empty: none
  std::vector<std::string> pose_ids;  // empty: every posture of the file
  /// R_BC of the cut, asked for only when the FRFs need orienting (several
  /// base directions, or two files); it may throw (an InputError naming
  /// the cut file, or the caller's own error for a bad tool axis). With one
  /// direct FRF (a symmetric tool) its InputError is taken as "no frame"
  /// and R_BC stays the identity.
  std::function<Eigen::Matrix3d()> cutting_frame;
  /// How the caller gave the tool axis, for messages ("--tool-axis 0,0,1").
  std::string tool_axis_source;
  bool fit{true};    // fit modes to the direct FRFs (for the SD and the usable band)
  int sd_modes{3};   // dominant modes kept per direct FRF (stability-lobes' default)

  /// @throws OptionError naming the field, its value and the bound:
  /// sd_modes >= 1 (a tip of no mode has no SD lobes). The paths are for
  /// messages only and may be empty.
  void Validate() const;
};

// What building the tool tips has to say, as it happens, is a Message
// (common/messages.h): the noise model and the modal fit of each direct FRF
// (kInfo, several lines, continuation lines indented by two blanks), notes
// and warnings.

/// The tool tips of measured FRFs, one per posture (and `ysets`, when given,
/// the y_C direction of each from a second file of one direct FRF each):
/// - two files: Hxx along the feed and Hyy normal to it, no cross terms;
/// - one direct FRF only: a symmetric tool, the FRF in both in-plane
///   directions;
/// - else the 3×3 FRF in B oriented into the cutting plane, which its
///   directions must span (a missing cross FRF is taken as zero, a warning).
/// Every tip carries the unit findings of its FRFs (TipFrfsUnitFinding).
/// With `fit`, every direct FRF gets a noise model and a modal fit
/// (FitDirectFrf); the SD's modes come from them (a mode seen in two direct
/// FRFs with a cross FRF is one mode, ModesOfTwoDirections), and the ZOA
/// keeps the lines inside the usable band of every fitted direction.
/// @throws InputError naming the file for a posture missing, FRFs the
///   cutting plane needs but the file lacks, grids that differ between the
///   files.
std::vector<TipDynamics> TipsFromMeasuredFrfs(const std::vector<TipFrfs>& sets, const std::vector<TipFrfs>& ysets,
                                              const MeasuredTipOptions& options, const MessageSink& on_message);

/// The modes of a tool tip in the frame of its source (p_B = R_BC p_C) as
/// rows of a modal table: frequency, damping, modal mass 1/|p|², the shape
/// normalised with its largest component positive.
std::vector<dynamics::Mode> ModesInSourceFrame(const TipDynamics& tip);

}  // namespace robomach::stability
