#include "robomach/report/json.h"

#include "robomach/common/errors.h"
#include "robomach/common/version.h"

namespace robomach::report {
namespace {

// Strings (keys too) with their bytes that are not UTF-8 escaped as \xHH
// (EscapeInvalidUtf8): nlohmann::json refuses to dump invalid UTF-8, and a
// header quoted from a Latin-1 file would otherwise end the run.
nlohmann::json EscapedStrings(const nlohmann::json& j) {
  if (j.is_string()) return EscapeInvalidUtf8(j.get_ref<const std::string&>());
  if (j.is_array()) {
    nlohmann::json a = nlohmann::json::array();
    for (const auto& v : j) a.push_back(EscapedStrings(v));
    return a;
  }
  if (j.is_object()) {
    nlohmann::json o = nlohmann::json::object();
    for (auto it = j.begin(); it != j.end(); ++it) o[EscapeInvalidUtf8(it.key())] = EscapedStrings(it.value());
    return o;
  }
  return j;
}

}  // namespace

std::string DumpJson(const nlohmann::json& j) {
  nlohmann::json out = EscapedStrings(j);
  if (out.is_object() && !out.contains("robomach_version")) out["robomach_version"] = Version();
  return out.dump(2) + "\n";
}

}  // namespace robomach::report
