#include "robomach/drilling/drilling_process.h"

#include "robomach/common/enum_names.h"

namespace robomach::drilling {

const char* ToString(HoleAxis a) {
  switch (a) {
    case HoleAxis::kTipX: return "tip_x";
    case HoleAxis::kTipY: return "tip_y";
    case HoleAxis::kTipZ: return "tip_z";
  }
  return "?";
}

HoleAxis ParseHoleAxis(const std::string& name) {
  constexpr HoleAxis kAll[] = {HoleAxis::kTipX, HoleAxis::kTipY, HoleAxis::kTipZ};
  return ParseByName("hole axis", name, kAll);
}

}  // namespace robomach::drilling
