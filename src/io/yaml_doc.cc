#include "robomach/io/yaml_doc.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include "robomach/common/closest_name.h"
#include "robomach/io/csv_table.h"

namespace robomach::io {

YamlDoc::YamlDoc(YAML::Node node, std::shared_ptr<const std::string> path, std::string key_path)
    : node_(std::move(node)),
      path_(std::move(path)),
      key_path_(std::move(key_path)),
      used_keys_(std::make_shared<std::vector<std::string>>()) {}

YamlDoc YamlDoc::LoadFile(const std::string& path, const std::string& expected) {
  RequireFileKind(path, {FileKind::kYaml}, expected);
  std::ifstream in(path);
  if (!in) throw MissingFileError({path, 0, 0}, "cannot open file for reading");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return LoadString(text, path);
}

namespace {

// yaml-cpp keeps the first of two equal keys in a map and drops the other
// without a word; a config edited by hand must not change meaning that way.
// A key must be a plain name: a list, map or empty key ("? [a, b]: 1")
// threw yaml-cpp's TypedBadConversion where the readers list the keys
// (issue #22, found by fuzz_nurbs_yaml).
void RejectDuplicateKeys(const YAML::Node& node, const std::string& path) {
  if (node.IsMap()) {
    std::map<std::string, YAML::Mark> seen;
    for (const auto& kv : node) {
      if (!kv.first.IsScalar()) {
        const YAML::Mark m = kv.first.Mark();
        throw InputError({path, m.line + 1, m.column + 1},
                         std::string("expected a key name, got ") +
                             (kv.first.IsMap() ? "a map" : kv.first.IsSequence() ? "a list" : "an empty key"));
      }
      if (kv.first.IsScalar()) {
        const std::string key = kv.first.Scalar();
        const auto [it, fresh] = seen.emplace(key, kv.first.Mark());
        if (!fresh) {
          const YAML::Mark m = kv.first.Mark();
          throw InputError({path, m.line + 1, m.column + 1},
                           "key '" + key + "' appears twice (first on line " +
                               std::to_string(it->second.line + 1) + ")");
        }
      }
      RejectDuplicateKeys(kv.second, path);
    }
  } else if (node.IsSequence()) {
    for (const auto& item : node) RejectDuplicateKeys(item, path);
  }
}

}  // namespace

namespace {

// YAML indents with spaces only; yaml-cpp's answer to a tab ("illegal tab
// when looking for indentation", or a key silently taken into the value
// before it) does not lead to the fix (issue #35). A line whose indentation
// holds a tab is refused at the tab, except comment lines.
void RejectTabIndentation(const std::string& text, const std::string& path) {
  size_t line = 1;
  for (size_t pos = 0; pos < text.size();) {
    size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    const size_t first = text.find_first_not_of(" \t", pos);
    if (first < end && text[first] != '#' && text[first] != '\r') {
      const size_t tab = text.find('\t', pos);
      if (tab < first) {
        throw InputError({path, static_cast<int>(line), static_cast<int>(tab - pos + 1)},
                         "a tab in the indentation: YAML is indented with spaces only; indent with spaces");
      }
    }
    pos = end + 1;
    ++line;
  }
}

}  // namespace

YamlDoc YamlDoc::LoadString(const std::string& text, const std::string& path) {
  RejectTabIndentation(text, path);
  try {
    YAML::Node root = YAML::Load(text);
    RejectDuplicateKeys(root, path);
    return YamlDoc(root, std::make_shared<const std::string>(path), "");
  } catch (const YAML::Exception& e) {
    throw InputError({path, e.mark.line + 1, e.mark.column + 1},
                     "not valid YAML: " + e.msg);
  }
}

SourceLocation YamlDoc::location() const {
  if (!node_ || node_.Mark().is_null()) return {*path_, 0, 0};
  const YAML::Mark m = node_.Mark();
  return {*path_, m.line + 1, m.column + 1};
}

InputError YamlDoc::Error(const std::string& message) const {
  const std::string prefix = key_path_.empty() ? "" : key_path_ + ": ";
  return InputError(location(), prefix + message);
}

bool YamlDoc::Has(const std::string& key) const {
  return node_.IsMap() && node_[key] && !node_[key].IsNull();
}

YamlDoc YamlDoc::operator[](const std::string& key) const {
  if (!node_.IsMap()) throw Error("expected a map with key '" + key + "'");
  used_keys_->push_back(key);
  YAML::Node child = node_[key];
  if (!child) {
    // A key of the map that is close to the one missing is most likely it,
    // mistyped: that key's place and name (issue #35).
    // Keys read already are not the one mistyped.
    std::vector<std::string> present;
    for (const auto& kv : node_) {
      if (kv.first.IsScalar() &&
          std::find(used_keys_->begin(), used_keys_->end(), kv.first.Scalar()) == used_keys_->end()) {
        present.push_back(kv.first.Scalar());
      }
    }
    const std::string closest = ClosestName(key, present);
    if (!closest.empty()) {
      for (const auto& kv : node_) {
        if (kv.first.IsScalar() && kv.first.Scalar() == closest) {
          const YAML::Mark km = kv.first.Mark();
          throw InputError({*path_, km.line + 1, km.column + 1},
                           "missing key '" + key + "'" + (key_path_.empty() ? "" : " in '" + key_path_ + "'") +
                               "; the file has '" + closest + "' here: mistyped?");
        }
      }
    }
    throw InputError(location(), "missing key '" + key + "'" +
                                     (key_path_.empty() ? "" : " in '" + key_path_ + "'") +
                                     (key_path_.empty() ? OtherYamlKind(key) : ""));
  }
  return YamlDoc(child, path_, key_path_.empty() ? key : key_path_ + "." + key);
}

std::string YamlDoc::OtherYamlKind(const std::string& missing) const {
  // robomach's YAML files by the top-level keys only each has (the shipped
  // examples in config/): a missing key at the top that the file's own kind
  // does not have is the file given to another option (drill-sim --robot
  // config/kr210.yaml: "missing key 'flexible_joints'").
  if (!node_.IsMap()) return "";
  const auto has = [&](const char* k) { return static_cast<bool>(node_[k]); };
  // A tool's JSON summary (JSON is YAML): every one has these two keys.
  if (has("tool") && has("robomach_version") && node_["tool"].IsScalar()) {
    return "; this is the JSON summary of " + node_["tool"].as<std::string>() +
           " (its --summary), not the file this option takes";
  }
  // kq-identify writes two files: the stiffness to paste (--out) and its
  // uncertainty (--uncertainty-out); the first given for the second.
  if (missing == "parameter_uncertainty" && (has("joint_stiffness_Nm_per_rad") || has("parameters")) &&
      !has("robot") && !has("urdf") && !has("dh")) {
    return "; this is kq-identify's --out (the stiffness to paste into the robot config): --uncertainty takes the "
           "file kq-identify writes with --uncertainty-out (docs/formats.md §12)";
  }
  struct Kind {
    bool match;
    const char* what;
    std::vector<std::string> keys;  // the kind's own top-level keys
  };
  const Kind kinds[] = {
      {has("flexible_joints"), "a flexible-joint robot for drill-sim --robot (config/drilling/planar3r.yaml)",
       {"robot", "flexible_joints", "dh"}},
      {has("joint_stiffness_Nm_per_rad") || has("end_effector"), "a robot config (config/kr210.yaml)",
       {"robot", "joint_stiffness_Nm_per_rad", "damping", "end_effector", "spindle_toolholder_interface",
        "hammer_test", "parameters", "effects", "urdf", "dh", "uncertainty"}},
      {has("drill") && has("process"), "a drill file for drill-sim --drill (config/drilling/drill_5mm.yaml)",
       {"drill", "process", "offset", "simulation"}},
      {has("material"), "a material file (config/drilling/q235.yaml)", {"material", "std_dev", "fit", "table"}},
      {has("axes") && has("kinematics"), "a machine file (config/machine/dmu80p.yaml)",
       {"axes", "kinematics", "controller_axes", "errors"}},
      {has("cutting_coefficients"), "a cut file for stability-lobes and stability-map --cut (config/cut_demo.yaml)",
       {"diameter_mm", "teeth", "radial_immersion", "milling", "feed_direction", "feed_per_tooth_mm",
        "cutting_coefficients", "spindle_speed_min_rpm", "spindle_speed_max_rpm", "spindle_speed_count",
        "spindle_speed_rpm"}},
      {has("origin_mm") && has("grid_step_mm"), "a region file for stability-map --region (config/region_demo.yaml)",
       {"origin_mm", "u_axis", "v_axis", "size_mm", "grid_step_mm", "tool_axis", "rotation_about_tool_axis",
        "seed_posture_deg"}},
      {has("nurbs"), "a NURBS surface for polish-plan --surface (config/polishing/dome.yaml)", {"nurbs"}},
      {has("parameter_uncertainty"), "a parameter-uncertainty file for --uncertainty (docs/formats.md §12)",
       {"parameter_uncertainty"}},
      {has("tool") && has("workpiece"), "a polishing process for --process (config/polishing/belt_2N.yaml)",
       {"tool", "workpiece", "process", "robot"}},
  };
  for (const Kind& k : kinds) {
    if (!k.match) continue;
    if (std::find(k.keys.begin(), k.keys.end(), missing) != k.keys.end()) return "";  // its own kind, incomplete
    return "; the file's keys are those of " + std::string(k.what) + ": the file for another option?";
  }
  return "";
}

std::vector<std::string> YamlDoc::Keys() const {
  std::vector<std::string> keys;
  if (!node_.IsMap()) throw Error("expected a map");
  for (const auto& kv : node_) keys.push_back(kv.first.as<std::string>());
  return keys;
}

int YamlDoc::size() const {
  if (!node_.IsSequence()) throw Error("expected a list");
  return static_cast<int>(node_.size());
}

YamlDoc YamlDoc::at(int index) const {
  if (!node_.IsSequence()) throw Error("expected a list");
  return YamlDoc(node_[index], path_, key_path_ + "[" + std::to_string(index) + "]");
}

double YamlDoc::Number() const {
  if (!node_.IsScalar()) throw Error("expected a number");
  double v = 0.0;
  if (!ParseFiniteNumber(node_.Scalar(), &v)) {
    throw Error("expected a finite number, got \"" + node_.Scalar() + "\"");
  }
  return v;
}

double YamlDoc::PositiveNumber() const {
  const double v = Number();
  if (!(v > 0.0)) throw Error("expected a number > 0, got " + node_.Scalar());
  return v;
}

double YamlDoc::NumberInRange(double lo, double hi, bool include_lo, bool include_hi) const {
  const double v = Number();
  const bool ok_lo = include_lo ? v >= lo : v > lo;
  const bool ok_hi = include_hi ? v <= hi : v < hi;
  if (!ok_lo || !ok_hi) {
    throw Error("expected a number in " + std::string(include_lo ? "[" : "(") +
                std::to_string(lo) + ", " + std::to_string(hi) + (include_hi ? "]" : ")") +
                ", got " + node_.Scalar());
  }
  return v;
}

namespace {
constexpr double kMaxWholeNumber = 1e9;  // every count robomach reads is far below
}  // namespace

int YamlDoc::Int() const {
  const double v = Number();
  if (v != std::floor(v)) throw Error("expected a whole number, got " + node_.Scalar());
  if (std::abs(v) > kMaxWholeNumber) {
    // A whole number, but too large (issue #35: it said "expected a whole
    // number" of 2000000000).
    throw Error(node_.Scalar() + " is too large: expected a whole number of at most 1000000000 in magnitude");
  }
  return static_cast<int>(v);
}

int YamlDoc::IntInRange(int lo, int hi) const {
  const double v = Number();
  if (v != std::floor(v)) throw Error("expected a whole number, got " + node_.Scalar());
  if (v < lo || v > hi) {
    throw Error(node_.Scalar() + " is too " + (v > hi ? "large" : "small") + ": expected a whole number in [" +
                std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
  return static_cast<int>(v);
}

bool YamlDoc::Bool() const {
  if (node_.IsScalar()) {
    const std::string& s = node_.Scalar();
    if (s == "true" || s == "yes" || s == "on") return true;
    if (s == "false" || s == "no" || s == "off") return false;
  }
  throw Error("expected true or false");
}

std::string YamlDoc::String() const {
  if (!node_.IsScalar()) throw Error("expected a text value");
  return node_.Scalar();
}

std::vector<double> YamlDoc::Numbers(int expected_size) const {
  if (!node_.IsSequence()) throw Error("expected a list of numbers");
  if (expected_size >= 0 && static_cast<int>(node_.size()) != expected_size) {
    throw Error("expected a list of " + std::to_string(expected_size) + " numbers, got " +
                std::to_string(node_.size()));
  }
  std::vector<double> out;
  for (int i = 0; i < static_cast<int>(node_.size()); ++i) out.push_back(at(i).Number());
  return out;
}

std::vector<std::string> YamlDoc::Strings() const {
  if (!node_.IsSequence()) throw Error("expected a list of names");
  std::vector<std::string> out;
  for (int i = 0; i < static_cast<int>(node_.size()); ++i) out.push_back(at(i).String());
  return out;
}

void YamlDoc::MarkUsed(const std::string& key) const { used_keys_->push_back(key); }

void YamlDoc::RejectUnknownKeys() const {
  if (!node_.IsMap()) return;
  for (const auto& kv : node_) {
    const std::string key = kv.first.as<std::string>();
    if (std::find(used_keys_->begin(), used_keys_->end(), key) != used_keys_->end()) continue;
    std::string known;
    std::vector<std::string> sorted = *used_keys_;
    std::sort(sorted.begin(), sorted.end());
    sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
    for (const auto& k : sorted) known += (known.empty() ? "" : ", ") + k;
    const std::string closest = ClosestName(key, sorted);
    const YAML::Mark m = kv.first.Mark();
    throw InputError({*path_, m.line + 1, m.column + 1},
                     "unknown key '" + key + "'" +
                         (key_path_.empty() ? "" : " in '" + key_path_ + "'") +
                         (closest.empty() ? "; known keys: " : "; did you mean '" + closest + "'? Known keys: ") +
                         known);
  }
}

std::string ResolveRelative(const std::string& config_path, const std::string& relative) {
  namespace fs = std::filesystem;
  const fs::path rel(relative);
  if (rel.is_absolute()) return relative;
  const fs::path base = fs::path(config_path).parent_path();
  return (base / rel).lexically_normal().string();
}

std::string RebaseRelative(const std::string& config_path, const std::string& path,
                           const std::string& output_path) {
  namespace fs = std::filesystem;
  if (fs::path(path).is_absolute()) return path;
  const fs::path target = fs::absolute(ResolveRelative(config_path, path)).lexically_normal();
  const fs::path out_dir = fs::absolute(output_path).parent_path().lexically_normal();
  const fs::path rel = target.lexically_relative(out_dir);
  return rel.empty() ? target.string() : rel.string();
}

}  // namespace robomach::io
