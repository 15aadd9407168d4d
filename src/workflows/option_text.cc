#include "robomach/workflows/option_text.h"

#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/io/csv_table.h"

namespace robomach::workflows {

std::vector<double> ParseNumberList(const std::string& field, const std::string& text) {
  std::vector<double> v;
  for (size_t pos = 0; pos <= text.size();) {
    size_t comma = text.find(',', pos);
    if (comma == std::string::npos) comma = text.size();
    double x = 0.0;
    if (!io::ParseFiniteNumber(text.substr(pos, comma - pos), &x)) {
      throw OptionError(field, field + ": expected numbers separated by commas, got \"" + text + "\"");
    }
    v.push_back(x);
    pos = comma + 1;
  }
  return v;
}

std::optional<Eigen::Vector3d> ParsePointMm(const std::string& field, const std::string& text) {
  if (text.empty() || text == "tcp") return std::nullopt;
  std::vector<double> v;
  try {
    v = ParseNumberList(field, text);
  } catch (const OptionError&) {
    v.clear();
  }
  if (v.size() != 3) throw OptionError(field, field + ": expected x,y,z in mm or 'tcp', got \"" + text + "\"");
  return Eigen::Vector3d(MmToM(v[0]), MmToM(v[1]), MmToM(v[2]));
}

}  // namespace robomach::workflows
