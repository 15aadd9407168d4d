#pragma once
// ISO 230-2 runs (formats.md §8.6).
// Deviations stay in the file's unit (mm or deg): ISO 230-2 reports them so.

#include <map>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/machine/iso230.h"

namespace robomach::io {

/// ISO 230-2 runs (formats.md §8.6): approaches per axis name, in file order
/// of first appearance; deviations in the file's unit (wrapped for rotary).
struct IsoRuns {
  bool rotary{false};
  std::vector<std::string> axis_order;
  std::map<std::string, std::vector<machine::Iso230Approach>> approaches;
};
IsoRuns ReadIsoRuns(const std::string& path);

}  // namespace robomach::io
