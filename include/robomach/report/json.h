#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "robomach/dynamics/posture_dynamics.h"

namespace robomach::report {

/// Everything of one posture as JSON with unit-suffixed keys: q_rad, tcp
/// position, J and its condition number, M_q/K_q/C_q, Cartesian M/K/C (null
/// when near singular), static compliance, modes. Matrices are row-major
/// arrays of rows.
nlohmann::json PostureToJson(const std::string& pose_id, const dynamics::PostureDynamics& d);

/// Dumps JSON with non-finite numbers written as null. A JSON object gets a
/// `robomach_version` field (robomach::Version(): the version and git
/// commit that made it) unless it has one, so every JSON output of the
/// tools can be traced to its code.
std::string DumpJson(const nlohmann::json& j);

}  // namespace robomach::report
