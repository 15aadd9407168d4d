#pragma once

#include <string>

#include "robomach/kinematics/serial_chain.h"

namespace robomach::io {

/// Reads a URDF with urdfdom and converts the kinematic chain between the
/// links `base_link` and `tip_link` to a SerialChain: for every joint,
/// KDL::Joint(name, F.p, F.M·axis, RotAxis) with F the joint origin in the
/// parent link, and the child link's inertial rotated by its
/// `<inertial><origin rpy>` (this replaces ROS's kdl_parser, style.md §4).
/// Joint limits come from `<limit>`; continuous joints are unbounded.
///
/// @throws InputError naming the file (and the line of the offending element
///   where it can be found) if the XML is not a valid URDF (with urdfdom's
///   own reason), a link is missing, the tip is not below the base, a joint
///   is prismatic or planar, or an inertial is not physical.
kinematics::SerialChain LoadUrdfChain(const std::string& path, const std::string& base_link,
                                      const std::string& tip_link);

}  // namespace robomach::io
