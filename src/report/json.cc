#include "robomach/report/json.h"

#include "robomach/common/version.h"

namespace robomach::report {

std::string DumpJson(const nlohmann::json& j) {
  if (!j.is_object() || j.contains("robomach_version")) return j.dump(2) + "\n";
  nlohmann::json stamped = j;
  stamped["robomach_version"] = Version();
  return stamped.dump(2) + "\n";
}

}  // namespace robomach::report
