#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "robomach/common/errors.h"
#include "robomach/dynamics/joint_plausibility.h"
#include "robomach/dynamics/parameters.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/io/yaml_doc.h"

namespace robomach::io {

/// A robot config file read into a description and its parameter values.
struct RobotConfig {
  dynamics::RobotDescription description;
  dynamics::ParameterSet parameters;   // defaults, then the file's `parameters:` overrides
  std::string path;
  /// "implausible (unit mistake?): file:line:col: ..." for each value outside
  /// its plausible range below (docs/plausibility.md): a tool prints them and
  /// flags its result (exit 3). The joints' plausibility (frequencies, sag
  /// under the robot's weight, damping ratio) is the model's, not the
  /// reader's: workflows::LoadRobotConfigChecked appends it
  /// (dynamics::JointPlausibilityFindings).
  std::vector<std::string> implausible;
  /// Where the joint stiffnesses and the damping were typed, for the joints'
  /// plausibility findings.
  dynamics::JointValueLocations joint_value_locations;
  /// Where each of `description.extra_values` was typed (the numbers of
  /// `spindle_toolholder_interface` and `hammer_test`), so that a tool that
  /// refuses one of them can name its file:line:col.
  std::map<std::string, SourceLocation> extra_value_locations;
  /// `uncertainty: [files]`: parameter-uncertainty files (formats.md §12,
  /// kq-identify --uncertainty-out), resolved against the config's folder;
  /// the predicting tools use them when --uncertainty is not given.
  std::vector<std::string> uncertainty_files;
  std::shared_ptr<const dynamics::RobotModel> Build() const {
    return dynamics::RobotModel::Build(description, parameters);
  }
};

// Plausible ranges of a robot config's values (docs/plausibility.md): wide,
// so that no real robot is flagged, and each names the likely unit mistake.
// Sources: manufacturers' data sheets (KUKA KR 1000 titan: 4.7 t in all, a
// reach of 3.2 m; the longest arms reach about 4 m); joint stiffnesses of
// industrial robots 1e4 to 1e7 N·m/rad (Dumas, Caro, Garnier and Furet,
// Robot. CIM 27 (2011); the seed's KR 210: 1.9e5 to 4.3e6), of small arms
// down to 1e3; first modes of robots 5 to 50 Hz and wrist modes to a few
// hundred Hz, damping ratios 0.01 to 0.1 (Cordes, Hintze and Altintas,
// Robot. CIM 55 (2019); Tunc and Stoddart, IJAMT 89 (2017)).
inline constexpr double kMaxPlausibleBodyMassKg = 5000.0;      // a link or end-effector body
inline constexpr double kMaxPlausibleRobotLengthM = 10.0;      // |each component| of a length
inline constexpr double kMinPlausibleJointStiffnessNmPerRad = 100.0;
inline constexpr double kMaxPlausibleJointStiffnessNmPerRad = 1e9;
// The joints' frequency, sag and damping ranges are the model's
// (dynamics/joint_plausibility.h).

// Plausible ranges of the `spindle_toolholder_interface` section (the
// spindle_interface effect, docs/model.md) and of `hammer_test`. Practice:
// hollow-taper holders HSK-25 to HSK-160 (ISO 12164-1, DIN 69893: taper
// large diameters 19 - 120 mm, taper lengths about 10 - 80 mm, taper 1:10)
// and steep-taper holders SK/BT/CAT 30 - 60 (ISO 7388-1, JIS B 6339: large
// diameters 31.75 - 107.95 mm, tapers up to about 170 mm long, taper 7:24 =
// 0.29); drawbar (clamping) forces of spindles from about 3 kN (HSK-E25) to
// 45 kN (HSK-A100) and 25 - 60 kN (SK/BT 50) by clamping-unit catalogues
// (OTT-JAKOB, Roehm; figures recalled, not re-checked); Yoshimura's
// unit-area law k_n = alpha' p^beta' (p in Pa, k_n in N/m³): beta' 0.3 - 1
// for machined steel joints, the seed's alpha' 3.3e6 with beta' 0.604
// (Yoshimura, "Computer-aided design improvement of machine tool structure
// incorporating joint dynamics data", CIRP Annals 28/1 (1979)); dry steel
// on steel friction 0.1 - 0.8 (Machinery's Handbook, 30th ed., friction
// tables); hammer-test acquisition at 1 - 200 kHz (the seed's 5120 Hz).
// A taper diameter or length in mm under its `_m` key is 1000 times the
// range, a drawbar force in kN 1000 times below it.
inline constexpr double kMinPlausibleTaperDiameterM = 0.01;
inline constexpr double kMaxPlausibleTaperDiameterM = 0.2;
inline constexpr double kMinPlausibleTaperLengthM = 0.005;
inline constexpr double kMaxPlausibleTaperLengthM = 0.2;
/// Diameter change per length: 1:50 to 1:1 (HSK 0.1, SK/BT 7:24 = 0.29).
inline constexpr double kMinPlausibleTaperRatio = 0.02;
inline constexpr double kMaxPlausibleTaperRatio = 1.0;
inline constexpr double kMinPlausibleDrawbarForceN = 500.0;
inline constexpr double kMaxPlausibleDrawbarForceN = 1e6;
inline constexpr double kMaxPlausibleFrictionCoefficient = 2.0;
inline constexpr double kMinPlausibleYoshimuraAlpha = 1e3;   // alpha' [N/m³ per Pa^beta']
inline constexpr double kMaxPlausibleYoshimuraAlpha = 1e10;
inline constexpr double kMinPlausibleYoshimuraBeta = 0.1;
inline constexpr double kMaxPlausibleYoshimuraBeta = 1.5;
inline constexpr double kMinPlausibleTangentialToNormal = 0.05;
inline constexpr double kMaxPlausibleTangentialToNormal = 2.0;
/// `elements` (rings of the taper): refused outside [1, kMaxTaperElements].
inline constexpr int kMaxTaperElements = 1000;
inline constexpr double kMinPlausibleHammerSampleRateHz = 100.0;
inline constexpr double kMaxPlausibleHammerSampleRateHz = 1e6;

/// Reads a robot config (see config/kr210.yaml for the documented schema):
/// `robot:` with `urdf`, `base_link`, `tip_frame` (and optional
/// `joint_names`), or `dh:` with a modified-DH table; `joint_stiffness_Nm_per_rad`;
/// `damping` (`alpha_s`, `beta_per_s`); `end_effector` (bodies in the tip
/// frame, `tcp_m`, `spindle_nose_m`, and the reference `m6_kg`, `d6_m`,
/// which must agree with the geometry); optional
/// `spindle_toolholder_interface`, `hammer_test`, `effects` and
/// `parameters` (values by parameter name, as calibration writes them).
/// Unknown keys are rejected. Paths are relative to the config's folder.
/// Values outside the plausible ranges above (masses, lengths, joint
/// stiffnesses; DH angles that look like radians) are listed in
/// RobotConfig::implausible; the joints' frequencies, sag and damping ratios
/// are not judged here (workflows::LoadRobotConfigChecked does).
/// @throws InputError with `file:line:col` for any problem; a refused value
///   1000 times its reference (m6_kg, d6_m, a `parameters:` value) names the
///   unit mistake.
RobotConfig LoadRobotConfig(const std::string& path);

/// The kinematic chain of a config's `robot:` section (URDF or `dh:`, as
/// LoadRobotConfig reads it); `path` is the config file, for relative paths.
/// Used by readers of other robot files (drilling's flexible-joint robot).
/// When `implausible` is given, it receives the unit findings of a `dh:`
/// table (masses, lengths, angles that look like radians).
/// @throws InputError with `file:line:col` for any problem.
kinematics::SerialChain ReadRobotChain(const YamlDoc& robot, const std::string& path,
                                       std::vector<std::string>* implausible = nullptr);

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
