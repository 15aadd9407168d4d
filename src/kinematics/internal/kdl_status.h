#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

#include <kdl/solveri.hpp>

namespace robomach::kinematics::internal {

// KDL solvers return int codes (0 ok, +1 degraded, negative errors) instead
// of throwing (style.md §3). Negative codes become exceptions naming the
// operation; the caller records E_DEGRADED where it matters.
inline void ThrowIfKdlFailed(int code, const KDL::SolverI& solver, std::string_view operation) {
  if (code >= KDL::SolverI::E_NOERROR) return;
  throw std::runtime_error(std::string(operation) + ": KDL error " + std::to_string(code) + " (" +
                           solver.strError(code) + ")");
}

}  // namespace robomach::kinematics::internal
