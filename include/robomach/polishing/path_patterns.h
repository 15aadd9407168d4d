#pragma once

// The tool path patterns of polish-plan behind one interface, chosen by name
// in one place (as OMPL's planners are; issue #21): the cycloid rolling
// along guide lines (seed 004 eq. 11) and the direction-parallel zig-zag. A
// new pattern is one class in paths.cc (it walks PlanPath's guide lines) and
// one line in its list; PlanPath, CheckValid, MaxEdgeOverrun and the tools
// ask the pattern instead of comparing names.
#include <string>
#include <vector>

#include "robomach/common/named_registry.h"
#include "robomach/polishing/paths.h"

namespace robomach::polishing {

namespace internal {
struct GuideWalk;  // PlanPath's state along one guide line (src/polishing/paths.cc)
}  // namespace internal

class PathPattern {
 public:
  virtual ~PathPattern() = default;
  /// The value of PathParameters::pattern this class implements.
  virtual Pattern id() const = 0;
  /// The name on the command line and in summaries: "cycloid", "parallel".
  virtual std::string name() const = 0;
  /// One line for --help.
  virtual std::string description() const = 0;
  /// The radius of the circle the tool runs around its guide line [m]
  /// (PathParameters::radius), 0 when the tool follows the guide itself:
  /// the room the pattern needs at the region's edge, and at its links.
  virtual double circle_radius(const PathParameters& p) const = 0;
  /// The pattern's own feasibility limits, after the shared ones.
  /// @throws std::invalid_argument naming the violated limit.
  virtual void CheckValid(const PathParameters& p) const = 0;
  /// The largest edge_overrun PlanPath uses [m].
  virtual double MaxEdgeOverrun(const PathParameters& p, const PolishingProcess& process) const = 0;
  /// The nominal rolling rate at the speed limit `max_speed` [m/s] (the
  /// point on the circle at that speed) [rad/s]; 0 when nothing rolls.
  virtual double NominalRate(const PathParameters& p, double max_speed) const = 0;
  /// The speed of the circle's centre at rolling rate `rate` [m/s]; 0 when
  /// nothing rolls.
  virtual double CentreSpeed(const PathParameters& p, double rate) const = 0;
  /// Appends the rows (with their time stamps) along one guide line.
  virtual void Follow(internal::GuideWalk& walk) const = 0;
};

/// Every pattern by name, in a fixed order (cycloid, parallel): the
/// functions below are this registry's. A name is ToString of the
/// pattern's id().
const NamedRegistry<const PathPattern*>& PathPatternRegistry();

/// Every pattern, in a fixed order (cycloid, parallel).
const std::vector<const PathPattern*>& PathPatterns();

/// The names, for messages: "cycloid or parallel".
std::string PathPatternList();

/// The pattern called `name`. @throws std::invalid_argument naming the known ones.
const PathPattern& FindPathPattern(const std::string& name);

/// The pattern of PathParameters::pattern.
const PathPattern& PathPatternOf(Pattern id);

}  // namespace robomach::polishing
