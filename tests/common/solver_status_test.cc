#include "robomach/common/solver_status.h"

#include <set>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "robomach/common/run_status.h"

namespace robomach {
namespace {

// Every status has its own snake_case name: the spelling the summaries,
// the material file and Python use.
TEST(SolverStatus, EachStatusHasItsOwnName) {
  std::set<std::string> names;
  for (SolverStatus s : {SolverStatus::kConverged, SolverStatus::kNotConverged, SolverStatus::kFailed,
                         SolverStatus::kNotImproved}) {
    const std::string n = ToString(s);
    EXPECT_EQ(n.find(' '), std::string::npos) << n;
    names.insert(n);
  }
  EXPECT_EQ(names, (std::set<std::string>{"converged", "not_converged", "failed", "not_improved"}));
}

// One vocabulary (issue #36): each status goes through its name and back, and
// a name that is not one is refused.
TEST(SolverStatus, RoundTripsThroughItsName) {
  for (SolverStatus s : {SolverStatus::kConverged, SolverStatus::kNotConverged, SolverStatus::kFailed,
                         SolverStatus::kNotImproved}) {
    EXPECT_EQ(ParseSolverStatus(ToString(s)), s) << ToString(s);
  }
  EXPECT_THROW(ParseSolverStatus("converged "), std::invalid_argument);
  for (RunStatus s : {RunStatus::kOk, RunStatus::kFlagged}) {
    EXPECT_EQ(ParseRunStatus(ToString(s)), s) << ToString(s);
  }
  EXPECT_THROW(ParseRunStatus("OK"), std::invalid_argument);
}

}  // namespace
}  // namespace robomach
