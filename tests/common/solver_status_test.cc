#include "robomach/common/solver_status.h"

#include <set>
#include <string>

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace robomach
