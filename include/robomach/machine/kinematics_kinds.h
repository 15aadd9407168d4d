#pragma once
// The kinds of machine kinematics chosen by name (a machine file's
// kinematics.type, formats.md §8.3), in one registry (issue #36 "one
// vocabulary"): each name with the builder of its MachineKinematics from the
// geometry the file gives. A new kind (table-table, head-head) is its class,
// its geometry in io::MachineFile and one entry here.

#include <functional>
#include <memory>

#include "robomach/common/named_registry.h"
#include "robomach/machine/kinematics.h"
#include "robomach/machine/nutating_head_rotary_table.h"

namespace robomach::machine {

/// Builds a kind's kinematics from the geometry read for it. The one kind
/// today reads a NutatingHeadGeometry; a kind with other geometry widens
/// this argument.
using KinematicsFactory = std::function<std::shared_ptr<const MachineKinematics>(const NutatingHeadGeometry&)>;

/// Every kind by name, in a fixed order: nutating_head_rotary_table. Find
/// throws std::invalid_argument "unknown kinematics type 'NAME': expected
/// nutating_head_rotary_table".
const NamedRegistry<KinematicsFactory>& KinematicsKinds();

}  // namespace robomach::machine
