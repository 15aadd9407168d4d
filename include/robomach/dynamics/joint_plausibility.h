#pragma once
// The joint plausibility of a robot description (docs/plausibility.md; it
// was io::LoadRobotConfig's until issue #36 left io the formats only): each
// joint's decoupled frequency, its turn under the robot's own weight, and
// the damping ratio, judged against what robots have. A finding names the
// file:line:col of the value it blames and the likely unit mistake; the
// tools print the findings as warnings after the reader's own and flag
// their result (exit 3). The tools read a config with
// workflows::LoadRobotConfigChecked, which appends these to
// io::RobotConfig::implausible.

#include <string>
#include <vector>

#include "robomach/common/errors.h"
#include "robomach/dynamics/parameters.h"
#include "robomach/dynamics/robot_model.h"

namespace robomach::dynamics {

// Plausible ranges (docs/plausibility.md). Sources: joint stiffnesses of
// industrial robots 1e4 to 1e7 N·m/rad (Dumas, Caro, Garnier and Furet,
// Robot. CIM 27 (2011); the seed's KR 210: 1.9e5 to 4.3e6), of small arms
// down to 1e3; first modes of robots 5 to 50 Hz and wrist modes to a few
// hundred Hz, damping ratios 0.01 to 0.1 (Cordes, Hintze and Altintas,
// Robot. CIM 55 (2019); Tunc and Stoddart, IJAMT 89 (2017)).
/// sqrt(kq_j / M_q(j,j)) / 2 pi at q = 0 (mid-limits where they exclude 0):
/// x1000 in kq or /1000 in the masses moves it by 31.6 (the KR 210's are
/// 10 to 250 Hz). Below 1 Hz a joint that carries its links' weight would
/// let them sag by g / w² = 25 cm (a link of mass m at radius r: torque
/// m g r over kq = m r² w² turns it by g / (w² r)).
inline constexpr double kMinPlausibleJointFrequencyHz = 1.0;
inline constexpr double kMaxPlausibleJointFrequencyHz = 2000.0;
/// The turn of a joint under the robot's own weight, |G_j(q)| / kq_j, the
/// largest over each joint swept through its limits (9 angles, the others at
/// the same posture): robot gearboxes (RV and harmonic reducers) deflect by
/// 1 - 5 arc-minutes under their rated torque (Nabtesco RV-E, Harmonic Drive
/// CSG catalogues), and the KR 210's joints turn by at most 0.09 deg (joint
/// 2: 4760 N·m on 3.13e6 N·m/rad) under its weight. Over 1 deg (20 times
/// the catalogues) the tool would sag by centimetres: a stiffness typed per
/// degree (N·m/deg, the value / 57.3) or in kN·m/rad. Frequencies alone miss
/// the first: /57.3 moves them by only 7.6 (the KR 210's lowest to 1.3 Hz,
/// inside the range above).
inline constexpr double kMaxPlausibleGravitySagRad = 0.017453292519943295;  // 1 deg
/// Rayleigh damping ratio (alpha w + beta / w) / 2 at each joint frequency.
inline constexpr double kMaxPlausibleDampingRatio = 0.5;

/// Where the values these checks blame were typed: each joint's stiffness
/// (in joint order) and the damping section.
struct JointValueLocations {
  std::vector<SourceLocation> joint_stiffness;
  SourceLocation damping;
};

/// "implausible (unit mistake?): file:line:col: ..." findings of the model
/// built from `description` and `parameters`, in this order: each joint
/// whose frequency sqrt(kq_j / M_q(j,j)) / 2 pi at q = 0 (mid-limits where
/// they exclude 0) is outside [kMinPlausibleJointFrequencyHz,
/// kMaxPlausibleJointFrequencyHz]; if none, the joint that turns most under
/// the robot's own weight (each joint swept through its limits, 9 angles,
/// the others at q) when that exceeds kMaxPlausibleGravitySagRad; if none,
/// the largest Rayleigh damping ratio when it exceeds
/// kMaxPlausibleDampingRatio. Nothing for a model that does not build (the
/// tool that builds it reports it); a weight that cannot be computed leaves
/// the sag unjudged. `where.joint_stiffness` has one location per joint.
std::vector<std::string> JointPlausibilityFindings(const RobotDescription& description,
                                                   const ParameterSet& parameters, const JointValueLocations& where);

}  // namespace robomach::dynamics
