#include "polish_support.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "cli_support.h"
#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/io/cad_face.h"
#include "robomach/io/robot_config.h"
#include "robomach/io/polishing_files.h"
#include "robomach/report/heat_map.h"
#include "robomach/report/plot.h"

namespace robomach::apps {

polishing::NurbsSurface LoadSurface(const std::string& tool, const std::string& path, const SurfaceChoice& choice) {
  if (!io::IsCadFile(path)) {
    if (choice.face_given) {
      throw UsageError("--face " + std::to_string(choice.face) + ": " + path +
                       " is a NURBS YAML (one patch); --face picks a face of a STEP/IGES file");
    }
    if (choice.cad_unit_scale != 1.0) {
      throw UsageError("--cad-unit-scale: " + path + " is a NURBS YAML (lengths in mm by docs/formats.md §5); "
                       "the option applies to STEP/IGES files");
    }
    return io::ReadNurbsYaml(path);
  }
  io::CadReadOptions options;
  options.unit_scale = choice.cad_unit_scale;
  io::CadPartInfo info;
  polishing::NurbsSurface s = io::ReadCadFace(path, choice.face, options, &info);
  if (!info.unit_warning.empty()) Warn(tool, path + ": " + info.unit_warning);
  if (choice.face == 0 && s.trim()) {
    std::ostringstream m;
    m << "--face 0: " << s.trim()->source << ", the largest of " << info.num_faces << " faces by area ("
      << 1e6 * s.trim()->area << " mm^2); --list-faces lists them all";
    Note(tool, m.str());
  }
  return s;
}

void AddSurfaceChoiceOptions(CLI::App* app, SurfaceChoice* choice) {
  app->add_option("--face", choice->face,
                  "face of a STEP/IGES file (1-based, in the file's order; polish-plan --list-faces lists them); "
                  "0 or not given: the largest by area (named on stderr). An error with a YAML surface")
      ->capture_default_str();
  app->add_option("--cad-unit-scale", choice->cad_unit_scale,
                  "multiply a STEP/IGES file's lengths (as read in mm) by this: 1000 for a file that says mm but "
                  "holds metres (the reader warns when a part is under 1 mm or over 10 m)")
      ->capture_default_str();
}

std::vector<std::string> PicturePaths(const std::string& png, bool with_convergence) {
  const std::filesystem::path p(png);
  const std::string stem = (p.parent_path() / p.stem()).string();
  std::vector<std::string> out = {png, stem + "_histogram.png", stem + "_path.png"};
  if (with_convergence) out.push_back(stem + "_convergence.png");
  return out;
}

std::vector<std::string> WritePictures(const std::string& png, const polishing::SampleGrid& grid,
                                       const std::vector<double>& removal_m,
                                       const std::vector<polishing::PathRow>& rows,
                                       const std::vector<std::vector<Eigen::Vector2d>>& guide_lines_st,
                                       const std::vector<double>& history, const std::string& title,
                                       const std::vector<double>& evaluated) {
  const std::vector<std::string> files = PicturePaths(png, !history.empty());
  // Removal map (seed Fig. 19) on the developed plane.
  report::HeatMap map;
  map.title = title + ": removal";
  map.x_label = "s (arc length along u) [mm]";
  map.y_label = "t (arc length along v) [mm]";
  map.colorbar_label = "removal [um]";
  map.nan_label = "margin (not polished)";
  // Block-averaged to at most ~150 cells a side: the drawing costs per cell.
  const int f = std::max(1, static_cast<int>(std::ceil(std::max(grid.ns(), grid.nt()) / 150.0)));
  map.nx = (grid.ns() + f - 1) / f;
  map.ny = (grid.nt() + f - 1) / f;
  const double ds = 1e3 * grid.length_s() / std::max(1, grid.ns() - 1);
  const double dt = 1e3 * grid.length_t() / std::max(1, grid.nt() - 1);
  map.dx = ds * f;
  map.dy = dt * f;
  map.x0 = 0.5 * (f - 1) * ds;
  map.y0 = 0.5 * (f - 1) * dt;
  std::vector<double> sum(map.nx * map.ny, 0.0), cnt(map.nx * map.ny, 0.0);
  std::vector<double> region;
  for (int j = 0; j < grid.nt(); ++j) {
    for (int i = 0; i < grid.ns(); ++i) {
      const int k = grid.index(i, j);
      if (!grid.in_region()[k]) continue;
      const int c = (j / f) * map.nx + i / f;
      sum[c] += 1e6 * removal_m[k];
      cnt[c] += 1.0;
      region.push_back(1e6 * removal_m[k]);
    }
  }
  map.values.assign(map.nx * map.ny, std::nan(""));
  for (size_t c = 0; c < sum.size(); ++c)
    if (cnt[c] > 0) map.values[c] = sum[c] / cnt[c];
  if (f > 1) map.title += " (" + std::to_string(f) + " x " + std::to_string(f) + " point averages)";
  report::SaveHeatMapPng(map, files[0]);
  // Histogram (seed Fig. 20).
  report::Figure hist(1, 1, 900, 420);
  hist.title = title + ": removal histogram";
  auto& ax = hist.at(0, 0);
  ax.x_label = "removal [um]";
  ax.y_label = "fraction of sample points [%]";
  if (!region.empty()) {
    const double lo = *std::min_element(region.begin(), region.end());
    const double hi = *std::max_element(region.begin(), region.end());
    const int bins = 40;
    const double w = (hi - lo) > 0 ? (hi - lo) / bins : 1.0;
    std::vector<double> count(bins, 0.0);
    for (double x : region) count[std::min(bins - 1, static_cast<int>((x - lo) / w))] += 100.0 / region.size();
    report::Series s;
    s.color = report::PaletteColor(0);
    for (int b = 0; b < bins; ++b) {  // bars as outlines
      s.x.insert(s.x.end(), {lo + b * w, lo + b * w, lo + (b + 1) * w, lo + (b + 1) * w});
      s.y.insert(s.y.end(), {0.0, count[b], count[b], 0.0});
    }
    ax.series.push_back(s);
    ax.y_min = 0.0;
  }
  hist.SavePng(files[1]);
  // Path with guide lines (seed Fig. 18) in the developed plane, as the
  // removal map: an x-y view says little about a steep or wrapped face.
  report::Figure fp(1, 1, 900, 700);
  fp.title = title + ": path (developed plane)";
  auto& a2 = fp.at(0, 0);
  a2.x_label = "s (arc length along u) [mm]";
  a2.y_label = "t (arc length along v) [mm]";
  auto s_mm = [&](const polishing::PathRow& r) { return 1e3 * grid.SOfU(r.u); };
  auto t_mm = [&](const polishing::PathRow& r) { return 1e3 * grid.TOfV(r.v); };
  // One series per stretch in contact (blue) or lifted (rows with force 0,
  // thin grey dashes); a segment belongs to the stretch of its first row.
  bool labelled[2] = {false, false};
  for (size_t i = 0; i < rows.size();) {
    const bool lifted = rows[i].force == 0.0;
    report::Series s;
    size_t j = i;
    while (j < rows.size() && (rows[j].force == 0.0) == lifted) {
      s.x.push_back(s_mm(rows[j]));
      s.y.push_back(t_mm(rows[j]));
      ++j;
    }
    if (lifted && j < rows.size()) {  // the lifted move ends where the tool sets down
      s.x.push_back(s_mm(rows[j]));
      s.y.push_back(t_mm(rows[j]));
    }
    if (lifted && s.x.size() > 2) {
      // A lift is straight in the developed plane: its ends draw it, and the
      // dashes stay visible (rows every 0.5 mm would draw it solid).
      s.x = {s.x.front(), s.x.back()};
      s.y = {s.y.front(), s.y.back()};
    }
    if (s.x.size() >= 2) {
      s.label = labelled[lifted] ? "" : (lifted ? "lifted" : "contact path");
      s.color = lifted ? report::Rgb{150, 150, 150} : report::PaletteColor(0);
      s.thickness = 1;
      s.dashed = lifted;
      labelled[lifted] = true;
      a2.series.push_back(s);
    }
    i = j;
  }
  for (size_t g = 0; g < guide_lines_st.size(); ++g) {
    report::Series s;
    s.label = g == 0 ? "guide lines" : "";
    s.color = report::PaletteColor(1);
    s.dashed = true;
    for (const auto& p : guide_lines_st[g]) {
      s.x.push_back(1e3 * p.x());
      s.y.push_back(1e3 * p.y());
    }
    a2.series.push_back(s);
  }
  fp.SavePng(files[2]);
  if (!history.empty()) {
    report::Figure fc(1, 1, 900, 420);
    fc.title = title + ": optimiser convergence";
    auto& a3 = fc.at(0, 0);
    a3.x_label = "iteration / evaluation";
    a3.y_label = "cv of removal";
    a3.log_y = true;  // the best is 10-100 x below the first and the worst evaluations
    if (!evaluated.empty()) {
      report::Series e;
      e.color = report::PaletteColor(0);
      e.markers = true;
      e.label = "cv of each feasible evaluation";
      for (size_t i = 0; i < evaluated.size(); ++i) {
        if (!std::isfinite(evaluated[i])) continue;
        e.x.push_back(static_cast<double>(i + 1));
        e.y.push_back(evaluated[i]);
      }
      a3.series.push_back(e);
    }
    report::Series s;
    s.color = report::PaletteColor(2);
    s.label = evaluated.empty() ? "" : "best so far";
    for (size_t i = 0; i < history.size(); ++i) {
      if (!std::isfinite(history[i])) continue;  // before the first feasible evaluation
      s.x.push_back(static_cast<double>(i + 1));
      s.y.push_back(history[i]);
    }
    a3.series.push_back(s);
    fc.SavePng(files[3]);
  }
  return files;
}

}  // namespace robomach::apps

#include "robomach/common/units.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/number_format.h"
#include "robomach/workflows/polish_robot_check.h"

namespace robomach::apps {

void RobotOptions::Add(CLI::App* app) {
  app->add_option("--robot", robot_path_, "robot config YAML: solve the IK of every tool frame, flag unreachable rows, "
                                          "joint-limit and singularity margins (summary 'robot' block)");
  app->add_option("--part-frame-mm-deg", part_frame_text_, "with --robot: the surface's frame in the robot base, "
                                                           "x,y,z [mm], rx,ry,rz [deg] about fixed x, y, z")
      ->capture_default_str();
  app->add_option("--robot-seed-deg", seed_text_, "with --robot: IK start of the first row [deg]")->capture_default_str();
  app->add_option("--joints", joints_out_,
                  "with --robot: joint trajectory CSV t_s,q1_deg..,reachable,limit_margin_deg,jacobian_condition");
}

void RobotOptions::Prepare(std::vector<std::pair<std::string, std::string>>* outs) {
  outs->push_back({"--joints", joints_out_});
  if (!joints_out_.empty() && robot_path_.empty()) throw UsageError("--joints needs --robot");
  part_ = ParseNumberList("--part-frame-mm-deg", part_frame_text_);
  seed_deg_ = ParseNumberList("--robot-seed-deg", seed_text_);
  if (part_.size() != 6) throw UsageError("--part-frame-mm-deg: expected x,y,z,rx,ry,rz (6 numbers)");
  if (robot_path_.empty()) return;
  RequireReadableFile(robot_path_, "robot config");
  robot_ = io::LoadRobotConfig(robot_path_).Build();
  if (static_cast<int>(seed_deg_.size()) != robot_->num_joints()) {
    throw UsageError("--robot-seed-deg: expected " + std::to_string(robot_->num_joints()) + " angles");
  }
}

bool RobotOptions::Check(const std::string& tool, const polishing::PolishingProcess& process,
                         const std::vector<polishing::PathRow>& rows, nlohmann::json* summary) {
  if (!robot_) return false;
  Eigen::VectorXd q0(robot_->num_joints());
  for (int j = 0; j < q0.size(); ++j) q0(j) = DegToRad(seed_deg_[j]);
  check_ = workflows::CheckPolishPathOnRobot(*robot_, workflows::PartFrameFromMmDeg(part_), process, rows, q0);
  (*summary)["robot"] = workflows::PolishRobotSummaryJson(rows, check_);
  const RunFindings verdict = workflows::JudgePolishPathOnRobot(check_);
  for (const Finding& f : verdict.findings) Warn(tool, f.message);
  return verdict.flagged();
}

void RobotOptions::WriteJoints(const std::vector<polishing::PathRow>& rows) const {
  if (robot_ && !joints_out_.empty()) io::WriteJointTrajectoryCsv(joints_out_, rows, check_, robot_->num_joints());
}

}  // namespace robomach::apps
