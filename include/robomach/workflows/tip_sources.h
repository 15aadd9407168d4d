#pragma once
// stability-lobes' three sources of tool tips, read from their files
// (issue #21: one call for the tool and Python): the robot model at the
// postures of a posture file, a measured FRF file (and a second one for the
// y direction), and a modal table.

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/dynamics/robot_model.h"
#include "robomach/io/cut_file.h"
#include "robomach/io/posture_file.h"
#include "robomach/stability/tip_dynamics.h"

namespace robomach::workflows {

/// R_BC of `cut` for a tool axis (from the tip to the spindle) in the
/// source's frame (stability::CuttingFrame). A feed along the axis is an
/// InputError at the cut file's feed_direction that names `axis_source`
/// (how the caller gave the axis, e.g. "--tool-axis 0,0,1").
Eigen::Matrix3d CutFrame(const io::CutSpec& cut, const Eigen::Vector3d& tool_axis, const std::string& axis_source);

/// The tool tips of `model` at the postures `pose_ids` of the posture file
/// (in that order; every posture of the file, in its order, when empty). A
/// posture near a singularity is told as a warning naming the file and line
/// (the joint-space FRF stays valid).
/// @throws InputError naming the posture file for an unknown id (listing the
///   known ones) and the cut file's feed_direction for a feed along the tool
///   axis at a posture.
std::vector<stability::TipDynamics> TipsFromRobotPostures(const std::shared_ptr<const dynamics::RobotModel>& model,
                                                          const std::string& postures_path,
                                                          const std::vector<std::string>& pose_ids, const io::CutSpec& cut,
                                                          const MessageSink& tell = {},
                                                          std::vector<io::Posture>* chosen_postures = nullptr);

/// The tool tips of the measured FRFs of options.frf_path (and
/// options.frf_y_path): io::ReadTipFrfs, its warnings told, then
/// stability::TipsFromMeasuredFrfs.
std::vector<stability::TipDynamics> TipsFromFrfFiles(const stability::MeasuredTipOptions& options,
                                                     const MessageSink& tell = {});

/// The tool tips of a modal table's postures `pose_ids` (all when empty),
/// oriented by R_BC (CutFrame).
/// @throws InputError naming the file when none of the postures is in it.
std::vector<stability::TipDynamics> TipsFromModalTableFile(const std::string& path,
                                                           const std::vector<std::string>& pose_ids,
                                                           const Eigen::Matrix3d& R_BC, const io::CutSpec& cut);

}  // namespace robomach::workflows
