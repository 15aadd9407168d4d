#pragma once

#include <ostream>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/dynamics/uncertainty.h"

namespace robomach::io {

/// The tool-tip FRFs of one posture on one frequency grid.
struct PosturePrediction {
  std::string pose_id;
  Eigen::VectorXd freq_hz;
  std::vector<Eigen::Matrix3cd> H;  // [m/N] per line, in B
};

/// Which response/excitation pairs to write, e.g. {{0,0},{1,1},{0,1}}.
using DirectionPairs = std::vector<std::pair<int, int>>;
/// All nine pairs.
DirectionPairs AllDirectionPairs();
/// "xx,yy,xy" (each letter as ParseAxis takes it, a capital too) or "all".
/// @throws std::invalid_argument for a malformed list such as "xx,yq".
DirectionPairs ParseDirectionPairs(const std::string& text);

/// Writes predicted FRFs in the long CSV format of formats.md §3,
/// `# quantity: receptance`, one file for all postures.
void WritePredictedFrfCsv(const std::string& path, const std::vector<PosturePrediction>& predictions,
                          const DirectionPairs& pairs);
void WritePredictedFrfCsv(std::ostream& os, const std::vector<PosturePrediction>& predictions,
                          const DirectionPairs& pairs);

/// Writes the modal table of formats.md §4:
/// pose_id,mode,freq_hz,damping_ratio,modal_mass_kg,ux,uy,uz; with
/// `intervals` (one per posture, from --uncertainty) also the columns
/// freq_hz_lower, freq_hz_upper, damping_ratio_lower, damping_ratio_upper,
/// peak_receptance_m_per_N, peak_receptance_m_per_N_lower,
/// peak_receptance_m_per_N_upper and interval_method.
void WriteModalTableCsv(const std::string& path, const std::vector<std::string>& pose_ids,
                        const std::vector<std::vector<dynamics::Mode>>& modes,
                        const std::vector<dynamics::PostureModeIntervals>* intervals = nullptr);

/// Everything of one posture as JSON with unit-suffixed keys (frf-predict's
/// --summary, one per posture): q_rad, tcp position, J and its condition
/// number, M_q/K_q/C_q, Cartesian M/K/C (null when near singular), static
/// compliance, modes. Matrices are row-major arrays of rows.
nlohmann::json PostureToJson(const std::string& pose_id, const dynamics::PostureDynamics& d);

}  // namespace robomach::io
