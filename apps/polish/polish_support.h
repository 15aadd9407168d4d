#pragma once

// Shared by polish-plan and polish-sim: the surface choice's options, the
// pictures and the "on the robot" options (the work is in
// workflows/polish_plan.h and workflows/polish_robot_check.h).

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/kinematics/pose_path.h"
#include "robomach/polishing/nurbs_surface.h"
#include "robomach/polishing/paths.h"
#include "robomach/polishing/process.h"
#include "robomach/polishing/removal.h"
#include "robomach/polishing/surface_grid.h"
#include "robomach/workflows/polish_plan.h"

namespace CLI {
class App;
}

namespace robomach::apps {

/// --face and --cad-unit-scale (workflows::LoadPolishSurface loads the surface).
using SurfaceChoice = workflows::SurfaceChoice;

/// Registers --face and --cad-unit-scale on `app` (polish-plan, polish-sim).
void AddSurfaceChoiceOptions(CLI::App* app, SurfaceChoice* choice);

/// Pictures next to `png`: the removal map (png itself, colour scale in
/// um on the developed s, t plane), <stem>_histogram.png, <stem>_path.png
/// (path, lifted moves and guide lines in the developed s, t plane) and, if `history` is not empty,
/// <stem>_convergence.png: `history` the best cv so far per evaluation, `evaluated` the cv of each
/// (NaN entries: infeasible evaluations, not drawn). Returns the paths written.
std::vector<std::string> WritePictures(const std::string& png, const polishing::SampleGrid& grid,
                                       const std::vector<double>& removal_m,
                                       const std::vector<polishing::PathRow>& rows,
                                       const std::vector<std::vector<Eigen::Vector2d>>& guide_lines_st,
                                       const std::vector<double>& history, const std::string& title,
                                       const std::vector<double>& evaluated = {});

/// The list of picture files WritePictures would write (for clean-up and
/// distinct-path checks).
std::vector<std::string> PicturePaths(const std::string& png, bool with_convergence);

}  // namespace robomach::apps

namespace robomach::dynamics {
class RobotModel;
}
namespace CLI {
class App;
}

namespace robomach::apps {

/// The "on the robot" options of polish-plan and polish-sim (--robot,
/// --part-frame-mm-deg, --robot-seed-deg, --joints) and what they do, in one
/// place for both tools.
class RobotOptions {
 public:
  /// Registers the four options on `app`.
  void Add(CLI::App* app);
  /// Checks the options and loads the robot (before any output is written);
  /// adds --joints to `outs` for the distinct-path check.
  /// @throws UsageError (bad command line), InputError (robot config).
  void Prepare(std::vector<std::pair<std::string, std::string>>* outs);
  bool enabled() const { return robot_ != nullptr; }
  const std::string& robot_path() const { return robot_path_; }
  /// Checks `rows` on the robot (workflows::CheckPolishPathOnRobot), fills
  /// summary["robot"], warns on stderr under `tool` for flagged rows and
  /// returns true if any row is flagged.
  bool Check(const std::string& tool, const polishing::PolishingProcess& process,
             const std::vector<polishing::PathRow>& rows, nlohmann::json* summary);
  /// Writes the joint trajectory if --joints was given.
  void WriteJoints(const std::vector<polishing::PathRow>& rows) const;

 private:
  std::string robot_path_, part_frame_text_ = "0,0,0,0,0,0", joints_out_, seed_text_ = "0,-90,90,0,45,0";
  std::vector<double> part_, seed_deg_;
  std::shared_ptr<const dynamics::RobotModel> robot_;
  kinematics::PosePathCheck check_;
};

}  // namespace robomach::apps
