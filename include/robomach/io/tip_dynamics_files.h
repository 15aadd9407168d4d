#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/stability/tip_dynamics.h"
#include "robomach/stability/tool_tip_model.h"

namespace robomach::io {

/// The tool-tip FRFs of one posture from a file, as receptance [m/N] in B
/// (stability/tip_dynamics.h's TipFrfs, which turns them into tool tips).
using FrfSetOfPose = stability::TipFrfs;

/// Reads measured or predicted tool-tip FRFs (formats.md §3: the long CSV,
/// or UFF58 by extension; io/frf_files.h validates them and converts
/// mobility and accelerance to receptance) and groups them per posture. All
/// FRFs of one posture must share one frequency grid. `default_pose_id`
/// names the posture of a UFF file whose records do not (else their pose id
/// is empty: a posture-free FRF). Reader warnings are appended to
/// `warnings` and notes to `notes` if given.
/// @throws InputError naming file, line and column.
std::vector<FrfSetOfPose> ReadTipFrfs(const std::string& path, const std::string& default_pose_id = "",
                                      std::vector<std::string>* warnings = nullptr,
                                      std::vector<std::string>* notes = nullptr);

/// The unit plausibility of the FRFs read (stability::TipFrfsUnitFinding:
/// the largest receptance of each posture's FRFs on their usable bands):
/// one finding per posture out of range, naming the file and posture (a
/// mobility or accelerance read as receptance, a response in mm under _m).
std::vector<std::string> ReceptanceUnitFindings(const std::vector<FrfSetOfPose>& sets);

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
