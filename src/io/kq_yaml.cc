#include "robomach/io/kq_yaml.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <regex>
#include <sstream>

#include "robomach/common/errors.h"
#include "robomach/io/number_format.h"
#include "robomach/io/yaml_doc.h"

namespace robomach::io {
namespace {

std::string Sci(double v, int digits = 4) {
  if (!std::isfinite(v)) return v > 0 ? "inf" : "nan";
  std::ostringstream s;
  s << std::scientific << std::setprecision(digits) << v;
  return s.str();
}

// Five significant digits are far below the identification's uncertainty
// (>= 1e-3 relative), so the pasted value loses nothing that is known.
std::string Value(double v) {
  std::ostringstream s;
  s << std::setprecision(5) << std::scientific << v;
  return s.str();
}

}  // namespace

void KqYamlOptions::Validate() const {
  for (const std::string& c : header_comments) {
    if (c.find_first_of("\r\n") != std::string::npos) {
      throw OptionError("header_comments", "header_comments: expected one line per comment (no line break), got \"" +
                                               EscapeInvalidUtf8(c) + "\"");
    }
  }
}

std::string JointStiffnessYaml(const identification::JointStiffnessResult& r,
                               const KqYamlOptions& o) {
  o.Validate();
  using identification::Determination;
  std::ostringstream s;
  for (const auto& c : o.header_comments) s << "# " << c << "\n";
  s << "# status: " << robomach::ToString(r.status) << "; " << r.num_cases
    << " load cases; RMS residual " << std::fixed << std::setprecision(4) << 1e3 * r.rms_residual
    << " mm; condition number " << std::setprecision(1) << r.condition_number << "\n";
  s << "# joint  stiffness [N·m/rad]  std dev      95 % interval                 determination\n";
  for (int j = 0; j < r.num_joints; ++j) {
    s << "#   " << j + 1 << "    " << Sci(r.joint_stiffness(j)) << "         " << Sci(r.std_dev(j), 2)
      << "     [" << Sci(r.lower_95(j), 3) << ", " << Sci(r.upper_95(j), 3) << "]   "
      << identification::ToString(r.determination[j])
      << (r.determination[j] == Determination::kNotDetermined ? " (value kept from the robot config)" : "")
      << "\n";
  }
  s << "# correlation of the stiffnesses:\n";
  for (int a = 0; a < r.num_joints; ++a) {
    s << "#  ";
    for (int b = 0; b < r.num_joints; ++b) {
      const double c = r.correlation(a, b);
      std::ostringstream cell;
      if (std::isfinite(c)) cell << std::fixed << std::setprecision(3) << std::showpos << c;
      else cell << "   -  ";
      s << " " << std::setw(6) << cell.str();
    }
    s << "\n";
  }
  for (const auto& a : r.advice) s << "# NOTE: " << a << "\n";
  if (o.as_parameters) {
    s << "parameters:\n";
    for (int j = 0; j < r.num_joints; ++j) {
      s << "  kq" << j + 1 << "_Nm_per_rad: " << Value(r.joint_stiffness(j));
      if (r.determination[j] == Determination::kNotDetermined) s << "   # NOT DETERMINED: prior kept";
      s << "\n";
    }
  } else {
    s << "joint_stiffness_Nm_per_rad: [";
    for (int j = 0; j < r.num_joints; ++j) s << (j ? ", " : "") << Value(r.joint_stiffness(j));
    s << "]";
    if (!r.not_determined.empty()) {
      s << "   # NOT DETERMINED (prior kept): joint";
      for (int j : r.not_determined) s << " " << j + 1;
    }
    s << "\n";
  }
  return s.str();
}

std::string MergeJointStiffness(const std::string& config_path, const Eigen::VectorXd& kq,
                                const std::string& output_path,
                                const std::vector<std::string>& header_comments,
                                const std::string& uncertainty_path) {
  std::ifstream in(config_path);
  if (!in) throw InputError({config_path, 0, 0}, "cannot read the robot config");
  // Check the structure with the YAML reader first (file:line:col errors).
  const YamlDoc doc = YamlDoc::LoadFile(config_path);
  if (doc.Has("parameters")) {
    const YamlDoc params = doc["parameters"];
    for (const std::string& k : params.Keys()) {
      if (std::regex_match(k, std::regex(R"(kq\d+_Nm_per_rad)"))) {
        throw params[k].Error("the config sets " + k + " under 'parameters:', which would "
                              "override the merged joint_stiffness_Nm_per_rad; remove it first");
      }
    }
  }
  std::ostringstream out;
  for (const auto& c : header_comments) out << "# " << c << "\n";
  const std::regex kq_line(R"(^joint_stiffness_Nm_per_rad\s*:\s*\[.*\]\s*(#.*)?$)");
  const std::regex urdf_line(R"(^(\s+urdf\s*:\s*)([^#\s]+)(.*)$)");
  const std::regex uncertainty_line(R"(^uncertainty\s*:.*$)");
  std::string line;
  int line_no = 0, replaced = 0;
  while (std::getline(in, line)) {
    ++line_no;
    std::smatch m;
    if (std::regex_match(line, m, kq_line)) {
      out << "joint_stiffness_Nm_per_rad: [";
      for (int j = 0; j < kq.size(); ++j) out << (j ? ", " : "") << Value(kq(j));
      out << "]   # identified by kq-identify\n";
      ++replaced;
    } else if (!uncertainty_path.empty() && std::regex_match(line, m, uncertainty_line)) {
      continue;  // replaced at the end
    } else if (std::regex_match(line, m, urdf_line)) {
      out << m[1].str() << RebaseRelative(config_path, m[2].str(), output_path) << m[3].str() << "\n";
    } else {
      out << line << "\n";
    }
  }
  if (replaced != 1) {
    throw InputError({config_path, 0, 0},
                     "expected exactly one line 'joint_stiffness_Nm_per_rad: [k1, ..., kn]' at the "
                     "start of a line to merge into, found " + std::to_string(replaced));
  }
  if (!uncertainty_path.empty()) {
    // The file as the output's folder sees it (the tool writes both).
    namespace fs = std::filesystem;
    const std::string ref =
        fs::path(uncertainty_path).is_absolute()
            ? uncertainty_path
            : fs::absolute(uncertainty_path).lexically_normal().lexically_relative(
                  fs::absolute(output_path).lexically_normal().parent_path()).string();
    out << "# the identified stiffnesses' covariance (kq-identify --uncertainty-out; docs/formats.md §12)\n"
        << "uncertainty: [\"" << ref << "\"]\n";
  }
  return out.str();
}

}  // namespace robomach::io
