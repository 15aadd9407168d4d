// tracker-synth: simulates a laser-tracker load-test campaign from a robot
// config and writes it in the tracker format (docs/formats.md §2), to rehearse a
// campaign or to test kq-identify.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <iostream>

#include "cli_support.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/tracker_file.h"
#include "robomach/report/json.h"
#include "robomach/workflows/tracker_synth.h"

namespace robomach::apps {
namespace {

constexpr char kTool[] = "tracker-synth";

int Run(int argc, char** argv) {
  CLI::App app{
      "tracker-synth: simulate a laser-tracker load-test campaign (docs/formats.md §2).\n"
      "For every posture, pulley and mass: the static deflection of the target under the rope\n"
      "force (large-displacement equilibrium with the config's joint stiffness), tracker readings\n"
      "with Gaussian noise, optional gross outliers. Seeded: the same options give the same file."};
  AddVersionFlag(app, kTool);
  app.footer(ExitCodeHelp());
  std::string out_path, summary_path, load_point = workflows::kDefaultLoadPointMm, target = workflows::kDefaultTargetMm;
  workflows::TrackerSynthOptions o;
  app.add_option("--robot", o.robot_path, "robot config YAML; its joint stiffness is the truth")->required();
  app.add_option("--out", out_path, "tracker CSV to write (stdout if omitted or '-')");
  app.add_option("--summary", summary_path,
                 "summary JSON (docs/formats.md §4.1): inputs, load cases, outliers, the true joint stiffness, "
                 "deflections; '-' = stdout");
  app.add_option("--postures", o.postures_path, "posture file CSV (docs/formats.md §1); default: random postures");
  app.add_option("--plan-file", o.plan_path,
                 "a plan from kq-identify --plan: its postures and pulleys (and load point and target "
                 "unless given here)");
  app.add_option("--num-postures", o.num_postures, "number of random postures (without --postures)")
      ->capture_default_str();
  app.add_option("--min-reach-mm", o.min_reach_mm,
                 "random postures: least horizontal distance of the load point from the base axis [mm]")
      ->capture_default_str();
  app.add_option("--masses-kg", o.masses_kg, "masses hung at every posture and pulley [kg]")->capture_default_str();
  app.add_option("--pulley-mm", o.pulley_mm, "pulley position x,y,z in the base frame [mm], one per rope direction")
      ->capture_default_str();
  app.add_option("--load-point-mm", load_point, "load point x,y,z in the tip frame [mm], or tcp")
      ->capture_default_str();
  app.add_option("--target-mm", target, "tracker target x,y,z in the tip frame [mm], or tcp")->capture_default_str();
  app.add_option("--noise-mm", o.noise_mm, "tracker noise, 1 sigma per coordinate [mm]")->capture_default_str();
  app.add_option("--outliers", o.outliers, "number of cases with a gross error")->capture_default_str();
  app.add_option("--outlier-mm", o.outlier_mm, "size of that error [mm]")->capture_default_str();
  app.add_option("--form", o.form, "load columns: rope (mass_kg + rope points) or force (fx_N..fz_N)")
      ->check(OneOf({"rope", "force"}))
      ->capture_default_str();
  app.add_option("--seed", o.seed, "random seed (postures, noise, outliers)")->capture_default_str();
  app.add_option("--set", o.sets, "override a model parameter of the truth, NAME=VALUE (e.g. kq3_Nm_per_rad=4e6)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }

  return RunGuarded(kTool, [&]() -> int {
    const std::vector<FieldSource> fields = {
        {"noise_mm", "--noise-mm"},       {"outliers", "--outliers"},           {"num_postures", "--num-postures"},
        {"outlier_mm", "--outlier-mm"},   {"sets", "--set"},                    {"masses_kg", "--masses-kg"},
        {"pulley_mm", "--pulley-mm"},     {"load_point_mm", "--load-point-mm"}, {"target_mm", "--target-mm"},
        {"plan_path", "--plan-file"},     {"postures_path", "--postures"},      {"form", "--form"},
        {"min_reach_mm", "--min-reach-mm"}};
    for (const FieldSource& f : fields) o.names[f.field] = f.name;
    FromFields(fields, [&] { o.Validate(); });
    RequireReadableFile(o.robot_path, "robot config");
    if (!o.postures_path.empty()) RequireReadableFile(o.postures_path, "posture file");
    CheckDistinctPaths({{"--robot", o.robot_path}, {"--postures", o.postures_path}, {"--plan-file", o.plan_path}},
                       {{"--out", out_path}, {"--summary", summary_path}});
    if (!o.plan_path.empty()) RequireReadableFile(o.plan_path, "plan file");
    // Given or not decides whether a plan's own load point and target count.
    if (app.count("--load-point-mm") > 0) o.load_point_mm = load_point;
    if (app.count("--target-mm") > 0) o.target_mm = target;
    const workflows::TrackerSynthRun run =
        FromFields(fields, [&] { return workflows::RunTrackerSynth(o, MessagePrinter(kTool)); });
    io::WriteTrackerFile(out_path.empty() ? "-" : out_path, run.measurements, run.Metadata(o));
    if (!summary_path.empty()) {
      nlohmann::json j = run.Summary(o);
      j["tool"] = kTool;
      j["out"] = out_path.empty() ? "-" : out_path;
      io::WriteFileAtomically(summary_path, SummaryText(j));
    }
    std::cerr << kTool << ": " << run.CountsLine() << "\n";
    return ExitCodeFor(run.status());
  });
}

}  // namespace
}  // namespace robomach::apps

int main(int argc, char** argv) { return robomach::apps::Run(argc, argv); }
