#pragma once
// The machine type behind one small interface: forward and inverse
// kinematics between machine axis positions and the tool in workpiece
// coordinates. A table-table or head-head machine is another implementation
// of this interface (see nutating_head_rotary_table.h for the seed's DMU 80P).

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace robomach::machine {

/// Tool tip and tool axis in workpiece coordinates.
struct ToolPose {
  Eigen::Vector3d p_W{Eigen::Vector3d::Zero()};  // tool tip [m]
  Eigen::Vector3d k_W{Eigen::Vector3d::UnitZ()}; // tool axis, tip towards spindle, unit
};

enum class InverseStatus {
  kOk,
  kUnreachableAxis,  // the tool axis cannot be reached by the rotary axes
};

struct InverseResult {
  InverseStatus status{InverseStatus::kOk};
  Eigen::VectorXd q;          // machine axes in axis_names() order [m, rad]
  std::string message;        // why, if not kOk
};

class MachineKinematics {
 public:
  virtual ~MachineKinematics() = default;
  /// Names of the machine axes this kinematics needs, in the order of q.
  virtual std::vector<std::string> axis_names() const = 0;
  /// Which of those axes are rotary.
  virtual std::vector<bool> rotary() const = 0;
  /// Tool tip and axis in workpiece coordinates at machine position q.
  virtual ToolPose Forward(const Eigen::VectorXd& q) const = 0;
  /// Every solution (rotary angles in their principal range) for a pose.
  virtual std::vector<Eigen::VectorXd> InverseSolutions(const ToolPose& pose,
                                                        const Eigen::VectorXd& q_previous) const = 0;
  /// The solution nearest to q_previous, rotary axes unwrapped by whole turns
  /// towards q_previous (so a path stays continuous).
  InverseResult Inverse(const ToolPose& pose, const Eigen::VectorXd& q_previous) const;
  /// The same machine without its geometric errors (the controller's model).
  virtual std::unique_ptr<MachineKinematics> WithoutErrors() const = 0;
};

}  // namespace robomach::machine
