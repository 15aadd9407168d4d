#pragma once

#include <memory>
#include <string>
#include <vector>

#include "robomach/dynamics/parameters.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/io/yaml_doc.h"

namespace robomach::io {

/// A robot config file read into a description and its parameter values.
struct RobotConfig {
  dynamics::RobotDescription description;
  dynamics::ParameterSet parameters;   // defaults, then the file's `parameters:` overrides
  std::string path;
  std::shared_ptr<const dynamics::RobotModel> Build() const {
    return dynamics::RobotModel::Build(description, parameters);
  }
};

/// Reads a robot config (see config/kr210.yaml for the documented schema):
/// `robot:` with `urdf`, `base_link`, `tip_frame` (and optional
/// `joint_names`), or `dh:` with a modified-DH table; `joint_stiffness_Nm_per_rad`;
/// `damping` (`alpha_s`, `beta_per_s`); `end_effector` (bodies in the tip
/// frame, `tcp_m`, `spindle_nose_m`, and the reference `m6_kg`, `d6_m`,
/// which must agree with the geometry); optional
/// `spindle_toolholder_interface`, `hammer_test`, `effects` and
/// `parameters` (values by parameter name, as calibration writes them).
/// Unknown keys are rejected. Paths are relative to the config's folder.
/// @throws InputError with `file:line:col` for any problem.
RobotConfig LoadRobotConfig(const std::string& path);

/// The kinematic chain of a config's `robot:` section (URDF or `dh:`, as
/// LoadRobotConfig reads it); `path` is the config file, for relative paths.
/// Used by readers of other robot files (drilling's flexible-joint robot).
/// @throws InputError with `file:line:col` for any problem.
kinematics::SerialChain ReadRobotChain(const YamlDoc& robot, const std::string& path);

/// The `parameters:` block that reproduces `parameters` where they differ
/// from the description's defaults (all of them if `all`), as YAML text.
std::string ParametersYaml(const dynamics::ParameterSet& parameters,
                           const dynamics::ParameterSet& defaults, bool all = false);

/// frf-calibrate's calibrated config (and model-audit --write-config's): the
/// text of the config at `input_path` with its `parameters:` block (if any)
/// replaced by `parameters_yaml` at the end under the comment line
/// `comment`, a relative `urdf:` path made valid from `output_path`'s
/// folder, and `effects` (those switched on for the calibration, whose
/// parameters the block may set) added to the config's `effects:` list: at
/// the end of its block-style list with the indentation of its items, in
/// place of an empty `effects: []`, or as a new list. Only a non-empty flow
/// list (`effects: [{...}]`) is not edited (its layout is the user's):
/// `*effects_left_out` is then true, for the caller to tell the user.
std::string CalibratedConfigText(const std::string& input_path, const std::string& output_path,
                                 const std::string& parameters_yaml, const std::vector<std::string>& effects = {},
                                 bool* effects_left_out = nullptr,
                                 const std::string& comment = "Calibrated by robomach frf-calibrate against measured FRFs.");

}  // namespace robomach::io
