#include "robomach/workflows/tip_sources.h"

#include <algorithm>
#include <sstream>
#include <stdexcept>

#include "robomach/common/errors.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/tip_dynamics_files.h"
#include "robomach/stability/tool_tip_model.h"

namespace robomach::workflows {

Eigen::Matrix3d CutFrame(const io::CutSpec& cut, const Eigen::Vector3d& tool_axis, const std::string& axis_source) {
  try {
    return stability::CuttingFrame(tool_axis, cut.feed_direction_B);
  } catch (const std::invalid_argument& e) {
    throw InputError({cut.path, cut.feed_line, cut.feed_column},
                     std::string("feed_direction: ") + e.what() + " (" + axis_source + ")");
  }
}

std::vector<stability::TipDynamics> TipsFromRobotPostures(const std::shared_ptr<const dynamics::RobotModel>& model,
                                                          const std::string& postures_path,
                                                          const std::vector<std::string>& pose_ids, const io::CutSpec& cut,
                                                          const MessageSink& tell,
                                                          std::vector<io::Posture>* chosen_postures) {
  const std::vector<io::Posture> postures = io::ReadPostureFile(postures_path, model->num_joints());
  std::vector<const io::Posture*> chosen;
  for (const std::string& id : pose_ids) {
    auto it = std::find_if(postures.begin(), postures.end(), [&](const io::Posture& p) { return p.id == id; });
    if (it == postures.end()) {
      std::string known;
      for (const io::Posture& p : postures) known += (known.empty() ? "" : ", ") + p.id;
      throw InputError({postures_path, 0, 0}, "no posture \"" + id + "\" in the file; it has " + known);
    }
    chosen.push_back(&*it);
  }
  if (chosen.empty()) {
    for (const io::Posture& p : postures) chosen.push_back(&p);
  }
  std::vector<stability::TipDynamics> tips;
  dynamics::PostureEvaluator ev(model);
  for (const io::Posture* p : chosen) {
    if (chosen_postures) chosen_postures->push_back(*p);
    const dynamics::PostureDynamics d = ev.Evaluate(p->q);
    if (d.near_singular && tell) {
      tell({Message::Kind::kWarning, postures_path + ":" + std::to_string(p->line) + ": posture " +
                                                       p->id + " is near a singularity; the tool-tip FRF (joint "
                                                               "space) stays valid"});
    }
    try {
      tips.push_back(
          stability::TipFromPosture(p->id, d, cut.feed_direction_B, cut.process.teeth, cut.spindle_speed_max_rad_s));
    } catch (const std::invalid_argument& e) {
      throw InputError({cut.path, cut.feed_line, cut.feed_column},
                       std::string("feed_direction: ") + e.what() + " at posture " + p->id);
    }
  }
  return tips;
}

std::vector<stability::TipDynamics> TipsFromFrfFiles(const stability::MeasuredTipOptions& options,
                                                     const MessageSink& tell) {
  // Each file's reader warnings as it is read, before the fits speak.
  auto read = [&](const std::string& path) {
    std::vector<std::string> warnings;
    std::vector<io::FrfSetOfPose> sets = io::ReadTipFrfs(path, "", &warnings);
    if (tell) {
      for (const std::string& w : warnings) tell({Message::Kind::kWarning, w});
    }
    return sets;
  };
  const std::vector<io::FrfSetOfPose> sets = read(options.frf_path);
  std::vector<io::FrfSetOfPose> ysets;
  if (!options.frf_y_path.empty()) ysets = read(options.frf_y_path);
  return stability::TipsFromMeasuredFrfs(sets, ysets, options, tell);
}

std::vector<stability::TipDynamics> TipsFromModalTableFile(const std::string& path,
                                                           const std::vector<std::string>& pose_ids,
                                                           const Eigen::Matrix3d& R_BC, const io::CutSpec& cut) {
  std::vector<stability::TipDynamics> tips;
  for (const io::ModalTableEntry& e : io::ReadModalTable(path)) {
    if (!pose_ids.empty() && std::find(pose_ids.begin(), pose_ids.end(), e.pose_id) == pose_ids.end()) continue;
    tips.push_back(stability::TipFromModes(e.pose_id, e.modes, R_BC, cut.process.teeth, cut.spindle_speed_max_rad_s));
  }
  if (tips.empty()) throw InputError({path, 0, 0}, "none of the requested postures is in the file");
  return tips;
}

}  // namespace robomach::workflows
