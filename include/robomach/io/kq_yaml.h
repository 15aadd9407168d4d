#pragma once

#include <string>
#include <vector>

#include "robomach/identification/joint_stiffness.h"

namespace robomach::io {

struct KqYamlOptions {
  /// Write a `parameters:` block (kq1_Nm_per_rad: ...) instead of the
  /// `joint_stiffness_Nm_per_rad: [...]` line.
  bool as_parameters{false};
  std::vector<std::string> header_comments;   // written first, each prefixed by "# "

  /// @throws OptionError naming the field and the value: every
  /// header_comments entry is one line (no line break: the text after one
  /// would not be a comment, and the YAML would not parse).
  void Validate() const;
};

/// The identified stiffness as YAML that can be pasted into a robot config,
/// with the uncertainty, determination and correlation as comments. Joints
/// that are not determined keep their prior value and say so in a comment.
/// @throws OptionError for bad options (KqYamlOptions::Validate).
std::string JointStiffnessYaml(const identification::JointStiffnessResult& result,
                               const KqYamlOptions& options = {});

/// A copy of the robot config at `config_path` with its
/// `joint_stiffness_Nm_per_rad:` entry replaced by `kq` [N·m/rad], meant to
/// be written to `output_path`: a relative `urdf:` path is rewritten to stay
/// valid from the output's folder. Comments and everything else are kept.
/// @throws InputError if the config has no one-line joint_stiffness entry or
///   sets kq parameters under `parameters:` (which would override it).
/// With `uncertainty_path` (kq-identify --merge --uncertainty-out) the copy
/// ends with `uncertainty: [path]` (relative to the output's folder when
/// the path is relative), replacing an `uncertainty:` line it had.
std::string MergeJointStiffness(const std::string& config_path, const Eigen::VectorXd& kq,
                                const std::string& output_path,
                                const std::vector<std::string>& header_comments = {},
                                const std::string& uncertainty_path = "");

}  // namespace robomach::io
