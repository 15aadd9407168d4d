#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/stability/tool_tip_model.h"

namespace robomach::io {

/// The tool-tip FRFs of one posture from a file, as receptance [m/N] in B.
/// Directions that the file does not give are zero and flagged absent.
struct FrfSetOfPose {
  std::string pose_id;
  Eigen::VectorXd freq_hz;            // one grid shared by all pairs of the pose
  std::vector<Eigen::Matrix3cd> H;    // per line [m/N]
  std::array<std::array<bool, 3>, 3> present{};  // [response][excitation]
  std::string source;                 // file, for messages
};

/// Reads the hammer-test FRF CSV of formats.md §3 (long format,
/// `# quantity:` receptance, mobility or accelerance, converted to
/// receptance). All FRFs of one posture must share one frequency grid
/// (strictly increasing); a pair given twice is an error.
/// @throws InputError naming file, line and column.
std::vector<FrfSetOfPose> ReadFrfCsv(const std::string& path);

/// One posture of a modal table.
struct ModalTableEntry {
  std::string pose_id;
  stability::TipModalModel modes;  // p in B [1/√kg]
};

/// Reads a modal table (formats.md §4): `pose_id,mode,freq_hz,damping_ratio,`
/// then `modal_mass_kg` or `modal_stiffness_N_per_m` (k = m ω_n²), and the
/// tool-tip shape `ux,uy,uz` (normalised on reading). p = u/√m.
/// @throws InputError naming file, line and column.
std::vector<ModalTableEntry> ReadModalTable(const std::string& path);

}  // namespace robomach::io
